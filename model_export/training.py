"""Training loop (paper section 2.3.3): Euler rollouts, soft-argmax landing loss L_p (+ max-height loss L_h),
Adam, per-epoch checkpoints with resume, the best checkpoint by validation landing error, NaN guards.

A run directory holds last.pt (resume point), best.pt (lowest validation landing error) and history.json;
every file is written to a temporary file beside it and renamed, so a crash never leaves half a checkpoint.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Literal

import torch
from golfflight.errors import InputError
from golfflight.flight.constants import YARD_M
from golfflight.flight.devices import DEFAULT_DEVICE, resolve_device
from golfflight.model_export import DEFAULT_HIDDEN, VARIANTS
from golfflight.model_export.data import MIN_APEX_M, DataSummary, ShotTensors, load_training_data
from golfflight.flight.integrator import FORWARD_EULER, StepRule
from golfflight.flight.rollout import (
    DT_S,
    SOFT_ARGMAX_TEMPERATURE_M,
    T_SIM_S,
    euler_rollout,
    hard_landing,
    soft_landing,
    step_rule,
)
from golfflight.model_export.variants import build_model
from golfflight.shots.files import write_atomic, write_text_atomic
from golfflight.shots.progress import print_line, progress_bar
from torch import nn

CHECKPOINT_FORMAT = 1
VALIDATION_BATCH = 4096
GRAD_CLIP_NORM = 100.0
"""Global gradient-norm cap (loss in metres). Phys-NN's norm runs 5-80 over its first steps, so only spikes are cut;
Phys-Q's (50-400) is cut more often, which Adam's per-parameter scaling makes harmless."""


@dataclass
class TrainConfig:
    """Everything that decides a training run (stored in every checkpoint and in the model card)."""

    variant: str = "phys-nn+"
    hidden: tuple[int, ...] = DEFAULT_HIDDEN
    epochs: int = 50
    batch_size: int = 1024
    lr: float = 1e-3
    loss: Literal["lp", "lp+lh", "observables"] = "lp+lh"
    """The paper's landing loss, with its max-height loss, or (recorded only: `model_export.joint` trains it) every
    observable weighted by its noise."""
    seed: int = 0
    grad_clip_norm: float = GRAD_CLIP_NORM
    soft_argmax_temperature_m: float = SOFT_ARGMAX_TEMPERATURE_M
    min_apex_m: float = MIN_APEX_M
    limit: int | None = None
    dt_s: float = DT_S
    t_sim_s: float = T_SIM_S

    def __post_init__(self) -> None:
        self.hidden = tuple(int(h) for h in self.hidden)
        if self.variant not in VARIANTS:
            raise InputError(f"unknown variant {self.variant!r}; choose from {', '.join(VARIANTS)}")
        if self.loss not in ("lp", "lp+lh", "observables"):
            raise InputError(f"loss must be 'lp', 'lp+lh' or 'observables', not {self.loss!r}")
        if self.variant == "nn" and self.loss != "lp":
            raise InputError("the NN baseline predicts the landing point only: train it with --loss lp")

    def as_dict(self) -> dict[str, Any]:
        return {**asdict(self), "hidden": list(self.hidden)}


@dataclass
class RunResult:
    """What `train` leaves behind: the run directory's checkpoints and the per-epoch history."""

    out_dir: Path
    history: list[dict[str, Any]]
    best: dict[str, Any] | None
    data: DataSummary
    skipped_batches: int = 0


