"""Fine-tune a trained model on a user's own canonical recordings and export the result as a new bundle.

Starts from a bundle (weights rebuilt from its ONNX graph) or a training run/checkpoint, trains with the same
losses and physics on the user's file, keeps the epoch with the lowest validation landing error, and writes a
bundle only if that epoch beats the starting model on the same validation shots (few shots overfit quickly).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
from golfflight.errors import InputError
from golfflight.flight.devices import DEFAULT_DEVICE, resolve_device
from golfflight.model_export.data import load_training_data
from golfflight.model_export.export import export_checkpoint
from golfflight.model_export.training import (
    RunResult,
    TrainConfig,
    load_checkpoint,
    model_from_checkpoint,
    train,
    validate,
)
from golfflight.shots.progress import progress_step
from golfflight.shots.records import ShotSet, read_shots, write_shots
from golfflight.weights_schema.bundle import CARD_FILE
from golfflight.weights_schema.model_card import ModelCard
from torch import nn

RUN_DIR = "finetune-run"
"""Subdirectory of the output bundle that holds the fine-tuning run (checkpoints, history, the split data)."""

SPLIT_FILE = "data_with_split.csv"


@dataclass
class BaseModel:
    """The starting point: its weights, its training settings and where it came from."""

    state: dict[str, torch.Tensor]
    config: TrainConfig
    source: str


def load_base(model: str | os.PathLike) -> BaseModel:
    """Weights and settings of a bundle directory, a run directory (its best.pt) or a checkpoint file."""
    path = Path(model)
    if (path / CARD_FILE).is_file():
        from golfflight.model_export.bundle_model import config_from_card, model_from_bundle

        module, card = model_from_bundle(path)
        return BaseModel(module.state_dict(), config_from_card(card), f"bundle {path} ({card.variant})")
    checkpoint = path / "best.pt" if path.is_dir() else path
    if not checkpoint.is_file():
        raise FileNotFoundError(f"{path}: neither a model bundle ({CARD_FILE}) nor a run directory or checkpoint")
    module, config = model_from_checkpoint(load_checkpoint(checkpoint))
    return BaseModel(module.state_dict(), config, f"checkpoint {checkpoint} ({config.variant})")


def assign_split(shots: ShotSet, val_fraction: float) -> ShotSet:
    """Mark the most recent `val_fraction` of the shots 'val', the rest 'train' (by timestamp where every shot has
    one, else by file order). With several sessions, whole sessions go to validation; with one, the last shots."""
    if not 0 < val_fraction < 1:
        raise InputError(f"the validation fraction must be between 0 and 1, got {val_fraction}")
    stamps = shots.column("timestamp")
    order = np.argsort(stamps, kind="stable") if all(t is not None for t in stamps) else np.arange(len(shots))
    sessions = shots.column("session")[order]
    names = list(dict.fromkeys(sessions))
    n_val = max(1, round(val_fraction * len(shots)))
    is_val = np.zeros(len(shots), dtype=bool)
    if len(names) > 1:
        chosen, count = [], 0
        for name in reversed(names[1:]):
            if count >= n_val:
                break
            chosen.append(name)
            count += int(np.sum(sessions == name))
        is_val[order[[s in chosen for s in sessions]]] = True
    else:
        is_val[order[len(shots) - n_val :]] = True
    return ShotSet([r.model_copy(update={"split": "val" if v else "train"}) for r, v in zip(shots.records, is_val)])


def prepare_data(data: str | os.PathLike, val_fraction: float, run_dir: Path) -> Path:
    """The file to train on: the user's own if it marks a split, else a copy in the run directory with one."""
    shots = read_shots(data)
    if any(s is not None for s in shots.column("split")):
        return Path(data)
    run_dir.mkdir(parents=True, exist_ok=True)
    path = run_dir / SPLIT_FILE
    write_shots(path, assign_split(shots, val_fraction).records)
    return path


@dataclass
class FinetuneResult:
    """The base model's and the best fine-tuned epoch's validation metrics, the run, and the card if written."""

    base_metrics: dict[str, float]
    run: RunResult
    card: ModelCard | None

    @property
    def improved(self) -> bool:
        return self.card is not None


def _base_metrics(base: BaseModel, config: TrainConfig, data: Path, device: torch.device) -> dict[str, float]:
    _, val, _ = load_training_data(data, None, config.min_apex_m)
    model: nn.Module = model_from_checkpoint({"config": config.as_dict(), "model": base.state})[0]
    return validate(model.to(device), val.to(device), config)


def finetune(
    model: str | os.PathLike,
    data: str | os.PathLike,
    out: str | os.PathLike,
    epochs: int,
    lr: float,
    batch_size: int,
    val_fraction: float = 0.2,
    seed: int = 0,
    progress: bool = True,
    device: str = DEFAULT_DEVICE,
    compile_step: bool = False,
) -> FinetuneResult:
    """Fine-tune `model` on `data` for `epochs` and export OUT (model.onnx + model_card.json) from the best epoch,
    if it beats the base model's validation landing error; the run goes to OUT/finetune-run/. With `progress`, its
    steps and epochs go to standard error and a line per epoch to standard output; `device` and `compile_step` as
    `training.train` takes them."""
    if epochs < 1:
        raise InputError(f"epochs must be at least 1, got {epochs}")
    where = resolve_device(device)
    out = Path(out)
    run_dir = out / RUN_DIR
    base = load_base(model)
    config = replace(base.config, epochs=epochs, lr=lr, batch_size=batch_size, seed=seed, limit=None)
    train_file = prepare_data(data, val_fraction, run_dir)
    progress_step("measuring the starting model on the validation shots...", progress)
    before = _base_metrics(base, config, train_file, where)
    result = train(train_file, run_dir, config, progress=progress, init_state=base.state, device=device,
                   compile_step=compile_step)
    improved = result.best is not None and result.best["landing_error_m"] < before["landing_error_m"]
    progress_step(f"exporting {out}...", progress and improved)
    card = export_checkpoint(run_dir, out) if improved else None
    summary: dict[str, Any] = {
        "base": base.source,
        "data": str(data),
        "trained_on": str(train_file),
        "base_validation": before,
        "best": result.best,
        "bundle_written": improved,
    }
    (run_dir / "finetune.json").write_text(json.dumps(summary, indent=2) + "\n")
    return FinetuneResult(before, result, card)
