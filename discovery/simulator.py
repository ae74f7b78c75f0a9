"""Fly recorded launches through the diagnosed model under modified conditions, many variants in one batch.

The loop mirrors `service.flight.simulate` (same steppers and landing interpolation; a test checks they agree)
but keeps per-shot coefficient scales and an optional extra acceleration, and drops landed shots as it goes:
effect fits fly the same shots under several parameter sets stacked into one batch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Literal

import numpy as np

from service.flight import STEPPERS
from service.physics import CoefficientModel, State, derivatives, initial_state
from service.wind import Wind

CoefficientsFor = Callable[[np.ndarray], CoefficientModel]
"""Builds the model's coefficient function for shots whose air density is `ratio` x the assumed one (per shot)."""

Correction = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""Extra acceleration [N,3] from (air-relative velocity [N,3], spin [N,3], per-shot weights [N,K])."""


@dataclass
class Conditions:
    """Everything one simulation of N shots uses: launches, air, wind, landing ground, coefficient scales."""

    launch: dict[str, np.ndarray]
    density_ratio: np.ndarray
    """True air density over the density the model assumes for the shot [N]."""
    density_kg_m3: np.ndarray
    """The density the model assumes for each shot (recorded conditions, else the model's reference air) [N]."""
    wind_xy_mps: np.ndarray
    """Uniform air velocity [N,2] (x right, y to the target)."""
    ground_height_m: np.ndarray
    """Height of the landing ground above the tee's ground [N]."""
    coefficient_scale: np.ndarray
    """Multipliers of C_L, C_D, C_M [N,3]."""
    correction_weights: np.ndarray | None = None
    """Weights [N,K] of an extra-acceleration term (see `discovery.correction`), None = no term."""

    def __len__(self) -> int:
        return len(self.density_ratio)

    def take(self, index: np.ndarray) -> Conditions:
        values = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "launch":
                values[f.name] = {k: v[index] for k, v in value.items()}
            else:
                values[f.name] = None if value is None else value[index]
        return Conditions(**values)

    def copy(self) -> Conditions:
        return self.take(np.arange(len(self)))


def concatenate(parts: list[Conditions]) -> Conditions:
    """Stack several condition sets of the same shots into one batch."""
    values = {}
    for f in fields(Conditions):
        items = [getattr(p, f.name) for p in parts]
        if f.name == "launch":
            values[f.name] = {k: np.concatenate([i[k] for i in items]) for k in items[0]}
        else:
            values[f.name] = None if items[0] is None else np.concatenate(items)
    return Conditions(**values)


class ScaledCoefficients:
    """A coefficient model with C_L, C_D, C_M multiplied per shot."""

    def __init__(self, base: CoefficientModel, scale: np.ndarray):
        self.base, self.scale = base, scale

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        out = self.base(v_rel, omega)
        out[:, :3] *= self.scale
        return out


@dataclass
class Flown:
    """Outcome of a batch: landing point (x, y), apex, flight time, landing angle; NaN where a ball did not land."""

    landing_xy: np.ndarray
    apex_m: np.ndarray
    flight_time_s: np.ndarray
    landing_angle_deg: np.ndarray
    positions: np.ndarray | None = None
    """[T, N, 3] positions at t = 0, dt, 2 dt, ... (NaN after landing), when asked for."""
    dt_s: float = 0.0

    def outcomes(self) -> np.ndarray:
        """[N, 5] in `discovery.recordings.OBSERVABLES` order."""
        return np.stack(
            [self.landing_xy[:, 1], self.landing_xy[:, 0], self.apex_m, self.flight_time_s, self.landing_angle_deg],
            axis=1,
        )


def _take(state: State, index: np.ndarray) -> State:
    return State(state.position[index], state.velocity[index], state.spin[index])


def fly(
    conditions: Conditions,
    coefficients_for: CoefficientsFor,
    dt_s: float,
    t_max_s: float,
    method: Literal["euler", "rk4"] = "euler",
    correction: Correction | None = None,
    keep_positions: bool = False,
) -> Flown:
    """Integrate every shot until it crosses its landing ground downwards (or t_max), dropping landed shots.

    A parameter set far outside reality may make a ball diverge; its outcome is then NaN (not landed), silently.
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return _fly(conditions, coefficients_for, dt_s, t_max_s, method, correction, keep_positions)


def _fly(
    conditions: Conditions,
    coefficients_for: CoefficientsFor,
    dt_s: float,
    t_max_s: float,
    method: str,
    correction: Correction | None,
    keep_positions: bool,
) -> Flown:
    n = len(conditions)
    step = STEPPERS[method]
    state = initial_state(**conditions.launch)
    landing_xy = np.full((n, 2), np.nan)
    flight_time = np.full(n, np.nan)
    landing_angle = np.full(n, np.nan)
    apex = state.position[:, 2].copy()
    positions = [state.position.copy()] if keep_positions else None
    active = np.arange(n)

    def right_hand_side(index: np.ndarray) -> Callable[[State], State]:
        part = conditions.take(index)
        model = ScaledCoefficients(coefficients_for(part.density_ratio), part.coefficient_scale)
        density = part.density_kg_m3 * part.density_ratio
        xy = part.wind_xy_mps
        wind = Wind(np.hypot(xy[:, 0], xy[:, 1]), np.degrees(np.arctan2(-xy[:, 0], -xy[:, 1])))
        air_velocity = wind.at_reference

        def rhs(s: State) -> State:
            rate = derivatives(s, model, density, wind)
            if correction is not None:
                rate.velocity += correction(s.velocity - air_velocity, s.spin, part.correction_weights)
            return rate

        return rhs

    rhs = right_hand_side(active)
    ground = conditions.ground_height_m
    for i in range(1, round(t_max_s / dt_s) + 1):
        new = step(state, rhs, dt_s)
        z_old, z_new = state.position[:, 2], new.position[:, 2]
        apex[active] = np.maximum(apex[active], z_new)
        g = ground[active]
        crossing = (z_old > g) & (z_new <= g)
        if keep_positions:
            frame = np.full((n, 3), np.nan)
            frame[active] = new.position
            positions.append(frame)
        if crossing.any():
            frac = ((z_old - g) / (z_old - z_new))[crossing][:, None]
            position = state.position[crossing] + frac * (new.position[crossing] - state.position[crossing])
            velocity = state.velocity[crossing] + frac * (new.velocity[crossing] - state.velocity[crossing])
            done = active[crossing]
            landing_xy[done] = position[:, :2]
            flight_time[done] = (i - 1 + frac[:, 0]) * dt_s
            landing_angle[done] = np.degrees(np.arctan2(-velocity[:, 2], np.hypot(velocity[:, 0], velocity[:, 1])))
            keep = ~crossing
            active = active[keep]
            if active.size == 0:
                break
            state = _take(new, keep)
            rhs = right_hand_side(active)
        else:
            state = new
    apex[np.isnan(flight_time)] = np.nan
    finite = np.isfinite(landing_xy).all(axis=1) & np.isfinite(landing_angle)
    for values in (landing_xy, apex, flight_time, landing_angle):
        values[~finite] = np.nan
    return Flown(landing_xy, apex, flight_time, landing_angle, np.stack(positions) if keep_positions else None, dt_s)