def predict(
    model: nn.Module, shots: ShotTensors, config: TrainConfig, soft: bool, step: StepRule = FORWARD_EULER
) -> tuple[torch.Tensor, torch.Tensor | None]:
    """Landing point [N,2] and apex [N] (None for the NN baseline): soft-argmax landing for training, the runtime's
    landing (first crossing interpolated to r_z = 0) for validation; the apex as the runtime measures it. The soft
    landing weighs every step; validation's rollout stops once every shot has come down (`euler_rollout`). `step`:
    `flight.rollout.step_rule`'s forward Euler, eager or compiled."""
    if config.variant == "nn":
        return model(shots.velocity, shots.spin), None
    trajectory = euler_rollout(
        shots.position,
        shots.velocity,
        shots.spin,
        model,
        shots.density,
        config.dt_s,
        config.t_sim_s,
        shots.reynolds_scale[:, None],
        step=step,
        stop_after_s=None if soft else 0.0,
    )
    if soft:
        landing = soft_landing(trajectory, config.soft_argmax_temperature_m)
    else:
        landing = hard_landing(trajectory).position[:, :2]
    return landing, trajectory.apex_m


def _masked_mean(values: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    return torch.where(mask, values, torch.zeros_like(values)).sum() / mask.sum().clamp_min(1)


def errors(landing: torch.Tensor, apex: torch.Tensor | None, shots: ShotTensors) -> tuple[torch.Tensor, torch.Tensor]:
    """Mean landing-point distance L_p and mean absolute max-height error L_h (m) over the shots that have
    each target (L_h is zero without an apex prediction)."""
    l_p = _masked_mean(torch.linalg.vector_norm(landing - shots.landing, dim=-1), shots.landing_mask)
    if apex is None:
        return l_p, torch.zeros_like(l_p)
    return l_p, _masked_mean((apex - shots.apex).abs(), shots.apex_mask)


@torch.no_grad()
def validate(model: nn.Module, shots: ShotTensors, config: TrainConfig, step: StepRule = FORWARD_EULER
             ) -> dict[str, float]:
    """Validation metrics with the runtime's landing and apex (`rollout.hard_landing`, `apex`), in m and yd
    (`step` as `predict` takes it)."""
    model.eval()
    sums = {"landing": 0.0, "apex": 0.0}
    for start in range(0, len(shots), VALIDATION_BATCH):
        stop = min(start + VALIDATION_BATCH, len(shots))
        batch = shots.take(torch.arange(start, stop, device=shots.position.device))
        landing, apex = predict(model, batch, config, soft=False, step=step)
        l_p, l_h = errors(landing, apex, batch)
        sums["landing"] += float(l_p) * int(batch.landing_mask.sum())
        sums["apex"] += float(l_h) * int(batch.apex_mask.sum())
    model.train()
    landing_m = sums["landing"] / max(int(shots.landing_mask.sum()), 1)
    metrics = {"landing_error_m": landing_m, "landing_error_yd": landing_m / YARD_M}
    if config.variant != "nn":
        apex_m = sums["apex"] / max(int(shots.apex_mask.sum()), 1)
        metrics |= {"max_height_error_m": apex_m, "max_height_error_yd": apex_m / YARD_M}
    return metrics


def save_checkpoint(path: Path, payload: dict[str, Any]) -> None:
    """torch.save to a temporary file in the same directory, then rename over `path`."""
    write_atomic(path, lambda tmp: torch.save(payload, tmp), mode=0o600)


def load_checkpoint(path: str | os.PathLike) -> dict[str, Any]:
    """A checkpoint written by `save_checkpoint` (tensors and plain values only: weights_only loading, which never
    unpickles code); InputError naming the file for anything else."""
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as error:  # noqa: BLE001 - torch's weights-only reader raises many types on a corrupt file
        raise InputError(f"{path}: not a readable checkpoint ({type(error).__name__}: {error})") from None
    if not isinstance(payload, dict) or payload.get("format") != CHECKPOINT_FORMAT:
        found = payload.get("format") if isinstance(payload, dict) else type(payload).__name__
        raise InputError(f"{path}: not a golfflight training checkpoint (format {found!r})")
    return payload


def model_from_checkpoint(payload: dict[str, Any]) -> tuple[nn.Module, TrainConfig]:
    """Rebuild the trained model (eval mode, float32) and its training configuration."""
    config = TrainConfig(**payload["config"])
    model = build_model(config.variant, config.hidden)
    model.load_state_dict(payload["model"])
    return model.eval(), config


def _write_json(path: Path, data: Any) -> None:
    write_text_atomic(path, json.dumps(data, indent=2) + "\n")


def _check_resume(payload: dict[str, Any], config: TrainConfig, data: DataSummary) -> None:
    if payload["data"]["sha256"] != data.sha256:
        raise InputError(
            f"--resume: the checkpoint was trained on another data file ({payload['data']['file']}, different SHA-256)"
        )
    saved = {k: v for k, v in payload["config"].items() if k != "epochs"}
    given = {k: v for k, v in config.as_dict().items() if k != "epochs"}
    changed = [f"{k}: {saved.get(k)!r} in the checkpoint, {v!r} now" for k, v in given.items() if saved.get(k) != v]
    if changed:
        raise InputError("--resume with different settings: " + "; ".join(changed))


def _train_epoch(
    model: nn.Module,
    optimizer: torch.optim.Optimizer,
    shots: ShotTensors,
    config: TrainConfig,
    epoch: int,
    progress: bool,
    step: StepRule,
) -> dict[str, Any]:
    """One pass over the training shots in a seeded order (drawn on the CPU, so every device takes the same); a
    batch whose loss or gradient is not finite is skipped (no optimiser step) and counted. Returns the mean L_p, L_h
    of the steps taken (None if none)."""
    order = torch.randperm(len(shots), generator=torch.Generator().manual_seed(config.seed * 100_003 + epoch))
    order = order.to(shots.position.device)
    sums, steps, skipped = {"lp": 0.0, "lh": 0.0}, 0, 0
    n_batches = math.ceil(len(shots) / config.batch_size)
    bar = progress_bar(range(n_batches), f"epoch {epoch}/{config.epochs}", unit="batch", shown=progress)
    for b in bar:
        batch = shots.take(order[b * config.batch_size : (b + 1) * config.batch_size])
        optimizer.zero_grad(set_to_none=True)
        l_p, l_h = errors(*predict(model, batch, config, soft=True, step=step), batch)
        loss = l_p + l_h if config.loss == "lp+lh" else l_p
        if not torch.isfinite(loss):
            skipped += 1
            continue
        loss.backward()
        grad_norm = torch.nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip_norm)
        if not torch.isfinite(grad_norm):
            optimizer.zero_grad(set_to_none=True)
            skipped += 1
            continue
        optimizer.step()
        steps += 1
        sums["lp"] += float(l_p.detach())
        sums["lh"] += float(l_h.detach())
        bar.set_postfix(Lp=f"{sums['lp'] / steps:.2f}m", Lh=f"{sums['lh'] / steps:.2f}m", skipped=skipped)
    return {
        "train_lp_m": sums["lp"] / steps if steps else None,
        "train_lh_m": sums["lh"] / steps if steps else None,
        "skipped_batches": skipped,
    }


