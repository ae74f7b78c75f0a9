"""Canonical shot CSV -> training tensors: launch state, targets with masks, per-shot air density, and the split.

The validation split is the one marked in the file's `split` column (the paper holds out the most recent
10 %), never a random shuffle. Every shot left out is counted in `DataSummary.filters`.
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.physics import initial_state, reynolds_scale
from golfflight.shots.records import ShotSet, read_shots
from golfflight.shots.synth import MIN_APEX_M
from golfflight.weights_schema.bundle import sha256_of


@dataclass
class ShotTensors:
    """One split as tensors [N,...]: initial state, targets (NaN-free, with masks), air density and the Reynolds
    scale of the network's inputs (`flight.physics.reynolds_scale`; 1 in standard air)."""

    position: torch.Tensor
    velocity: torch.Tensor
    spin: torch.Tensor
    density: torch.Tensor
    reynolds_scale: torch.Tensor
    landing: torch.Tensor
    landing_mask: torch.Tensor
    apex: torch.Tensor
    apex_mask: torch.Tensor

    def __len__(self) -> int:
        return self.position.shape[0]

    def take(self, index: torch.Tensor) -> ShotTensors:
        """The shots at `index` (a batch)."""
        return ShotTensors(*(getattr(self, name)[index] for name in self.__dataclass_fields__))

    def to(self, device: torch.device) -> ShotTensors:
        """The same shots on `device` (themselves where they are there already)."""
        return ShotTensors(*(getattr(self, name).to(device) for name in self.__dataclass_fields__))


@dataclass
class DataSummary:
    """What the model was trained on, for checkpoints and the model card (field names as in the card's
    `TrainingData`). Recorded wind is counted but not simulated: training is in calm air, as in the paper."""

    file: str
    sha256: str
    n_rows: int
    n_train: int
    n_val: int
    n_landing_targets: int
    n_apex_targets: int
    density_min_kg_m3: float
    density_max_kg_m3: float
    n_with_wind: int
    min_apex_m: float
    filters: dict[str, int] = field(default_factory=dict)
    bad_rows: list[str] = field(default_factory=list)
    """Each malformed row left out with `skip_bad_rows` (file, line, column, value, reason); counted in filters."""

    def as_dict(self) -> dict:
        """The fields recorded in checkpoints and the model card (the bad rows themselves are only reported)."""
        return {k: v for k, v in asdict(self).items() if k != "bad_rows"}


def to_tensors(shots: ShotSet, dtype: torch.dtype = torch.float32) -> ShotTensors:
    """Initial state from `flight.physics.initial_state` (one source for eq. 12) and the targets of a set of shots."""
    state = initial_state(**shots.launch())
    landing = np.stack([shots.column("carry_x_m"), shots.column("carry_y_m")], -1)
    apex = shots.column("apex_m")
    landing_mask = ~np.isnan(landing).any(-1)
    apex_mask = ~np.isnan(apex)

    def tensor(array: np.ndarray) -> torch.Tensor:
        return torch.as_tensor(np.nan_to_num(array), dtype=dtype)

    air = shots.air()
    return ShotTensors(
        tensor(state.position),
        tensor(state.velocity),
        tensor(state.spin),
        tensor(air.density_kg_m3),
        tensor(reynolds_scale(air.kinematic_viscosity_m2_s, Air.standard().kinematic_viscosity_m2_s)),
        tensor(landing),
        torch.as_tensor(landing_mask),
        tensor(apex),
        torch.as_tensor(apex_mask),
    )


def _first(mask: np.ndarray, count: int) -> np.ndarray:
    keep = mask.copy()
    keep[np.flatnonzero(mask)[count:]] = False
    return keep


def load_training_data(
    path: str | os.PathLike,
    limit: int | None = None,
    min_apex_m: float = MIN_APEX_M,
    dtype: torch.dtype = torch.float32,
    skip_bad_rows: bool = False,
) -> tuple[ShotTensors, ShotTensors, DataSummary]:
    """Read a canonical CSV and return (train, val, summary).

    A malformed row refuses the file (`RecordError`), or with `skip_bad_rows` is left out, counted as `bad_rows`
    and listed in `summary.bad_rows`.
    Dropped and counted, in this order: rows with no split mark, shots with neither a landing point nor an
    apex, shots whose recorded apex is under `min_apex_m` (shots with no apex recorded are kept). `limit`
    keeps at most that many shots, the first of each split in the file's train/val proportion (quick runs).
    """
    path = Path(path)
    shots = read_shots(path, skip_bad_rows=skip_bad_rows)
    split = shots.column("split")
    landing_known = ~np.isnan(shots.column("carry_x_m")) & ~np.isnan(shots.column("carry_y_m"))
    apex = shots.column("apex_m")
    keep = np.ones(len(shots), dtype=bool)
    filters = {"bad_rows": len({problem.line for problem in shots.skipped})} if shots.skipped else {}
    for name, dropped in (
        ("no_split_mark", np.array([s is None for s in split], dtype=bool)),
        ("no_target", ~landing_known & np.isnan(apex)),
        ("apex_below_min", apex < min_apex_m),
    ):
        filters[name] = int(np.sum(keep & dropped))
        keep &= ~dropped
    is_train, is_val = keep & (split == "train"), keep & (split == "val")
    if limit is not None and limit < int(keep.sum()):
        n_val = min(int(is_val.sum()), max(1, round(limit * is_val.sum() / keep.sum())))
        before = int(keep.sum())
        is_train, is_val = _first(is_train, limit - n_val), _first(is_val, n_val)
        filters["limit"] = before - int(is_train.sum() + is_val.sum())
    if not is_train.any() or not is_val.any():
        raise InputError(
            f"{path}: need shots marked 'train' and 'val' in the split column after filtering "
            f"(have {int(is_train.sum())} train, {int(is_val.sum())} val; left out: {filters})"
        )
    train, val = to_tensors(shots.subset(is_train), dtype), to_tensors(shots.subset(is_val), dtype)
    density = torch.cat([train.density, val.density])
    wind = shots.column("wind_speed_mps")
    summary = DataSummary(
        file=path.name,
        sha256=sha256_of(path),
        n_rows=len(shots),
        n_train=len(train),
        n_val=len(val),
        n_landing_targets=int(train.landing_mask.sum() + val.landing_mask.sum()),
        n_apex_targets=int(train.apex_mask.sum() + val.apex_mask.sum()),
        density_min_kg_m3=float(density.min()),
        density_max_kg_m3=float(density.max()),
        n_with_wind=int(np.sum((wind > 0) & (is_train | is_val))),
        min_apex_m=min_apex_m,
        filters=filters,
        bad_rows=[str(problem) for problem in shots.skipped],
    )
    return train, val, summary
