"""`golfflight evaluate` on tiny runs: Table-1 rows, figures, the bundle's runtime path, and the noise floor on
crafted data whose truth is known."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from golfflight.evaluation.noise_floor import (
    expected_outcome_noise,
    noise_floors,
    nominal_conditions,
    population_air,
    read_session_truth,
)
from golfflight.flight.air import Air
from golfflight.flight.physics import initial_state
from golfflight.flight.wind import Wind
from golfflight.model_export.data import load_training_data
from golfflight.model_export.evaluate import COMMAND, FIGURES, CoefficientSamples, coefficient_summary, run_evaluation
from golfflight.model_export.export import export_checkpoint
from golfflight.model_export.training import TrainConfig, load_checkpoint, train
from golfflight.model_export.validation import load_validation
from golfflight.model_export.variants import PhysNN
from golfflight.shots.markdown import begin_marker
from golfflight.shots.records import ShotRecord, read_shots, write_csv_atomic, write_shots
from golfflight.shots.reference_world import fly_reference
from golfflight.shots.synth import sessions_path

from golfflight.cli import main

torch.set_num_threads(1)

RUNS = {
    "phys-nn+": {"hidden": (16,)},
    "phys-q": {},
    "nn": {"hidden": (8,), "loss": "lp"},
}


@pytest.fixture(scope="module")
def runs(tiny_shots, tmp_path_factory):
    """One tiny run of Phys-NN+, Phys-Q and NN (one epoch each) and the Phys-NN+ bundle."""
    root = tmp_path_factory.mktemp("runs")
    for variant, settings in RUNS.items():
        train(
            tiny_shots,
            root / variant,
            TrainConfig(variant=variant, epochs=1, batch_size=64, **settings),
            progress=False,
        )
    export_checkpoint(root / "phys-nn+", root / "bundle")
    return root


@pytest.fixture(scope="module")
def report(tiny_shots, runs, tmp_path_factory):
    docs = tmp_path_factory.mktemp("docs")
    (docs / "training.md").write_text("# Training\n\nHand-written text that must survive.\n")
    return run_evaluation(tiny_shots, [runs / v for v in RUNS], docs, bundle=runs / "bundle"), docs


def test_table_has_a_row_per_run_and_agrees_with_training(report, runs):
    result, docs = report
    assert [r.variant for r in result.runs] == list(RUNS)
    for run in result.runs:
        stored = load_checkpoint(runs / run.variant / "best.pt")["metrics"]
        assert run.errors.mean_landing_m == pytest.approx(stored["landing_error_m"], abs=1e-3)
        assert (run.errors.mean_abs_apex_m is None) == (run.variant == "nn")
        assert run.epochs_trained == run.best_epoch == 1 and run.train_seconds > 0
    for name in ("Phys-Q (`phys-q`)", "NN (`nn`)", "Phys-NN+ (`phys-nn+`)"):
        assert name in result.markdown
    assert "6.63" in result.markdown and "4.75" in result.markdown
    page = (docs / "training.md").read_text()
    assert "Hand-written text that must survive." in page and begin_marker(COMMAND) in page
    assert [p.name for p in result.figures] == list(FIGURES) and all(p.stat().st_size > 10_000 for p in result.figures)


def test_rerun_replaces_the_generated_section(report, tiny_shots, runs):
    _, docs = report
    run_evaluation(tiny_shots, [runs / "phys-q"], docs)
    page = (docs / "training.md").read_text()
    assert page.count(begin_marker(COMMAND)) == 1 and "Phys-NN+ (`phys-nn+`)" not in page


def test_bundle_runtime_path_matches_torch(report):
    check = report[0].bundle
    assert check.variant == "phys-nn+" and check.not_landed == 0
    assert check.max_landing_difference_m < 0.01 and check.max_apex_difference_m < 0.01
    assert check.numpy_errors.mean_landing_m == pytest.approx(report[0].runs[0].errors.mean_landing_m, abs=0.01)


def test_validation_shots_are_the_training_validation_split(tiny_shots):
    val = load_validation(tiny_shots)
    _, tensors, summary = load_training_data(tiny_shots)
    assert len(val) == summary.n_val
    torch.testing.assert_close(val.tensors.velocity.float(), tensors.velocity)


def test_command_line(tiny_shots, runs, tmp_path, capsys):
    assert main(["evaluate", "--data", str(tiny_shots), "--runs", str(runs / "phys-q"), "--out", str(tmp_path)]) == 0
    torch.set_num_threads(1)  # the command takes two threads for its big batches; tiny tests are faster on one
    assert "Phys-Q" in capsys.readouterr().out and (tmp_path / "figures" / FIGURES[0]).is_file()


AIRS = {"S0": (10.0, 0.0, 50.0), "S1": (30.0, 1500.0, 50.0), "S2": (20.0, 200.0, 80.0)}
"""Crafted sessions: temperature, altitude, humidity; S2 is the validation session and has a 5 m/s crosswind."""


def _crafted(tmp_path, noise_m: float = 0.0):
    """Shots flown through the reference world in each session's air (S2 with wind), recorded exactly (+ a
    deterministic landing offset `noise_m` along x), with a sessions file holding the truth."""
    rng = np.random.default_rng(3)
    records, truth_rows = [], []
    for name, (temperature, altitude, humidity) in AIRS.items():
        n = 6
        launch = {
            "ball_speed_mps": rng.uniform(45, 75, n),
            "launch_angle_deg": rng.uniform(10, 20, n),
            "launch_direction_deg": rng.uniform(-3, 3, n),
            "spin_rpm": rng.uniform(2500, 7000, n),
            "spin_axis_deg": rng.uniform(-5, 5, n),
        }
        wind = Wind(5.0, 90.0, profile="log") if name == "S2" else Wind()
        air = Air.from_conditions(temperature, altitude, humidity)
        flight = fly_reference(initial_state(**launch), air, wind)
        for i in range(n):
            records.append(
                ShotRecord(
                    shot_id=f"{name}-{i}",
                    session=name,
                    split="val" if name == "S2" else "train",
                    **{k: float(v[i]) for k, v in launch.items()},
                    carry_x_m=float(flight.landing_position[i, 0]) + noise_m,
                    carry_y_m=float(flight.landing_position[i, 1]),
                    apex_m=float(flight.apex_m[i]),
                )
            )
        truth_rows.append([name, temperature, altitude, humidity, 5.0 if name == "S2" else 0.0, 90.0])
    path = tmp_path / "crafted.csv"
    write_shots(path, records)
    write_csv_atomic(
        sessions_path(path),
        ["session", "temperature_c", "altitude_m", "humidity_pct", "wind_speed_mps", "wind_from_deg"],
        truth_rows,
    )
    return path


def test_noise_floor_with_the_true_conditions_is_zero_without_noise(tmp_path):
    val = load_validation(_crafted(tmp_path))
    air, described = nominal_conditions(val)
    expected = [Air.from_conditions(*AIRS[s]).density_kg_m3 for s in ("S0", "S1")]
    assert float(air.density_kg_m3) == pytest.approx(np.mean(expected)) and "mean air" in described
    nominal, true, noise = noise_floors(val, air, described)
    assert true.landing_m < 1e-3 and true.max_height_m < 1e-3, "only the CSV's 6 significant digits remain"
    assert nominal.landing_m > 1.0, "the crosswind and the other air must show in the nominal floor"
    assert noise.name == "outcome noise" and noise.landing_m > 0


def test_noise_floor_measures_a_known_offset(tmp_path):
    val = load_validation(_crafted(tmp_path, noise_m=0.7))
    _, true, _ = noise_floors(val, *nominal_conditions(val))
    assert true.landing_m == pytest.approx(0.7, abs=1e-3)
    assert np.allclose(true.errors.side_m, -0.7, atol=1e-3) and np.allclose(true.errors.length_m, 0.0, atol=1e-3)


def test_population_air_weights_sessions_by_training_shots(tmp_path):
    path = _crafted(tmp_path)
    shots, truth = read_shots(path), read_session_truth(sessions_path(path))
    assert set(truth) == set(AIRS) and truth["S2"].wind_speed_mps == 5.0
    air = population_air(shots, truth)
    s0, s1 = (Air.from_conditions(*AIRS[s]) for s in ("S0", "S1"))
    assert float(air.kinematic_viscosity_m2_s) == pytest.approx(
        (s0.kinematic_viscosity_m2_s + s1.kinematic_viscosity_m2_s) / 2
    )


def test_expected_outcome_noise_follows_the_noise_model(tmp_path):
    val = load_validation(_crafted(tmp_path))
    landing, apex = expected_outcome_noise(val)
    carry = np.hypot(*val.landing_m.T)
    assert landing == pytest.approx(np.mean(0.4 + 0.004 * carry) * math.sqrt(math.pi / 2))
    assert apex == pytest.approx(0.3 * math.sqrt(2 / math.pi))


def test_figure_7_in_numbers_compares_the_effective_coefficients_with_the_reference_world():
    samples = CoefficientSamples(spin_ratio=np.array([0.1, 0.2, 0.3, 0.6, 0.7]),
                                 c_lift=np.array([0.20, 0.20, 0.20, 0.25, 0.25]),
                                 c_drag=np.array([0.25, 0.25, 0.25, 0.30, 0.30]),
                                 c_q=np.full(5, 0.5),
                                 reference_lift=np.array([0.21, 0.20, 0.22, 0.20, 0.20]),
                                 reference_drag=np.array([0.25, 0.25, 0.25, 0.25, 0.25]))
    model = PhysNN("phys-nn+", (4,))
    text = coefficient_summary(samples, np.ones(5), model, "Phys-NN+")
    assert "raw C_L median 0.20" in text and "C_Q median 0.50" in text
    assert "median relative difference +0.0%" in text  # drag 0.25 vs 0.25 on 3 of 5 steps: the median is 0
    assert "median -0.010 below S = 0.5, +0.050 above (2 steps)" in text
    assert f"learned p_M = {float(model.p_m):.4f}" in text