def _epoch_line(row: dict[str, Any]) -> str:
    train_lp = "n/a" if row["train_lp_m"] is None else f"{row['train_lp_m']:.3f} m"
    line = f"epoch {row['epoch']}: train Lp {train_lp}, val landing {row['val_landing_error_m']:.3f} m"
    if "val_max_height_error_m" in row:
        line += f", val max height {row['val_max_height_error_m']:.3f} m"
    if row["skipped_batches"]:
        line += f", {row['skipped_batches']} batches skipped"
    return line


def train(
    data_path: str | os.PathLike,
    out_dir: str | os.PathLike,
    config: TrainConfig,
    resume: bool = False,
    progress: bool = True,
    init_state: dict[str, torch.Tensor] | None = None,
    skip_bad_rows: bool = False,
    device: str = DEFAULT_DEVICE,
    compile_step: bool = False,
) -> RunResult:
    """Train `config.variant` on the file's train split, validating on its val split after every epoch.

    `init_state` starts from these weights instead of a fresh initialisation (fine-tuning; with `resume`, the run's
    own last.pt wins); `skip_bad_rows` leaves malformed rows of the data file out (listed in the result's data
    summary) instead of refusing it; `device` is where the model and the shots live ("cpu", "cuda"; the model is
    initialised and the batches drawn on the CPU either way, `devices.DeviceError` where it is missing);
    `compile_step` fuses each Euler step's kernels, forward and backward, with torch.compile
    (`flight.rollout.step_rule`).
    Denormal floats are flushed to zero while training (without it the first backward passes through the rollout
    hit denormals and a CPU batch runs 20-100x slower), and the CPU's normal mode is restored afterwards."""
    if config.loss == "observables":
        raise InputError("the 'observables' loss is trained by model_export.joint (golfflight train-real)")
    where = resolve_device(device)
    torch.set_flush_denormal(True)
    try:
        return _train(data_path, out_dir, config, resume, progress, init_state, skip_bad_rows, where,
                      step_rule(compile_step))
    finally:
        torch.set_flush_denormal(False)


