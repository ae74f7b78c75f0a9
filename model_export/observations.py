"""A merged real-flight file (`model_export.real_data`) as training tensors: every observable a record has, with its
measurement noise, the sampled path where there is one, and the indices of the latent conditions each shot shares.

Noise figures (1 sigma, `NOISE`): the radar assumption of the synthetic generator (`shots.synth.MeasurementNoise`):
carry point 0.4 m + 0.4 % of the carry per axis, apex 0.3 m, flight time 0.05 s, landing angle 0.4 deg; path
positions 0.3 m. A radar path is one smooth fit, so its samples are not independent: a whole path counts as
`PATH_OBSERVATIONS` observations however many samples it has.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.physics import initial_state, reynolds_scale
from golfflight.shots.records import ShotSet, read_shots, read_trajectories, trajectories_path
from golfflight.shots.synth import MeasurementNoise

NOISE = MeasurementNoise()
PATH_SIGMA_M = 0.3
PATH_OBSERVATIONS = 3.0
OBSERVABLES = ("carry_x_m", "carry_y_m", "apex_m", "flight_time_s", "landing_angle_deg")
TOUR_SOURCES = ("sentry-2022", "players-2020", "tour-championship-2020")
"""Sources grouped by tour hole and round ('016-R2-H15'): one wind per hole and round, one air per round."""
CALM_SOURCES = ("synthetic", "trackman-model", "pga-2023-table")
"""Flown calm by construction (the reference world, TrackMan's model) or averaged over many winds (the table)."""
FIXED_AIR_SOURCES = ("synthetic", "pga-2023-table")
"""Flown in exactly their stated air: no latent air group (the synthetic sessions' standard air, the table's)."""
REFERENCE_BALLS = (None, "Premium")
"""Ball types the network itself learns (tour balls are unnamed); every other type gets a latent drag/lift scale."""


def noise_sigma(shots: ShotSet) -> np.ndarray:
    """1-sigma measurement noise [N, 5] of each observable (order `OBSERVABLES`)."""
    carry = np.hypot(shots.column("carry_x_m"), shots.column("carry_y_m"))
    carry_sigma = NOISE.carry_m + NOISE.carry_fraction * np.nan_to_num(carry)
    n = len(shots)
    return np.stack([carry_sigma, carry_sigma, np.full(n, NOISE.apex_m), np.full(n, NOISE.flight_time_s),
                     np.full(n, NOISE.landing_angle_deg)], axis=1)


@dataclass
class Index:
    """Names of a latent family's groups; index -1 means 'no latent' (validation shots, reference balls)."""

    names: list[str]

    def __len__(self) -> int:
        return len(self.names)


@dataclass
class ObservedShots:
    """Shots as tensors [N, ...]: launch state, air, observables (masked) with their noise, path samples relative
    to the start point (masked), the source weight, and indices of the shot's wind group, air group and ball."""

    position: torch.Tensor
    velocity: torch.Tensor
    spin: torch.Tensor
    density: torch.Tensor
    reynolds_scale: torch.Tensor
    targets: torch.Tensor
    target_mask: torch.Tensor
    sigma: torch.Tensor
    path_times: torch.Tensor
    path_positions: torch.Tensor
    path_mask: torch.Tensor
    weight: torch.Tensor
    source: torch.Tensor
    wind_group: torch.Tensor
    air_group: torch.Tensor
    ball: torch.Tensor

    def __len__(self) -> int:
        return self.position.shape[0]

    def take(self, index: torch.Tensor) -> ObservedShots:
        return ObservedShots(*(getattr(self, name)[index] for name in self.__dataclass_fields__))

    def to(self, device: torch.device) -> ObservedShots:
        """The same shots on `device` (themselves where they are there already)."""
        return ObservedShots(*(getattr(self, name).to(device) for name in self.__dataclass_fields__))


@dataclass
class ObservedData:
    """Train and validation tensors of a merged file and the names behind their indices."""

    train: ObservedShots
    val: ObservedShots
    sources: list[str]
    wind_groups: Index
    air_groups: Index
    balls: Index
    n_rows: int


def _paths(shots: ShotSet, paths: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    width = max((len(paths.get(r.shot_id, ())) for r in shots.records), default=0)
    times, positions = np.zeros((len(shots), max(width, 1))), np.zeros((len(shots), max(width, 1), 3))
    mask = np.zeros((len(shots), max(width, 1)), dtype=bool)
    for i, record in enumerate(shots.records):
        samples = paths.get(record.shot_id)
        if samples is not None and len(samples):
            k = len(samples)
            times[i, :k], positions[i, :k], mask[i, :k] = samples[:, 0], samples[:, 1:4], True
    return times, positions, mask


def _indices(values: list[str | None], names: list[str]) -> np.ndarray:
    lookup = {name: i for i, name in enumerate(names)}
    return np.array([lookup.get(v, -1) if v is not None else -1 for v in values], dtype=np.int64)


def _tensors(shots: ShotSet, paths: dict[str, np.ndarray], weights: dict[str, float], sources: list[str],
             wind: list[str], air: list[str], balls: list[str]) -> ObservedShots:
    state = initial_state(**shots.launch())
    targets = np.stack([shots.column(name) for name in OBSERVABLES], axis=1)
    times, positions, path_mask = _paths(shots, paths)
    recorded_air = shots.air()
    source = list(shots.column("source"))
    air_keys = [_air_key(s, g) for s, g in zip(source, shots.column("group"))]

    def f32(array: np.ndarray) -> torch.Tensor:
        return torch.as_tensor(np.nan_to_num(np.asarray(array, dtype=float)), dtype=torch.float32)

    return ObservedShots(
        f32(state.position), f32(state.velocity), f32(state.spin), f32(recorded_air.density_kg_m3),
        f32(reynolds_scale(recorded_air.kinematic_viscosity_m2_s, Air.standard().kinematic_viscosity_m2_s)),
        f32(targets), torch.as_tensor(~np.isnan(targets)), f32(noise_sigma(shots)),
        f32(times), f32(positions), torch.as_tensor(path_mask),
        f32([weights[s] for s in source]), torch.as_tensor(_indices(source, sources)),
        torch.as_tensor(_indices(list(shots.column("group")), wind)), torch.as_tensor(_indices(air_keys, air)),
        torch.as_tensor(_indices([b if b not in REFERENCE_BALLS else None for b in shots.column("ball")], balls)),
    )


def _air_key(source: str | None, group: str | None) -> str | None:
    """Air group of a shot: one day's air on tour (the round), one block's on a range, one for a modelled source;
    none for the sources flown in exactly their stated air."""
    if source in FIXED_AIR_SOURCES or group is None:
        return None
    if source == "trackman-model":
        return source
    if source in TOUR_SOURCES:
        return "-".join(group.split("-")[:2])
    return group


def load_observed(path: str | os.PathLike, weights: dict[str, float]) -> ObservedData:
    """Read a merged file (with `source`, `group`, `split` columns) and its trajectories companion. Latent groups
    are made from the training rows only (a validation shot is flown in the air and wind the model assumes)."""
    path = Path(path)
    shots = read_shots(path)
    companion = trajectories_path(path)
    paths = read_trajectories(companion) if companion.is_file() else {}
    unknown = sorted({s for s in shots.column("source") if s not in weights})
    if unknown:
        raise InputError(f"{path}: sources {unknown} have no weight (weights given for {sorted(weights)})")
    split = shots.column("split")
    train, val = shots.subset(split == "train"), shots.subset(split == "val")
    if not len(train) or not len(val):
        raise InputError(f"{path}: need rows marked 'train' and 'val' (have {len(train)} and {len(val)})")
    sources = list(dict.fromkeys(shots.column("source")))
    wind = [g for g, s in dict.fromkeys(zip(train.column("group"), train.column("source")))
            if g and s not in CALM_SOURCES]
    air = [k for k in dict.fromkeys(_air_key(s, g) for s, g in zip(train.column("source"), train.column("group")))
           if k is not None]
    balls = sorted({b for b in train.column("ball") if b not in REFERENCE_BALLS})
    make = lambda part: _tensors(part, paths, weights, sources, wind, air, balls)  # noqa: E731
    return ObservedData(make(train), make(val), sources, Index(wind), Index(air), Index(balls), len(shots))
