"""Integrate a batch of flights to the ground: fixed-step Euler or RK4, landing found by interpolation.

Kept small and explicit on purpose: one right-hand side (`physics.derivatives`), two steppers, one loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Literal

import numpy as np

from service.constants import RPM_TO_RADPS
from service.physics import CoefficientModel, State, derivatives
from service.wind import CALM, Wind

RightHandSide = Callable[[State], State]


def _advance(state: State, rate: State, dt: float) -> State:
    return State(state.position + dt * rate.position, state.velocity + dt * rate.velocity, state.spin + dt * rate.spin)


def euler_step(state: State, rhs: RightHandSide, dt: float) -> State:
    """One forward-Euler step (paper eq. 13): the scheme Phys-NN+ is trained and served with."""
    return _advance(state, rhs(state), dt)


def rk4_step(state: State, rhs: RightHandSide, dt: float) -> State:
    """One classical fourth-order Runge-Kutta step: the scheme of the high-fidelity reference world."""
    k1 = rhs(state)
    k2 = rhs(_advance(state, k1, dt / 2))
    k3 = rhs(_advance(state, k2, dt / 2))
    k4 = rhs(_advance(state, k3, dt))
    return State(
        state.position + dt / 6 * (k1.position + 2 * k2.position + 2 * k3.position + k4.position),
        state.velocity + dt / 6 * (k1.velocity + 2 * k2.velocity + 2 * k3.velocity + k4.velocity),
        state.spin + dt / 6 * (k1.spin + 2 * k2.spin + 2 * k3.spin + k4.spin),
    )


STEPPERS = {"euler": euler_step, "rk4": rk4_step}


@dataclass
class Flight:
    """Outcome of a batch of flights; landing values are NaN where `landed` is False."""

    landed: np.ndarray
    landing_position: np.ndarray
    landing_velocity: np.ndarray
    landing_spin: np.ndarray
    flight_time_s: np.ndarray
    apex_m: np.ndarray
    apex_time_s: np.ndarray
    times_s: np.ndarray | None = None
    states: list[State] | None = None

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
        v = self.landing_velocity
        return np.degrees(np.arctan2(-v[:, 2], np.hypot(v[:, 0], v[:, 1])))

    @property
    def landing_speed_mps(self) -> np.ndarray:
        return np.linalg.norm(self.landing_velocity, axis=-1)

    @property
    def landing_spin_rpm(self) -> np.ndarray:
        return np.linalg.norm(self.landing_spin, axis=-1) / RPM_TO_RADPS


def simulate(
    state: State,
    coefficient_model: CoefficientModel,
    density: np.ndarray | float,
    wind: Wind = CALM,
    dt: float = 0.1,
    t_max: float = 10.0,
    method: Literal["euler", "rk4"] = "euler",
    ground_height_m: np.ndarray | float = 0.0,
    keep_states: bool = False,
) -> Flight:
    """Fly a batch from `state` until every ball has come down through the ground plane or t_max has passed.

    The landing is the first downward crossing of z = ground_height_m, with the state interpolated
    linearly between the two steps around it (exact for Euler, whose positions are piecewise linear).
    """
    n = state.position.shape[0]
    step = STEPPERS[method]
    rhs = lambda s: derivatives(s, coefficient_model, density, wind)  # noqa: E731
    ground = np.broadcast_to(np.asarray(ground_height_m, dtype=float), (n,))

    landed = np.zeros(n, dtype=bool)
    landing = State(np.full((n, 3), np.nan), np.full((n, 3), np.nan), np.full((n, 3), np.nan))
    flight_time = np.full(n, np.nan)
    apex = state.position[:, 2].copy()
    apex_time = np.zeros(n)
    states = [state] if keep_states else None
    n_steps = int(round(t_max / dt))

    for i in range(1, n_steps + 1):
        new = step(state, rhs, dt)
        t = i * dt
        z_old, z_new = state.position[:, 2], new.position[:, 2]
        higher = ~landed & (z_new > apex)
        apex[higher], apex_time[higher] = z_new[higher], t
        crossing = ~landed & (z_old > ground) & (z_new <= ground)
        if crossing.any():
            frac = ((z_old - ground) / (z_old - z_new))[crossing][:, None]
            for name in ("position", "velocity", "spin"):
                old, nxt = getattr(state, name)[crossing], getattr(new, name)[crossing]
                getattr(landing, name)[crossing] = old + frac * (nxt - old)
            flight_time[crossing] = t - dt + frac[:, 0] * dt
            landed |= crossing
        state = new
        if keep_states:
            states.append(state)
        if landed.all():
            break

    times = dt * np.arange(len(states)) if keep_states else None
    return Flight(landed, landing.position, landing.velocity, landing.spin, flight_time, apex, apex_time, times, states)