def _train(
    data_path: str | os.PathLike,
    out_dir: str | os.PathLike,
    config: TrainConfig,
    resume: bool,
    progress: bool,
    init_state: dict[str, torch.Tensor] | None,
    skip_bad_rows: bool,
    device: torch.device,
    step: StepRule,
) -> RunResult:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    train_set, val_set, data = load_training_data(
        data_path, config.limit, config.min_apex_m, skip_bad_rows=skip_bad_rows
    )
    train_set, val_set = train_set.to(device), val_set.to(device)
    torch.manual_seed(config.seed)
    model = build_model(config.variant, config.hidden)
    if init_state is not None:
        model.load_state_dict(init_state)
    model.to(device)
    optimizer = torch.optim.Adam(model.parameters(), lr=config.lr)
    history: list[dict[str, Any]] = []
    best: dict[str, Any] | None = None
    first_epoch = 1
    if resume:
        payload = load_checkpoint(out_dir / "last.pt")
        _check_resume(payload, config, data)
        model.load_state_dict(payload["model"])
        optimizer.load_state_dict(payload["optimizer"])
        history, best, first_epoch = payload["history"], payload["best"], payload["epoch"] + 1

    for epoch in range(first_epoch, config.epochs + 1):
        started = time.perf_counter()
        row = {"epoch": epoch, **_train_epoch(model, optimizer, train_set, config, epoch, progress, step)}
        row["train_seconds"] = time.perf_counter() - started
        metrics = validate(model, val_set, config, step)
        row |= {"epoch_seconds": time.perf_counter() - started, **{f"val_{k}": v for k, v in metrics.items()}}
        history.append(row)
        if progress:
            print_line(_epoch_line(row))
        improved = math.isfinite(metrics["landing_error_m"]) and (
            best is None or metrics["landing_error_m"] < best["landing_error_m"]
        )
        if improved:
            best = {"epoch": epoch, **metrics}
        payload = {
            "format": CHECKPOINT_FORMAT,
            "epoch": epoch,
            "config": config.as_dict(),
            "data": data.as_dict(),
            "model": model.state_dict(),
            "optimizer": optimizer.state_dict(),
            "history": history,
            "best": best,
            "metrics": {"epoch": epoch, **metrics},
            "torch_version": str(torch.__version__),
        }
        save_checkpoint(out_dir / "last.pt", payload)
        if improved:
            save_checkpoint(out_dir / "best.pt", payload)
        _write_json(
            out_dir / "history.json",
            {"config": config.as_dict(), "data": data.as_dict(), "best": best, "epochs": history},
        )
    return RunResult(out_dir, history, best, data, sum(row["skipped_batches"] for row in history))
