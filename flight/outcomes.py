"""What a flight's states say about it and the outcome types, one per level: `Flight` (the integrator's batch),
`ShotFlight` (one shot, to rest) and `BatchFlights` (a batch of shots as columns), with `Rest` and `EulerStates`.
Every formula works on plain floats (the engine's one-shot latency path) and on NumPy arrays alike, so both paths
derive their figures from the same formulas."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from golfflight.errors import FlightError
from golfflight.flight import xp
from golfflight.flight.constants import RPM_TO_RADPS
from golfflight.flight.ground import GroundPath, GroundPhase
from golfflight.flight.physics import State


DEGREES_PER_RADIAN = 180.0 / math.pi


def landing_angle_deg(vx, vy, vz):
    """Descent angle below the horizontal (positive, degrees) of a velocity, component by component (floats, NumPy
    arrays or torch tensors, `flight.xp`)."""
    return xp.atan2(-vz, (vx * vx + vy * vy) ** 0.5) * DEGREES_PER_RADIAN


@dataclass
class Flight:
    """Outcome of a batch of flights; landing values are NaN where `landed` is False.

    `states` (when recorded) holds the state of every ball at each time of `times_s` (t = 0, dt, 2 dt, ...), a landed
    ball's flying on below its ground; `last_step[i]` is the index of ball i's last state above its ground."""

    landed: np.ndarray
    landing_position: np.ndarray
    landing_velocity: np.ndarray
    landing_spin: np.ndarray
    flight_time_s: np.ndarray
    apex_m: np.ndarray
    apex_time_s: np.ndarray
    times_s: np.ndarray | None = None
    states: list[State] | None = None
    last_step: np.ndarray | None = None

    @property
    def carry_m(self) -> np.ndarray:
        """Straight-line horizontal distance from the tee to the landing point."""
        return np.hypot(self.landing_position[:, 0], self.landing_position[:, 1])

    @property
    def lateral_m(self) -> np.ndarray:
        """Landing point right (+) or left (-) of the target line."""
        return self.landing_position[:, 0]

    @property
    def landing_angle_deg(self) -> np.ndarray:
        """Descent angle below the horizontal at landing (positive)."""
        return landing_angle_deg(*self.landing_velocity.T)

    @property
    def landing_speed_mps(self) -> np.ndarray:
        return np.linalg.norm(self.landing_velocity, axis=-1)

    @property
    def landing_spin_rpm(self) -> np.ndarray:
        return np.linalg.norm(self.landing_spin, axis=-1) / RPM_TO_RADPS


def landing_figures(x, y, vx, vy, vz, wx, wy, wz):
    """(carry, landing angle, landing speed, landing spin) from a landing state (floats or arrays)."""
    return (
        np.hypot(x, y),
        landing_angle_deg(vx, vy, vz),
        (vx * vx + vy * vy + vz * vz) ** 0.5,
        (wx * wx + wy * wy + wz * wz) ** 0.5 / RPM_TO_RADPS,
    )


@dataclass(frozen=True, kw_only=True)
class EulerStates:
    """States of one shot: times [K], positions and velocities [K,3]: the integrator's steps to the interpolated
    landing and, when the shot was rolled, the ground phase's states to the rest (an impact twice: in and out)."""

    times_s: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray

    @classmethod
    def to_landing(cls, positions: np.ndarray, velocities: np.ndarray, landing_position, landing_velocity, dt: float,
                   flight_time_s: float) -> EulerStates:
        """A shot's states at t = 0, dt, 2 dt, ... ([K,3] each) up to its last step above the ground, the landing
        interpolated after them (the single shot's and the batch's states alike)."""
        times = np.append(np.round(dt * np.arange(len(positions)), 9), flight_time_s)
        return cls(times_s=times, positions=np.vstack([positions, landing_position]),
                   velocities=np.vstack([velocities, landing_velocity]))

    @property
    def finite(self) -> bool:
        """Whether every recorded state is finite (a broken model's NaN never reaches a client)."""
        return all(np.isfinite(a).all() for a in (self.times_s, self.positions, self.velocities))

    def through_rest(self, phase: GroundPhase, i: int, flight_time_s: float) -> EulerStates:
        """These flight states continued through shot i's ground path (its first row, the landing, is their last)."""
        return self.followed_by(phase.paths[i], flight_time_s)

    def followed_by(self, path: GroundPath, flight_time_s: float) -> EulerStates:
        """These flight states continued through a ground path (its first row, the landing, is their last)."""
        return EulerStates(
            times_s=np.append(self.times_s, flight_time_s + path.times_s[1:]),
            positions=np.vstack([self.positions, path.positions[1:]]),
            velocities=np.vstack([self.velocities, path.velocities[1:]]),
        )


