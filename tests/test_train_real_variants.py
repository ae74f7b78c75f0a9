"""`golfflight train-real --variant`: Phys-NN+, Phys-Q (refitted from Ferguson 2022) and NN each train one epoch on a
tiny driver file laid out like the shared one (held-out lines included); the physics variants export bundles that
`golfflight simulate` flies in a process of its own, NN is evaluated and refused as a bundle to serve; and
`golfflight accuracy --variant` compares them, with block-bootstrap intervals and seed spreads."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import torch
from golfflight.contract.problems import launch_problem
from golfflight.evaluation.landing_network import LandingNetwork
from golfflight.evaluation.accuracy_flyers import ferguson_flyer
from golfflight.evaluation.variant_comparison import block_bootstrap, flown
from golfflight.flight.coefficients import FERGUSON_2022
from golfflight.flight.physics import initial_state
from golfflight.model_export.joint import JointConfig
from golfflight.model_export.real_nn import landing_nn_from_checkpoint
from golfflight.model_export.real_data import build
from golfflight.model_export.real_training import DATA_FILE, thin_training_rows, train_real
from golfflight.model_export.real_variants import Start, start_of
from golfflight.shots.paths import REPO_ROOT
from golfflight.shots.records import ShotRecord, ShotSet, read_shots
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


@pytest.fixture(scope="module")
def trained(data_root, tmp_path_factory) -> dict[str, tuple[Path, object]]:
    """Each variant trained one epoch (NN on two seeds): {variant: (its WORK folder, its RealRun)}, the physics
    variants exported to WORK/bundle."""
    runs = {}
    for variant in ("phys-nn+", "phys-q", "nn"):
        work = tmp_path_factory.mktemp(variant)
        out = None if variant == "nn" else work / "bundle"
        seeds = (0, 1) if variant == "nn" else (0,)
        runs[variant] = work, train_real(data_root, work, start_of(variant, None), ONE_EPOCH, seeds, out,
                                         ("trackman-outdoor",), progress=False)
    return runs


@pytest.mark.parametrize("variant", ["phys-nn+", "phys-q"])
def test_a_physics_variant_trains_an_epoch_and_simulate_flies_its_bundle(trained, tmp_path, variant):
    work, run = trained[variant]
    assert run.card.variant == variant
    assert max(_training_lines(work)) <= 2942, "a held-out line reached the training set"
    held_out = {h.name: h.n_shots for h in run.card.held_out}
    assert held_out == {"TrackMan outdoor drivers, second half": len(HELD_OUT_LINES)}, "measured, never trained on"
    flown = _simulate(work / "bundle", tmp_path)
    assert 150 < flown["carry_m"] < 320 and 10 < flown["apex_m"] < 60
    if variant == "phys-q":
        fitted = np.array(run.card.architecture.quadratic_params)
        moved = np.abs(fitted - np.array(FERGUSON_2022))
        assert moved.max() > 0 and moved.max() < 0.05, "Phys-Q did not start from Ferguson 2022's coefficients"


def test_nn_trains_an_epoch_and_is_evaluated_on_the_validation_blocks(trained):
    work, run = trained["nn"]
    final = run.runs["seed-0"].final
    assert final["val"]["trackman-outdoor"]["n_shots"] == 12
    assert np.isfinite(final["val"]["trackman-outdoor"]["landing_error_m"]) and np.isfinite(final["val_loss"])
    model = landing_nn_from_checkpoint(work / "seed-0" / "last.pt")
    launch = {"ball_speed_mps": np.array([70.0]), "launch_angle_deg": np.array([12.0]),
              "launch_direction_deg": np.array([0.0]), "spin_rpm": np.array([2500.0]),
              "spin_axis_deg": np.array([0.0])}
    state = initial_state(**launch)
    with torch.no_grad():
        in_torch = model(torch.tensor(state.velocity, dtype=torch.float32),
                         torch.tensor(state.spin, dtype=torch.float32))
    np.testing.assert_allclose(LandingNetwork(work / "seed-0").landing(launch), in_torch.numpy(), rtol=1e-4, atol=1e-3)
    assert max(_training_lines(work)) <= 2942


CELL = re.compile(r"^(-?\d+\.\d\d) \[(-?\d+\.\d\d), (-?\d+\.\d\d)\]( \(seeds (-?\d+\.\d\d)–(-?\d+\.\d\d)\))?$")


def _tables(markdown: str) -> dict[str, dict[str, list[str]]]:
    """{set title: {row name: cells}} of the comparison section."""
    tables, title = {}, None
    for line in markdown.splitlines():
        if line.startswith("**"):
            title = line.split("**")[1]
            tables[title] = {}
        elif line.startswith("| ") and title and not line.startswith("|  |"):
            name, *cells = [c.strip() for c in line.strip("|").split("|")]
            tables[title][name] = cells
    return tables


def test_accuracy_compares_the_variants_with_block_intervals_and_seed_spreads(trained, data_root, tmp_path):
    out = tmp_path / "accuracy.md"
    (phys_q, _), (nn_work, _) = trained["phys-q"], trained["nn"]
    done = subprocess.run([sys.executable, "-m", "golfflight", "accuracy", "--variant", f"phys-q={phys_q / 'bundle'}",
                           "--variant", f"nn={nn_work / 'seed-0'},{nn_work / 'seed-1'}", "--data-dir", str(data_root),
                           "--validation", str(nn_work / DATA_FILE), "--out", str(out)],
                          capture_output=True, text=True, env=ENV, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "<!-- BEGIN generated by `golfflight accuracy --variant` -->" in out.read_text()
    tables = _tables(out.read_text())
    assert set(tables) == {"TrackMan drives, Premium balls (held out)", "TrackMan drives, all balls (held out)",
                           "trackman-outdoor, validation split (training side)"}
    for rows in tables.values():
        assert rows["height MAE, yd"][1] == "—", "NN predicts no height"
        for name, cells in rows.items():
            phys_q_cell, nn_cell, ferguson, synthetic = (CELL.match(c) for c in cells)
            assert nn_cell is None or nn_cell[4], f"{name}: NN's two seeds give no spread"
            for match in (phys_q_cell, nn_cell, ferguson, synthetic):
                if match:
                    value, low, high = (float(match[i]) for i in (1, 2, 3))
                    assert low <= value + 0.01 and value <= high + 0.01


def test_the_interval_resamples_whole_blocks_not_shots():
    values = np.r_[np.zeros(50), np.full(50, 10.0)]
    blocks = np.array(["a"] * 50 + ["b"] * 50, dtype=object)
    assert block_bootstrap(values, blocks) == (0.0, 10.0)
    by_shot = block_bootstrap(values, np.arange(100))
    assert 3 < by_shot[0] < 5 < by_shot[1] < 7


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
        train_real(data_root, tmp_path / "work", Start("nn", None), ONE_EPOCH, (0,), tmp_path / "bundle")


def test_a_start_bundle_of_another_variant_is_refused_naming_both():
    with pytest.raises(InputError, match="is a phys-nn\\+ bundle; --variant phys-q needs a phys-q bundle"):
        Start("phys-q", str(REPO_ROOT / "models" / "default")).network()
    with pytest.raises(InputError, match="takes no --init"):
        start_of("nn", REPO_ROOT / "models" / "default")


def test_a_shot_that_records_only_its_carry_distance_is_compared_on_carry():
    record = ShotRecord(shot_id="players:1", ball_speed_mps=70, launch_angle_deg=12, launch_direction_deg=0,
                        spin_rpm=2500, spin_axis_deg=0, carry_y_m=200.0)
    shots = ShotSet([record])
    ferguson = ferguson_flyer()
    errors = flown(ferguson)(shots, None)
    carry = ferguson.flight(launch_problem(shots.launch())).carry_m
    np.testing.assert_allclose(errors["carry_m"], carry - 200.0)
    assert np.isnan(errors["landing_m"]).all() and np.isnan(errors["side_m"]).all()


def test_a_learning_curve_point_keeps_a_fraction_of_each_sources_training_shots_and_all_validation(data_root, tmp_path):
    build(data_root, tmp_path / "whole.csv", ("trackman-outdoor", "trackman-model"))
    for name in ("a.csv", "b.csv"):
        build(data_root, tmp_path / name, ("trackman-outdoor", "trackman-model"))
        thin_training_rows(tmp_path / name, 0.5)
    assert (tmp_path / "a.csv").read_text() == (tmp_path / "b.csv").read_text(), "the same shots every time"

    def counts(path: Path) -> Counter:
        shots = read_shots(path)
        return Counter(zip(shots.column("source"), shots.column("split")))

    full, half = counts(tmp_path / "whole.csv"), counts(tmp_path / "a.csv")
    for (source, split), n in full.items():
        assert half[(source, split)] == (n if split == "val" else max(1, round(n / 2))), (source, split)
    done = subprocess.run([sys.executable, "-m", "golfflight", "train-real", "--work", str(tmp_path / "w"),
                           "--data-root", str(data_root), "--train-fraction", "1.5"],
                          capture_output=True, text=True, env=ENV, timeout=120)
    assert done.returncode != 0 and "--train-fraction must be above 0 and at most 1, got 1.5" in done.stderr


def test_the_learning_curve_figure_draws_each_variant_against_its_training_shots(tmp_path):
    from golfflight.evaluation.figures import learning_curve
    from PIL import Image

    shots = {"Phys-Q": np.array([1700, 3400, 6800]), "NN": np.array([1700, 6800])}
    errors = {"Phys-Q": np.array([11.0, 10.2, 9.8]), "NN": np.array([14.0, 12.0])}
    spans = {label: np.stack([e - 0.5, e + 0.5], axis=1) for label, e in errors.items()}
    path = learning_curve(shots, errors, spans, tmp_path / "curve.png", "felt error (m)")
    with Image.open(path) as image:
        assert image.format == "PNG" and image.size[0] > 400 and len(image.getcolors(256) or []) > 3
