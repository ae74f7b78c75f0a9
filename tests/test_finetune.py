"""Fine-tuning: weights come back out of a bundle exactly, the split is assigned by time/session when the user's
file has none, the loss falls from the starting model, and the result is a valid bundle."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from golfflight.model_export.bundle_model import config_from_card, model_from_bundle
from golfflight.model_export.export import export_checkpoint
from golfflight.model_export.finetune import RUN_DIR, assign_split, finetune, load_base
from golfflight.model_export.training import TrainConfig, load_checkpoint, train
from golfflight.shots.records import ShotRecord, ShotSet, read_shots, write_shots
from golfflight.weights_schema import load_bundle

from golfflight.cli import main

torch.set_num_threads(1)


@pytest.fixture(scope="module")
def base(tiny_shots, tmp_path_factory):
    """A barely trained Phys-NN+ (one epoch) as run directory and bundle: fine-tuning has room to improve it."""
    root = tmp_path_factory.mktemp("base")
    train(
        tiny_shots, root / "run", TrainConfig(variant="phys-nn+", hidden=(16,), epochs=1, batch_size=64), progress=False
    )
    export_checkpoint(root / "run", root / "bundle")
    return root


@pytest.fixture(scope="module")
def unsplit(tiny_shots, tmp_path_factory):
    """The tiny shots without a split column, as a user's own recordings would come."""
    path = tmp_path_factory.mktemp("user") / "mine.csv"
    write_shots(path, [r.model_copy(update={"split": None}) for r in read_shots(tiny_shots).records])
    return path


@pytest.mark.parametrize("variant", ["phys-nn+", "phys-q"])
def test_bundle_weights_round_trip(tiny_shots, tmp_path, variant):
    settings = {"hidden": (16,)} if variant != "phys-q" else {}
    train(
        tiny_shots, tmp_path / "run", TrainConfig(variant=variant, epochs=1, batch_size=64, **settings), progress=False
    )
    export_checkpoint(tmp_path / "run", tmp_path / "bundle")
    model, card = model_from_bundle(tmp_path / "bundle")
    saved = load_checkpoint(tmp_path / "run" / "best.pt")
    for name, tensor in saved["model"].items():
        torch.testing.assert_close(model.state_dict()[name], tensor, rtol=1e-6, atol=1e-7)
    config = config_from_card(card)
    assert (config.variant, config.loss, config.lr) == (variant, "lp+lh", 1e-3)
    assert variant == "phys-q" or config.hidden == (16,)


def _shots(sessions: list[str], stamps: list[str | None]) -> ShotSet:
    return ShotSet(
        [
            ShotRecord(
                shot_id=str(i),
                session=s,
                timestamp=t,
                ball_speed_mps=60.0,
                launch_angle_deg=12.0,
                launch_direction_deg=0.0,
                spin_rpm=3000.0,
                spin_axis_deg=0.0,
            )
            for i, (s, t) in enumerate(zip(sessions, stamps))
        ]
    )


def test_split_by_whole_recent_sessions():
    sessions = ["b"] * 4 + ["a"] * 4 + ["c"] * 2
    stamps = (
        [f"2025-01-02T10:0{i}" for i in range(4)]
        + [f"2025-01-01T10:0{i}" for i in range(4)]
        + [f"2025-01-03T10:0{i}" for i in range(2)]
    )
    split = assign_split(_shots(sessions, stamps), 0.3).column("split")
    assert list(split) == ["val"] * 4 + ["train"] * 4 + ["val"] * 2, "c, then b (by time) until 30 % are held out"
    split = assign_split(_shots(sessions, [None] * 10), 0.2).column("split")
    assert list(split) == ["train"] * 8 + ["val"] * 2, "without timestamps, file order: c is the most recent"


def test_split_of_one_session_takes_the_last_shots():
    split = assign_split(_shots(["x"] * 10, [None] * 10), 0.3).column("split")
    assert list(split) == ["train"] * 7 + ["val"] * 3
    with pytest.raises(ValueError, match="between 0 and 1"):
        assign_split(_shots(["x"] * 3, [None] * 3), 1.0)


@pytest.mark.parametrize("source", ["bundle", "run"])
def test_finetune_lowers_the_loss_and_writes_a_bundle(base, unsplit, tmp_path, source):
    start = load_base(base / source)
    out = tmp_path / "mine"
    result = finetune(base / source, unsplit, out, epochs=3, lr=3e-3, batch_size=32, progress=False)
    history = result.run.history
    assert history[-1]["train_lp_m"] < history[0]["train_lp_m"]
    assert result.improved and result.run.best["landing_error_m"] < result.base_metrics["landing_error_m"]
    card, _ = load_bundle(out)
    assert card.variant == start.config.variant and card.architecture.hidden_units == [16]
    assert card.validation.landing_error_m == pytest.approx(result.run.best["landing_error_m"])
    assert card.training.learning_rate == 3e-3 and card.training_data.n_val >= 1
    summary = json.loads((out / RUN_DIR / "finetune.json").read_text())
    assert summary["bundle_written"] and source in summary["base"]


def test_no_bundle_when_fine_tuning_does_not_help(base, tiny_shots, tmp_path):
    result = finetune(base / "bundle", tiny_shots, tmp_path / "out", epochs=1, lr=1e-12, batch_size=32, progress=False)
    assert not result.improved and not (tmp_path / "out" / "model_card.json").exists()


def test_command_line(base, unsplit, tmp_path, capsys):
    args = [
        "finetune",
        "--model",
        str(base / "bundle"),
        "--data",
        str(unsplit),
        "--epochs",
        "2",
        "--lr",
        "3e-3",
        "--batch-size",
        "32",
        "--out",
        str(tmp_path / "mine"),
        "--compile",
    ]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "before: val landing error" in out and "wrote" in out
    assert np.isfinite(load_bundle(tmp_path / "mine")[0].validation.landing_error_m)
