"""Model bundles: ONNX matches torch, NumPy + ONNX Runtime flights match torch flights, tampering is refused."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import numpy as np
import onnxruntime as ort
import pytest
import torch
from conftest import random_launches
from golfflight.flight import constants
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.flight.physics import initial_state
from golfflight.flight.rollout import euler_rollout, hard_landing
from golfflight.model_export.export import OPSET, export_bundle, export_checkpoint, probe_inputs
from golfflight.model_export.training import TrainConfig, load_checkpoint, model_from_checkpoint, train
from golfflight.weights_schema import BundleError, load_bundle
from golfflight.weights_schema.model_card import SCHEMA_PATH, schema_text

from golfflight.cli import main

from flights import simulate

torch.set_num_threads(1)  # tiny models: one thread is as fast, and immune to other jobs on the 2 cores


@pytest.fixture(scope="module")
def trained(tiny_shots, tmp_path_factory):
    """A Phys-NN+ trained for one epoch on the tiny shots, and its bundle."""
    run = tmp_path_factory.mktemp("run")
    train(tiny_shots, run, TrainConfig(variant="phys-nn+", hidden=(32, 16), epochs=1, batch_size=32), progress=False)
    bundle = tmp_path_factory.mktemp("bundle")
    export_checkpoint(run, bundle)
    model, _ = model_from_checkpoint(load_checkpoint(run / "best.pt"))
    return model, bundle


def test_onnx_matches_torch_coefficients(trained):
    model, bundle = trained
    card, onnx_path = load_bundle(bundle)
    session = ort.InferenceSession(str(onnx_path))
    for n in (1, 7, 4096):
        velocity, spin = probe_inputs(n, seed=n)
        got = session.run(None, {"v_rel": velocity, "omega": spin})[0]
        with torch.no_grad():
            expected = model(torch.from_numpy(velocity), torch.from_numpy(spin)).numpy()
        assert got.shape == (n, 4) and got.dtype == np.float32
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-5)
    assert card.export_check.max_abs_coefficient_difference <= 1e-5


def test_numpy_onnx_flights_match_torch_flights(trained):
    model, bundle = trained
    coefficients = OnnxCoefficients(bundle)
    physics = coefficients.card.physics
    state = initial_state(**random_launches(100, seed=11))
    flight = simulate(state, coefficients, density=physics.air_density_kg_m3, dt=physics.dt_s, t_max=physics.t_sim_s)
    as_tensor = lambda a: torch.as_tensor(a, dtype=torch.float32)  # noqa: E731
    with torch.no_grad():
        trajectory = euler_rollout(
            as_tensor(state.position),
            as_tensor(state.velocity),
            as_tensor(state.spin),
            model,
            physics.air_density_kg_m3,
        )
        landing = hard_landing(trajectory)
    assert flight.landed.all() and landing.landed.all()
    distance = np.linalg.norm(landing.position[:, :2].numpy() - flight.landing_position[:, :2], axis=-1)
    assert distance.max() < 0.01
    np.testing.assert_allclose(trajectory.apex_m.numpy(), flight.apex_m, atol=0.01)


def test_card_describes_the_simulation(trained):
    card, _ = load_bundle(trained[1])
    physics = card.physics
    assert card.variant == "phys-nn+" and card.onnx.opset == OPSET
    assert [s.name for s in card.onnx.inputs] == ["v_rel", "omega"] and card.onnx.outputs[0].shape == ["N", 4]
    assert card.onnx.output_columns == ["C_L", "C_D", "C_M", "C_Q"]
    assert (physics.ball_mass_kg, physics.ball_radius_m, physics.gravity_mps2, physics.tee_height_m) == (
        constants.BALL_MASS_KG,
        constants.BALL_RADIUS_M,
        constants.GRAVITY_MPS2,
        constants.TEE_HEIGHT_M,
    )
    assert (physics.dt_s, physics.t_sim_s) == (0.1, 10.0)
    assert any("omega x v_rel" in e for e in physics.equations)
    assert card.architecture.hidden_units == [32, 16] and card.architecture.p_m > 0
    assert len(card.training_data.sha256) == 64 and card.training_data.n_val > 0


def _copy(bundle, tmp_path):
    return shutil.copytree(bundle, tmp_path / "copy")


def test_tampered_onnx_is_refused(trained, tmp_path):
    bundle = _copy(trained[1], tmp_path)
    with open(bundle / "model.onnx", "ab") as handle:
        handle.write(b"\0")
    with pytest.raises(BundleError, match="SHA-256"):
        load_bundle(bundle)
    with pytest.raises(BundleError):
        OnnxCoefficients(bundle)


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda card: card["physics"].update(dt_s=-0.1), "physics.dt_s"),
        (lambda card: card.update(surprise=1), "surprise"),
        (lambda card: card.pop("validation"), "validation"),
        (lambda card: card.update(schema_version="9.9"), "schema_version '9.9'"),
        (lambda card: card["onnx"].update(sha256="0" * 64), "does not match"),
    ],
)
def test_invalid_card_is_refused(trained, tmp_path, edit, message):
    bundle = _copy(trained[1], tmp_path)
    card = json.loads((bundle / "model_card.json").read_text())
    edit(card)
    (bundle / "model_card.json").write_text(json.dumps(card))
    with pytest.raises(BundleError, match=message):
        load_bundle(bundle)


def test_unreadable_or_missing_card_is_refused(trained, tmp_path):
    bundle = _copy(trained[1], tmp_path)
    (bundle / "model_card.json").write_text("{not json")
    with pytest.raises(BundleError, match="not valid JSON"):
        load_bundle(bundle)
    with pytest.raises(BundleError, match="no model_card.json"):
        load_bundle(tmp_path)


def test_committed_schema_is_current():
    assert SCHEMA_PATH.read_text() == schema_text(), (
        "model_card.schema.json is stale: run `python -m golfflight.weights_schema`"
    )


def test_phys_q_exports_and_nn_does_not(tiny_shots, tmp_path):
    run = tmp_path / "q"
    train(tiny_shots, run, TrainConfig(variant="phys-q", epochs=1, batch_size=64), progress=False)
    card = export_checkpoint(run, tmp_path / "q-bundle")
    assert card.architecture.kind == "quadratic-in-spin-ratio" and len(card.architecture.quadratic_params) == 7
    nn_run = tmp_path / "nn"
    train(
        tiny_shots, nn_run, TrainConfig(variant="nn", loss="lp", hidden=(8,), epochs=1, batch_size=64), progress=False
    )
    payload = load_checkpoint(nn_run / "best.pt")
    with pytest.raises(ValueError, match="no coefficient graph"):
        export_bundle(model_from_checkpoint(payload)[0], payload, tmp_path / "nn-bundle")


def test_command_line_train_and_export(tiny_shots, tmp_path, capsys):
    run, bundle = tmp_path / "run", tmp_path / "bundle"
    args = [
        "--data",
        str(tiny_shots),
        "--variant",
        "phys-nn-pm",
        "--hidden",
        "16",
        "--epochs",
        "1",
        "--batch-size",
        "32",
    ]
    assert main(["train", *args, "--limit", "60", "--out", str(run)]) == 0
    assert main(["export", "--checkpoint", str(run), "--out", str(bundle)]) == 0
    assert "val landing error" in capsys.readouterr().out
    assert load_bundle(bundle)[0].training.limit == 60


def test_runtime_path_imports_no_torch():
    code = (
        "import sys, golfflight.flight.onnx_coefficients, golfflight.flight.integrator\n"
        "import golfflight.weights_schema, golfflight.cli\n"
        "golfflight.cli.build_parser()\n"
        "assert 'torch' not in sys.modules, 'torch imported on the serving path'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