@dataclass(frozen=True, kw_only=True)
class Rest:
    """Where a shot came to rest after bouncing and rolling, SI: the point, its horizontal distance from the tee, the
    distance gained after the landing (total - carry: negative for a ball that spun back), hops, time on the
    ground."""

    x_m: float
    y_m: float
    total_m: float
    roll_m: float
    bounces: int
    ground_time_s: float

    @classmethod
    def at(cls, x_m: float, y_m: float, carry_m: float, bounces: int, ground_time_s: float) -> Rest:
        """The rest at (x, y) of a shot of this carry (a tee at the origin)."""
        total = math.hypot(x_m, y_m)
        return cls(x_m=x_m, y_m=y_m, total_m=total, roll_m=total - carry_m, bounces=bounces,
                   ground_time_s=ground_time_s)

    @classmethod
    def of_batch(cls, phase: GroundPhase | None, shots: np.ndarray, n: int, carry_m: np.ndarray) -> Rest:
        """The rests of a batch's `shots` (rolled, in order) as [n] arrays, NaN (bounces -1) for the others."""
        x, y, total, ground_time = (np.full(n, np.nan) for _ in range(4))
        bounces = np.full(n, -1, dtype=np.int64)
        if phase is not None:
            x[shots], y[shots] = phase.rest_position[:, 0], phase.rest_position[:, 1]
            total[shots] = [math.hypot(a, b) for a, b in zip(x[shots].tolist(), y[shots].tolist(), strict=True)]
            bounces[shots], ground_time[shots] = phase.bounces, phase.time_s
        return cls(x_m=x, y_m=y, total_m=total, roll_m=total - carry_m, bounces=bounces, ground_time_s=ground_time)

    def take(self, shots: np.ndarray) -> Rest:
        """The rests of `shots` of a batch's Rest of arrays."""
        return Rest(**{f.name: getattr(self, f.name)[shots] for f in fields(Rest)})


@dataclass(frozen=True, kw_only=True)
class ShotFlight:
    """The outcome of one shot down to its ground's elevation and, unless the flight alone was asked for, to rest,
    SI; `states`, when kept, run through the bounces and the roll to the rest."""

    landing_x_m: float
    landing_y_m: float
    carry_m: float
    lateral_m: float
    apex_m: float
    apex_time_s: float
    flight_time_s: float
    landing_angle_deg: float
    landing_speed_mps: float
    landing_spin_rpm: float
    states: EulerStates | None = None
    rest: Rest | None = None


SHOT_NUMBERS = tuple(f.name for f in fields(ShotFlight) if f.name not in ("states", "rest"))
"""The figures of a shot, the same names in ShotFlight and BatchFlights."""


@dataclass(frozen=True, kw_only=True)
class BatchFlights:
    """A batch's outcomes as [N] arrays, named as ShotFlight's fields (`shots` makes one ShotFlight a shot). `rest`
    holds arrays too (NaN, bounces -1, where `rolled` is False: a flight alone, or a shot that failed); `errors` maps
    a failed shot to why (its numbers are meaningless); `states`, where they were kept, each shot's states through its
    bounces and roll (None for a failed one)."""

    landing_x_m: np.ndarray
    landing_y_m: np.ndarray
    carry_m: np.ndarray
    lateral_m: np.ndarray
    apex_m: np.ndarray
    apex_time_s: np.ndarray
    flight_time_s: np.ndarray
    landing_angle_deg: np.ndarray
    landing_speed_mps: np.ndarray
    landing_spin_rpm: np.ndarray
    rest: Rest
    rolled: np.ndarray
    errors: dict[int, str]
    states: list[EulerStates | None] | None = None

    def take(self, shots) -> BatchFlights:
        """The flights of `shots` (indices), in that order."""
        shots = np.asarray(shots, dtype=np.intp)
        where = {int(s): k for k, s in enumerate(shots.tolist())}
        columns = [f.name for f in fields(self) if f.name not in ("rest", "errors", "states")]
        arrays = {name: getattr(self, name)[shots] for name in columns}
        errors = {where[i]: message for i, message in self.errors.items() if i in where}
        states = None if self.states is None else [self.states[i] for i in shots.tolist()]
        return BatchFlights(**arrays, rest=self.rest.take(shots), errors=errors, states=states)

    def shots(self) -> list[ShotFlight | FlightError]:
        """One ShotFlight a shot (its states where they were kept, its rest where it was rolled), or a FlightError
        for a shot that failed; in order."""
        rest_names = [f.name for f in fields(Rest)]
        rests = zip(*(getattr(self.rest, name).tolist() for name in rest_names), strict=True)
        numbers = zip(*(getattr(self, name).tolist() for name in SHOT_NUMBERS), strict=True)
        states = self.states or [None] * len(self.rolled)
        flown: list[ShotFlight | FlightError] = []
        for i, (shot, rest, rolled, kept) in enumerate(zip(numbers, rests, self.rolled.tolist(), states, strict=True)):
            if i in self.errors:
                flown.append(FlightError(self.errors[i]))
                continue
            shot_rest = Rest(**dict(zip(rest_names, rest, strict=True))) if rolled else None
            flown.append(ShotFlight(**dict(zip(SHOT_NUMBERS, shot, strict=True)), states=kept, rest=shot_rest))
        return flown
