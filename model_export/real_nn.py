"""The NN baseline (paper eq. 23: launch velocity and spin -> landing point) trained on the real flights' merged file,
as `train-real --variant nn` trains it: the same shots, split, source weights, minibatch order, learning-rate
schedule and landing loss (`joint.shot_losses` with its fitted noise factors) as the physics variants.

It flies nothing, so it cannot use the latent conditions: a shot's wind, air and ball are not its inputs, and it
learns each source's recordings as they are. It has no height, flight time or path, so it learns the landing
only, and the sources that record only an apex (the TOUR Championship) neither teach nor score it.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
from golfflight.errors import InputError
from golfflight.evaluation.landing_network import LANDING_WEIGHTS_FILE
from golfflight.model_export.joint import (
    JointConfig,
    JointResult,
    NoiseScales,
    Predicted,
    cosine_factor,
    felt_error_m,
    score,
    shot_losses,
    spread_heavy_rows,
)
from golfflight.model_export.observations import ObservedShots, load_observed
from golfflight.model_export.training import CHECKPOINT_FORMAT, load_checkpoint, save_checkpoint
from golfflight.model_export.variants import LANDING_SCALE_M, SPIN_SCALE_RADPS, VELOCITY_SCALE_MPS, LandingNN
from golfflight.shots.files import write_text_atomic
from golfflight.shots.progress import print_line, progress_bar
from torch import nn

CHECKPOINT_KIND = "landing-nn"


def landing_only(shots: ObservedShots) -> ObservedShots:
    """The shots with only their landing point as a target (no apex, time, angle or path): what NN can predict."""
    mask = shots.target_mask.clone()
    mask[:, 2:] = False
    return replace(shots, target_mask=mask, path_mask=torch.zeros_like(shots.path_mask))


def predicted(model: nn.Module, shots: ObservedShots) -> Predicted:
    """NN's landing point in the layout of a flight's observables (the other columns unused, every shot landed)."""
    landing = model(shots.velocity, shots.spin)
    rest = landing.new_zeros(len(shots), 3)
    return Predicted(torch.cat([landing, rest], dim=1), torch.zeros_like(shots.path_positions),
                     torch.ones(len(shots), dtype=torch.bool, device=landing.device))


def nn_selection_loss(metrics: dict[str, Any], config: JointConfig) -> float:
    """`joint.selection_loss` over the `select_on` sources that record a carry (NN predicts no apex)."""
    rows = [v for k, v in metrics["sources"].items() if k in config.select_on and "carry_y_m_mae" in v]
    return sum(felt_error_m(v) for v in rows) / max(len(rows), 1)


@torch.no_grad()
def evaluate_nn(model: nn.Module, shots: ObservedShots, config: JointConfig, sources: list[str]) -> dict[str, Any]:
    """NN's loss and per-source landing errors on `shots` (`joint.score`, landing only)."""
    shots = landing_only(shots)
    return score(predicted(model, shots), shots, config, sources)


