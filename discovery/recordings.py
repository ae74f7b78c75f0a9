"""The recordings being diagnosed: launches, observed outcomes (NaN = not observed), groups and conditions as arrays."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from golfflight.flight.wind import wind_vector
from golfflight.shots.records import LAUNCH_COLUMNS, ShotSet, read_shots, read_trajectories, trajectories_path

OBSERVABLES: tuple[str, ...] = ("carry_y_m", "carry_x_m", "apex_m", "flight_time_s", "landing_angle_deg")
"""Outcome columns compared with the model, in report order: carry along and across the line, apex, time, descent."""

UNKNOWN_CLUB = "unknown"
"""The club of a shot recorded without one."""

LABELS = {
    "carry_y_m": "carry along the line (m)",
    "carry_x_m": "carry across the line (m, + right)",
    "apex_m": "apex (m)",
    "flight_time_s": "flight time (s)",
    "landing_angle_deg": "landing angle (deg)",
}

COVARIATES: tuple[str, ...] = (
    "ball_speed_mps",
    "launch_angle_deg",
    "spin_rpm",
    "spin_axis_deg",
    "launch_direction_deg",
    "shot_order",
)
"""Continuous quantities the residuals are tested against (club and session are tested as groups)."""


@dataclass
class Recordings:
    """Shots as arrays: the five recorded launch values, outcomes [N, 5] in OBSERVABLES order, and who/where/when."""

    launch: dict[str, np.ndarray]
    observed: np.ndarray
    session: np.ndarray
    club: np.ndarray
    shot_order: np.ndarray
    shot_id: np.ndarray
    density_kg_m3: np.ndarray | None = None
    wind_xy_mps: np.ndarray | None = None
    trajectories: dict[str, np.ndarray] = field(default_factory=dict)
    source: str = ""
    kinematic_viscosity_m2_s: np.ndarray | None = None
    """Per shot where the air is recorded: the kinematic viscosity the service computes from the same conditions
    (Sutherland's at the recorded temperature over the density), so the model is read at the Reynolds numbers the
    service reads it at."""

    def __len__(self) -> int:
        return self.observed.shape[0]

    @property
    def observed_names(self) -> tuple[str, ...]:
        """The observables recorded for at least one shot."""
        return tuple(name for j, name in enumerate(OBSERVABLES) if np.isfinite(self.observed[:, j]).any())

    @property
    def n_sessions(self) -> int:
        return len(np.unique(self.session))

    def covariate(self, name: str) -> np.ndarray:
        return self.shot_order.astype(float) if name == "shot_order" else self.launch[name]

    def subset(self, index: np.ndarray) -> Recordings:
        """The shots at `index` (an integer or boolean array), with their trajectories."""
        index = np.arange(len(self))[index]
        ids = set(self.shot_id[index])
        return Recordings(
            {k: v[index] for k, v in self.launch.items()},
            self.observed[index],
            self.session[index],
            self.club[index],
            self.shot_order[index],
            self.shot_id[index],
            None if self.density_kg_m3 is None else self.density_kg_m3[index],
            None if self.wind_xy_mps is None else self.wind_xy_mps[index],
            {k: v for k, v in self.trajectories.items() if k in ids},
            self.source,
            None if self.kinematic_viscosity_m2_s is None else self.kinematic_viscosity_m2_s[index],
        )


def _text(values: np.ndarray, fallback: str) -> np.ndarray:
    return np.array([fallback if v is None or v == "" else str(v) for v in values], dtype=object)


def _shot_order(session: np.ndarray, timestamp: np.ndarray) -> np.ndarray:
    """0, 1, 2, ... within each session, by timestamp where recorded, else by file order."""
    keys = np.array(["" if t is None else str(t) for t in timestamp], dtype=object)
    sessions = np.unique(session, return_inverse=True)[1]
    times = np.unique(keys, return_inverse=True)[1]
    rows = np.lexsort((np.arange(len(session)), times, sessions))  # by session, then time, then file order
    starts = np.flatnonzero(np.r_[True, np.diff(sessions[rows]) != 0])
    order = np.empty(len(session), dtype=int)
    order[rows] = np.arange(len(rows)) - np.repeat(starts, np.diff(np.r_[starts, len(rows)]))
    return order


def _conditions(shots: ShotSet) -> tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None]:
    """Per-shot density and kinematic viscosity where any air condition is recorded (blanks: 15 degC, sea level,
    dry; `ShotSet.air`, as `golfflight simulate` flies them) and the recorded wind."""
    density = viscosity = None
    if shots.air_recorded():
        air = shots.air()
        density = np.asarray(air.density_kg_m3, dtype=float)
        viscosity = np.asarray(air.kinematic_viscosity_m2_s, dtype=float)
    speed, from_deg = shots.column("wind_speed_mps"), shots.column("wind_from_deg")
    wind = None
    if np.isfinite(speed).any():
        wind = wind_vector(np.nan_to_num(speed), np.nan_to_num(from_deg))[:, :2]
    return density, wind, viscosity


def from_shot_set(shots: ShotSet, trajectories: dict[str, np.ndarray] | None = None, source: str = "") -> Recordings:
    """Arrays from canonical records; shots without any observed outcome are left out."""
    observed = np.stack([shots.column(name) for name in OBSERVABLES], axis=1)
    session = _text(shots.column("session"), "all")
    ids = shots.column("shot_id")
    shot_id = np.array([f"row{i}" if v is None else str(v) for i, v in enumerate(ids)], dtype=object)
    density, wind, viscosity = _conditions(shots)
    recordings = Recordings(
        {name: shots.column(name) for name in LAUNCH_COLUMNS},
        observed,
        session,
        _text(shots.column("club"), UNKNOWN_CLUB),
        _shot_order(session, shots.column("timestamp")),
        shot_id,
        density,
        wind,
        trajectories or {},
        source,
        viscosity,
    )
    return recordings.subset(np.isfinite(observed).any(axis=1))


def read_recordings(path: str | os.PathLike) -> Recordings:
    """A canonical CSV and, when it exists beside it, its companion trajectories file."""
    path = Path(path)
    companion = trajectories_path(path)
    trajectories = read_trajectories(companion) if companion.is_file() else {}
    return from_shot_set(read_shots(path), trajectories, str(path))
