"""Training on ~200 tiny shots: the loss falls, checkpoints resume exactly, the best one is kept, NaNs are skipped."""

from __future__ import annotations

import json
import math

import golfflight.model_export.training as training
import pytest
import torch
from golfflight.model_export.data import load_training_data
from golfflight.model_export.training import TrainConfig, load_checkpoint, train
from golfflight.shots.records import read_shots

from golfflight.cli import main

torch.set_num_threads(1)  # tiny models: one thread is as fast, and immune to other jobs on the 2 cores

TINY = dict(variant="phys-nn-pm", hidden=(32, 16), batch_size=32, lr=3e-3)


@pytest.fixture(scope="module")
def run(tiny_shots, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    return train(tiny_shots, out, TrainConfig(epochs=3, **TINY), progress=False)


def test_loss_falls(run):
    history = run.history
    assert [row["epoch"] for row in history] == [1, 2, 3]
    assert history[-1]["train_lp_m"] < history[0]["train_lp_m"]
    assert history[-1]["val_landing_error_m"] < history[0]["val_landing_error_m"]
    assert run.skipped_batches == 0


def test_best_checkpoint_is_the_lowest_validation_error(run):
    best = load_checkpoint(run.out_dir / "best.pt")
    errors = [row["val_landing_error_m"] for row in run.history]
    assert best["metrics"]["epoch"] == 1 + errors.index(min(errors))
    assert best["metrics"]["landing_error_m"] == min(errors)
    assert load_checkpoint(run.out_dir / "last.pt")["epoch"] == 3
    assert json.loads((run.out_dir / "history.json").read_text())["best"]["epoch"] == best["metrics"]["epoch"]
    assert not list(run.out_dir.glob(".*tmp"))


def test_resume_continues_exactly(run, tiny_shots, tmp_path):
    train(tiny_shots, tmp_path, TrainConfig(epochs=2, **TINY), progress=False)
    resumed = train(tiny_shots, tmp_path, TrainConfig(epochs=3, **TINY), resume=True, progress=False)
    assert [row["epoch"] for row in resumed.history] == [1, 2, 3]
    straight, continued = (
        load_checkpoint(run.out_dir / "last.pt")["model"],
        load_checkpoint(tmp_path / "last.pt")["model"],
    )
    for name, tensor in straight.items():
        torch.testing.assert_close(continued[name], tensor, rtol=0, atol=1e-6)


def test_resume_refuses_other_settings(run, tiny_shots, tmp_path):
    (tmp_path / "last.pt").write_bytes((run.out_dir / "last.pt").read_bytes())
    with pytest.raises(ValueError, match="batch_size"):
        train(tiny_shots, tmp_path, TrainConfig(epochs=4, **{**TINY, "batch_size": 64}), resume=True, progress=False)


def test_non_finite_batches_are_skipped_and_counted(tiny_shots, tmp_path, monkeypatch):
    build = training.build_model
    calls = {"n": 0}

    def poisoned(variant, hidden):
        model = build(variant, hidden)

        def hook(module, inputs, output):
            calls["n"] += 1
            return output * math.nan if calls["n"] <= 100 else output

        model.register_forward_hook(hook)
        return model

    monkeypatch.setattr(training, "build_model", poisoned)
    result = train(tiny_shots, tmp_path, TrainConfig(epochs=1, **TINY), progress=False)
    assert result.skipped_batches == 1
    assert math.isfinite(result.history[0]["train_lp_m"]) and math.isfinite(result.history[0]["val_landing_error_m"])
    assert all(torch.isfinite(t).all() for t in load_checkpoint(tmp_path / "last.pt")["model"].values())


def test_split_comes_from_the_file_and_low_shots_are_reported(tiny_shots):
    shots = read_shots(tiny_shots)
    train_set, val_set, summary = load_training_data(tiny_shots)
    low = sum(1 for r in shots.records if r.apex_m < summary.min_apex_m)
    marked_val = [r for r in shots.records if r.split == "val" and r.apex_m >= summary.min_apex_m]
    assert summary.filters["apex_below_min"] == low
    assert summary.n_val == len(val_set) == len(marked_val)
    assert summary.n_train + summary.n_val + low == len(shots)
    expected = torch.tensor([[r.carry_x_m, r.carry_y_m] for r in marked_val], dtype=torch.float32)
    torch.testing.assert_close(val_set.landing, expected)
    limited = load_training_data(tiny_shots, limit=50)[2]
    assert limited.n_train + limited.n_val == 50 and limited.n_val >= 1


def test_nn_baseline_trains_on_landing_only(tiny_shots, tmp_path):
    with pytest.raises(ValueError, match="--loss lp"):
        TrainConfig(variant="nn", loss="lp+lh")
    result = train(
        tiny_shots,
        tmp_path,
        TrainConfig(variant="nn", loss="lp", hidden=(16,), epochs=1, batch_size=32),
        progress=False,
    )
    assert math.isfinite(result.best["landing_error_m"]) and "max_height_error_m" not in result.best


def test_a_compiled_step_trains_what_the_eager_step_trains(run, tiny_shots, tmp_path):
    """`golfflight train --compile`: the Euler step fused by torch.compile, forward and backward (the soft landing's
    rollout and validation's), changes rounding only: the eager run's weights and validation errors after three
    epochs. Compiled from an empty cache: torch.compile keeps its versions of the Euler step
    (`flight.rollout.step_rule`) by the function."""
    torch._dynamo.reset()
    assert main(["train", "--data", str(tiny_shots), "--out", str(tmp_path), "--variant", TINY["variant"],
                 "--hidden", ",".join(map(str, TINY["hidden"])), "--batch-size", str(TINY["batch_size"]),
                 "--lr", str(TINY["lr"]), "--epochs", "3", "--threads", "1", "--quiet", "--compile"]) == 0
    eager, compiled = (load_checkpoint(folder / "last.pt") for folder in (run.out_dir, tmp_path))
    for name, tensor in eager["model"].items():
        torch.testing.assert_close(compiled["model"][name], tensor, rtol=1e-4, atol=1e-6)
    for key in ("landing_error_m", "max_height_error_m"):
        assert compiled["metrics"][key] == pytest.approx(eager["metrics"][key], rel=1e-4)