def train_landing_nn(data_path: str | os.PathLike, out_dir: str | os.PathLike, config: JointConfig,
                     hidden: tuple[int, ...], progress: bool = True) -> JointResult:
    """Train NN from a fresh network (initialised from `config.seed`) on the merged file's landing points; writes
    OUT/last.pt (kind 'landing-nn') and history.json of the last epoch, as a joint run does, and its weights as
    NumPy arrays (LANDING_WEIGHTS_FILE) for the torch-free comparison."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    data = load_observed(data_path, config.weights)
    torch.manual_seed(config.seed)
    model, noise = LandingNN(hidden), NoiseScales(len(data.sources))
    optimizer = torch.optim.Adam([{"params": model.parameters(), "lr": config.lr},
                                  {"params": noise.parameters(), "lr": config.noise_lr}])
    train = spread_heavy_rows(landing_only(data.train))
    total_steps = config.epochs * math.ceil(len(train) / config.batch_size)
    schedule = torch.optim.lr_scheduler.LambdaLR(
        optimizer, lambda step: cosine_factor(step, total_steps, config.final_lr_fraction))
    history: list[dict[str, Any]] = []
    for epoch in range(1, config.epochs + 1):
        train_loss = _epoch(model, noise, optimizer, schedule, train, config, epoch, progress)
        metrics = evaluate_nn(model, data.val, config, data.sources)
        history.append({"epoch": epoch, "train_loss": train_loss, "val_loss": metrics["loss"],
                        "val": metrics["sources"], "selection_loss": nn_selection_loss(metrics, config)})
        if progress:
            print_line(f"epoch {epoch}: train {train_loss:.3f}, felt {history[-1]['selection_loss']:.2f} m")
    final = {"epoch": config.epochs, "val_loss": history[-1]["selection_loss"], "val": history[-1]["val"]}
    save_checkpoint(out / "last.pt", {"format": CHECKPOINT_FORMAT, "kind": CHECKPOINT_KIND, "epoch": config.epochs,
                                      "config": config.as_dict(), "hidden": list(hidden),
                                      "model": model.state_dict(), "noise": noise.run_state(0), "history": history})
    write_text_atomic(out / "history.json",
                      json.dumps({"config": config.as_dict(), "final": final, "epochs": history}, indent=2) + "\n")
    write_landing_weights(model, out / LANDING_WEIGHTS_FILE)
    return JointResult(out, history, final)


def write_landing_weights(model: LandingNN, path: Path) -> None:
    """The network's layers and scales as NumPy arrays (`evaluation.landing_network` reads them without torch)."""
    layers = [layer for layer in model.net if isinstance(layer, nn.Linear)]
    arrays = {f"weight_{i}": layer.weight.detach().numpy() for i, layer in enumerate(layers)}
    arrays |= {f"bias_{i}": layer.bias.detach().numpy() for i, layer in enumerate(layers)}
    arrays["input_scale"] = np.array([VELOCITY_SCALE_MPS] * 3 + [SPIN_SCALE_RADPS] * 3)
    arrays["output_scale"] = np.array(LANDING_SCALE_M)
    with path.open("wb") as handle:
        np.savez(handle, **arrays)


def _epoch(model: nn.Module, noise: NoiseScales, optimizer: torch.optim.Optimizer,
           schedule: torch.optim.lr_scheduler.LRScheduler, train: ObservedShots, config: JointConfig, epoch: int,
           progress: bool) -> float:
    """One epoch in the joint runs' minibatch order (seeded by seed and epoch); the mean minibatch loss."""
    order = torch.randperm(len(train), generator=torch.Generator().manual_seed(config.seed * 100_003 + epoch))
    total_weight, sums, steps = float(train.weight.sum()), 0.0, 0
    for start in progress_bar(range(0, len(train), config.batch_size), f"epoch {epoch}/{config.epochs}",
                              unit="batch", shown=progress):
        batch = train.take(order[start:start + config.batch_size])
        optimizer.zero_grad(set_to_none=True)
        losses = shot_losses(predicted(model, batch), batch, config.huber_delta, noise.factors()[0, batch.source])
        loss = (losses * batch.weight).sum() / total_weight * (len(train) / len(batch))
        if not torch.isfinite(loss):
            continue
        loss.backward()
        nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip_norm)
        optimizer.step()
        schedule.step()
        sums, steps = sums + float(loss.detach()), steps + 1
    return sums / max(steps, 1)


def landing_nn_from_checkpoint(path: str | os.PathLike) -> LandingNN:
    """The trained NN of a `train_landing_nn` run's last.pt, in eval mode. A checkpoint of another kind is refused."""
    payload = load_checkpoint(path)
    if payload.get("kind") != CHECKPOINT_KIND:
        raise InputError(f"{path} is not an NN run of train-real --variant nn (kind {payload.get('kind')!r})")
    model = LandingNN(tuple(payload["hidden"]))
    model.load_state_dict(payload["model"])
    return model.eval()
