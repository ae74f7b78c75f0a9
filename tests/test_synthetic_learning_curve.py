"""`scripts/synthetic_learning_curve.py` (issue 57's learning curve on the synthetic world): a subset keeps n training
shots and every validation shot, nested in a larger one; Phys-NN+, Phys-Q and NN trained an epoch on it are reported
with their validation error and their model-form error against the reference world, each within the triangle the
world's own error allows, each error and bias with a 95 % interval that draws whole sessions; the results file and
the figure are written only when asked."""

from __future__ import annotations

import importlib.util
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from golfflight.model_export.training import TrainConfig, train
from golfflight.shots.paths import REPO_ROOT
from golfflight.shots.records import read_shots

torch.set_num_threads(1)
SCRIPT = REPO_ROOT / "scripts" / "synthetic_learning_curve.py"
ENV = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
VARIANTS = ("phys-nn+", "phys-q", "nn")
SPEC = importlib.util.spec_from_file_location("synthetic_learning_curve", SCRIPT)
curve = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(curve)


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory) -> Path:
    """A small synthetic file with its hidden truth beside it, as `golfflight synth` writes them."""
    path = tmp_path_factory.mktemp("synth") / "synth.csv"
    done = subprocess.run([sys.executable, "-m", "golfflight", "synth", "--shots", "500", "--seed", "3", "--out",
                           str(path)], capture_output=True, text=True, env=ENV, timeout=120)
    assert done.returncode == 0, done.stderr
    return path


def _rows(path: Path, split: str) -> set[str]:
    shots = read_shots(path)
    return set(shots.column("shot_id")[shots.column("split") == split])


def test_a_subset_keeps_n_training_shots_inside_a_larger_one_and_every_validation_shot(synthetic, tmp_path):
    for n in (60, 150):
        assert curve.subset(synthetic, n, tmp_path / f"n{n}.csv") == n
        assert len(_rows(tmp_path / f"n{n}.csv", "train")) == n
        assert _rows(tmp_path / f"n{n}.csv", "val") == _rows(synthetic, "val")
    assert _rows(tmp_path / "n60.csv", "train") < _rows(tmp_path / "n150.csv", "train") <= _rows(synthetic, "train")
    too_many = len(_rows(synthetic, "train")) + 1
    with pytest.raises(SystemExit, match=f"--train-shots must be from 1 to the file's {too_many - 1} training rows"):
        curve.subset(synthetic, too_many, tmp_path / "x.csv")
    assert not (tmp_path / "x.csv").exists()


@pytest.fixture(scope="module")
def runs(synthetic, tmp_path_factory) -> list[Path]:
    """Each variant trained one epoch on 150 of the file's training shots."""
    work = tmp_path_factory.mktemp("runs")
    curve.subset(synthetic, 150, work / "n150.csv")
    for variant in VARIANTS:
        config = TrainConfig(variant=variant, epochs=1, loss="lp" if variant == "nn" else "lp+lh")
        train(work / "n150.csv", work / variant, config, progress=False)
    return [work / variant for variant in VARIANTS]


def test_each_variant_is_reported_against_the_records_and_the_world_within_the_worlds_own_error(synthetic, runs,
                                                                                                 tmp_path, capsys):
    curve.report(synthetic, runs, None, None)
    printed = capsys.readouterr().out
    assert not list(tmp_path.iterdir()), "nothing written without --results or --png"
    for label in ("Phys-NN+", "Phys-Q", "NN"):
        line = next(line for line in printed.splitlines() if line.startswith(f"| {label} | "))
        assert len(re.findall(r"\d\.\d\d \[\d+\.\d\d, \d+\.\d\d\] \([+-]\d+\.\d\d \[[+-]\d+\.\d\d, [+-]\d+\.\d\d\]\)",
                              line)) == 2, line
    assert re.search(r"Nominal floor .*: \d+\.\d\d m \[\d+\.\d\d, \d+\.\d\d\] \(bias [+-]", printed), printed
    curve.report(synthetic, runs, tmp_path / "c.png", tmp_path / "r.json")
    results = json.loads((tmp_path / "r.json").read_text())
    assert {row["variant"] for row in results["rows"]} == set(VARIANTS)
    floor = results["floor_m"]
    for row in results["rows"]:
        assert 140 <= row["n_train"] <= 150 and row["epochs"] == 1 and row["seeds"] == 1, row
        assert np.isfinite([row["val_length_bias_m"], row["form_length_bias_m"]]).all(), row
        assert 0 < row["form_landing_m"], row
        # per shot |model - record| lies within |world - record| +- |model - world|, so the means do too
        assert floor - row["form_landing_m"] - 1e-9 <= row["val_landing_m"] <= floor + row["form_landing_m"] + 1e-9
        for key in curve.PER_SHOT:
            low, high = row[f"{key}_interval"]
            assert low - 1e-9 <= row[key] <= high + 1e-9, (key, row)
    assert (tmp_path / "c.png").stat().st_size > 1000


def test_the_interval_draws_whole_sessions_of_the_seeds_mean_not_shots():
    sessions = np.array(["S1"] * 50 + ["S2"] * 50, dtype=object)
    zeros_then_tens = np.repeat([0.0, 10.0], 50)
    point = {"variant": "phys-q", "n_train": 1000, "epochs": 1, "batch_size": 256, "best_epoch": 1,
             "train_seconds": 1.0, **{key: 5.0 for key in curve.PER_SHOT},
             "per_shot": {key: zeros_then_tens for key in curve.PER_SHOT}}
    (row,) = curve.summarise([point], sessions)
    assert all(row[f"{key}_interval"] == [0.0, 10.0] for key in curve.PER_SHOT), row
    (by_shot,) = curve.summarise([point], np.arange(100))
    assert 3 < by_shot["val_landing_m_interval"][0] < by_shot["val_landing_m_interval"][1] < 7, by_shot
    other_seed = point | {"per_shot": {key: 10.0 - zeros_then_tens for key in curve.PER_SHOT}}
    (two_seeds,) = curve.summarise([point, other_seed], sessions)
    assert two_seeds["seeds"] == 2 and two_seeds["val_landing_m_interval"] == [5.0, 5.0], two_seeds
