"""`golfflight train-real --variant`: Phys-NN+, Phys-Q (refitted from Ferguson 2022) and NN each train one epoch on a
tiny driver file laid out like the shared one (held-out lines included); the physics variants export bundles that
`golfflight simulate` flies in a process of its own, NN is evaluated and refused as a bundle to serve."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from golfflight.flight.coefficients import FERGUSON_2022
from golfflight.model_export.joint import JointConfig
from golfflight.model_export.real_nn import landing_nn_from_checkpoint
from golfflight.model_export.real_training import DATA_FILE, train_real
from golfflight.model_export.real_variants import Start, start_of
from golfflight.shots.paths import REPO_ROOT
from golfflight.shots.records import read_shots
from golfflight.errors import InputError
from test_real_training import _driver_file

torch.set_num_threads(1)
HELD_OUT_LINES = list(range(2943, 2951))
TRAINING_LINES = [line for line in range(3, 100) if (line // 6) % 2 == 0]
"""Eight range blocks of six measured shots between indoor rows: two go to validation (every 4th block)."""
ONE_EPOCH = JointConfig(epochs=1, lr=1e-3)
ENV = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}


@pytest.fixture(scope="module")
def data_root(tmp_path_factory) -> Path:
    """A shared-data folder whose driver file has trainable range blocks and held-out lines (>= 2943)."""
    root = tmp_path_factory.mktemp("shared")
    _driver_file(root, measured_lines=TRAINING_LINES + HELD_OUT_LINES)
    return root


def _train(data_root: Path, work: Path, start: Start, out: Path | None):
    return train_real(data_root, work, start, ONE_EPOCH, (0,), out, ("trackman-outdoor",), progress=False)


def _simulate(bundle: Path, tmp_path: Path) -> dict:
    shot = [{"ball_speed_mps": 70, "launch_angle_deg": 12, "launch_direction_deg": 0, "spin_rpm": 2500,
             "spin_axis_deg": 0}]
    (tmp_path / "shot.json").write_text(json.dumps(shot))
    done = subprocess.run([sys.executable, "-m", "golfflight", "simulate", str(tmp_path / "shot.json"), "--model",
                           str(bundle)], capture_output=True, text=True, env=ENV, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)["results"][0]


def _training_lines(work: Path) -> list[int]:
    return [int(shot_id.split(":")[1]) for shot_id in read_shots(work / DATA_FILE).column("shot_id")]


@pytest.mark.parametrize("variant", ["phys-nn+", "phys-q"])
def test_a_physics_variant_trains_an_epoch_and_simulate_flies_its_bundle(data_root, tmp_path, variant):
    run = _train(data_root, tmp_path / "work", start_of(variant, None), tmp_path / "bundle")
    assert run.card.variant == variant
    assert max(_training_lines(tmp_path / "work")) <= 2942, "a held-out line reached the training set"
    held_out = {h.name: h.n_shots for h in run.card.held_out}
    assert held_out == {"TrackMan outdoor drivers, second half": len(HELD_OUT_LINES)}, "measured, never trained on"
    flown = _simulate(tmp_path / "bundle", tmp_path)
    assert 150 < flown["carry_m"] < 320 and 10 < flown["apex_m"] < 60
    if variant == "phys-q":
        fitted = np.array(run.card.architecture.quadratic_params)
        moved = np.abs(fitted - np.array(FERGUSON_2022))
        assert moved.max() > 0 and moved.max() < 0.05, "Phys-Q did not start from Ferguson 2022's coefficients"


def test_nn_trains_an_epoch_and_is_evaluated_on_the_validation_blocks(data_root, tmp_path):
    run = _train(data_root, tmp_path / "work", start_of("nn", None), None)
    final = run.runs["seed-0"].final
    assert final["val"]["trackman-outdoor"]["n_shots"] == 12
    assert np.isfinite(final["val"]["trackman-outdoor"]["landing_error_m"]) and np.isfinite(final["val_loss"])
    model = landing_nn_from_checkpoint(tmp_path / "work" / "seed-0" / "last.pt")
    assert model(torch.zeros(1, 3), torch.zeros(1, 3)).shape == (1, 2)
    assert max(_training_lines(tmp_path / "work")) <= 2942


def test_nn_is_refused_as_a_bundle_to_serve_before_anything_trains(data_root, tmp_path):
    done = subprocess.run([sys.executable, "-m", "golfflight", "train-real", "--variant", "nn", "--work",
                           str(tmp_path / "work"), "--data-root", str(data_root), "--sources", "trackman-outdoor",
                           "--epochs", "1", "--out", str(tmp_path / "bundle")],
                          capture_output=True, text=True, env=ENV, timeout=120)
    assert done.returncode != 0
    assert "--variant nn predicts landing points only" in done.stderr and "leave out --out" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "bundle").exists() and not (tmp_path / "work").exists()
    with pytest.raises(InputError, match="never exported"):
        _train(data_root, tmp_path / "work", Start("nn", None), tmp_path / "bundle")


def test_a_start_bundle_of_another_variant_is_refused_naming_both():
    with pytest.raises(InputError, match="is a phys-nn\\+ bundle; --variant phys-q needs a phys-q bundle"):
        Start("phys-q", str(REPO_ROOT / "models" / "default")).network()
    with pytest.raises(InputError, match="takes no --init"):
        start_of("nn", REPO_ROOT / "models" / "default")
