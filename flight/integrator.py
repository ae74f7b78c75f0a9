"""The one batch integrator every NumPy flight goes through: a step rule x a vector field x an event x a record.

- step rule (`STEP_RULES`): forward Euler (paper eq. 13, what Phys-NN+ is trained and served with) or classical
  RK4 (the reference world), each a function (state, field, dt) -> next state;
- vector field (`flight.field`): the right-hand side bound to the batch's per-ball values;
- event (`GroundPlane`): where the phase ends for a ball; at the first step that crosses it the state is
  interpolated linearly to the event (exact for Euler's straight segments);
- record: "summary" (landing, apex, times; each ball leaves the batch as it lands) or "states" (also every step's
  state of every ball until the last one lands: a landed ball flies on below its ground, so that states at fixed
  times exist for the whole batch).

The apex is interpolated between steps (`flight.outcomes.parabola_apex`). A later phase (bounce and roll on the
ground) starts from the landing state this returns, with its own field and event, through the same `integrate`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from golfflight.flight.field import BallInAir, VectorField, take
from golfflight.flight.outcomes import Flight, parabola_apex
from golfflight.flight.physics import CoefficientModel, State
from golfflight.flight.wind import CALM, Wind

StepRule = Callable[[State, VectorField, float], State]


def _advance(state: State, rate: State, dt: float) -> State:
    return State(state.position + dt * rate.position, state.velocity + dt * rate.velocity, state.spin + dt * rate.spin)


def forward_euler(state: State, field: VectorField, dt: float) -> State:
    """One forward-Euler step (paper eq. 13)."""
    return _advance(state, field(state), dt)


def runge_kutta_4(state: State, field: VectorField, dt: float) -> State:
    """One classical fourth-order Runge-Kutta step."""
    k1 = field(state)
    k2 = field(_advance(state, k1, dt / 2))
    k3 = field(_advance(state, k2, dt / 2))
    k4 = field(_advance(state, k3, dt))
    return State(
        state.position + dt / 6 * (k1.position + 2 * k2.position + 2 * k3.position + k4.position),
        state.velocity + dt / 6 * (k1.velocity + 2 * k2.velocity + 2 * k3.velocity + k4.velocity),
        state.spin + dt / 6 * (k1.spin + 2 * k2.spin + 2 * k3.spin + k4.spin),
    )


STEP_RULES: dict[str, StepRule] = {"euler": forward_euler, "rk4": runge_kutta_4}
Method = Literal["euler", "rk4"]


@dataclass(frozen=True)
class GroundPlane:
    """The event that ends the flight: a ball coming down through z = height_m (shared, or one per ball)."""

    height_m: np.ndarray | float = 0.0

    def crossed(self, z_before: np.ndarray, z_after: np.ndarray) -> np.ndarray:
        """Which balls came down through the plane during the step."""
        return (z_before > self.height_m) & (z_after <= self.height_m)

    def fraction(self, z_before: np.ndarray, z_after: np.ndarray, crossed: np.ndarray) -> np.ndarray:
        """How far into the step (0..1) each of the `crossed` balls met the plane."""
        height = self.height_m[crossed] if np.ndim(self.height_m) else self.height_m
        return (z_before[crossed] - height) / (z_before[crossed] - z_after[crossed])

    def take(self, index: np.ndarray) -> GroundPlane:
        return GroundPlane(take(np.asarray(self.height_m, dtype=float), index))


class _Apex:
    """The highest state of each ball and its neighbours before and after, for the parabola between steps."""

    def __init__(self, z: np.ndarray) -> None:
        self.peak, self.step = z.copy(), np.zeros(len(z), dtype=int)
        self.before, self.after = np.full(len(z), np.nan), np.full(len(z), np.nan)

    def update(self, alive: np.ndarray, step: int, z_before: np.ndarray, z_after: np.ndarray) -> None:
        higher = z_after > self.peak[alive]
        past_peak = ~higher & (self.step[alive] == step - 1)
        self.after[alive[past_peak]] = z_after[past_peak]
        ids = alive[higher]
        self.peak[ids], self.step[ids] = z_after[higher], step
        self.before[ids], self.after[ids] = z_before[higher], np.nan

    def interpolated(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        return parabola_apex(self.before, self.peak, self.after, self.step * dt, dt)


def _nan_states(n: int) -> State:
    return State(np.full((n, 3), np.nan), np.full((n, 3), np.nan), np.full((n, 3), np.nan))


def integrate(
    state: State,
    field: VectorField,
    dt: float,
    steps: int,
    rule: Method = "euler",
    event: GroundPlane = GroundPlane(),
    record: Literal["summary", "states"] = "summary",
) -> Flight:
    """Step a batch from `state` until every ball has met the event or `steps` steps have passed; balls that never
    meet it keep NaN landing values (`landed` False)."""
    n = state.position.shape[0]
    advance = STEP_RULES[rule]
    thin = record == "summary"
    alive, flying = np.arange(n), np.ones(n, dtype=bool)
    landing, flight_time, last_step = _nan_states(n), np.full(n, np.nan), np.full(n, -1)
    apex = _Apex(state.position[:, 2])
    history = None if thin else [state]
    for i in range(1, steps + 1):
        new = advance(state, field, dt)
        z_before, z_after = state.position[:, 2], new.position[:, 2]
        if thin:
            apex.update(alive, i, z_before, z_after)
            crossed = event.crossed(z_before, z_after)
        else:
            history.append(new)
            apex.update(alive[flying], i, z_before[flying], z_after[flying])
            crossed = event.crossed(z_before, z_after) & flying
        if crossed.any():
            frac = event.fraction(z_before, z_after, crossed)
            ids = alive[crossed]
            for name in ("position", "velocity", "spin"):
                before, after = getattr(state, name)[crossed], getattr(new, name)[crossed]
                getattr(landing, name)[ids] = before + frac[:, None] * (after - before)
            flight_time[ids], last_step[ids] = (i - 1 + frac) * dt, i - 1
            if thin:
                stay = np.flatnonzero(~crossed)
                alive, new, field, event = alive[stay], new.take(stay), field.take(stay), event.take(stay)
            else:
                flying &= ~crossed
        state = new
        if alive.size == 0 or not flying.any():
            break
    apex_m, apex_time_s = apex.interpolated(dt)
    times = dt * np.arange(len(history)) if history is not None else None
    landed = last_step >= 0
    return Flight(
        landed, landing.position, landing.velocity, landing.spin, flight_time, apex_m, apex_time_s, times, history,
        last_step,
    )


def simulate(
    state: State,
    coefficient_model: CoefficientModel,
    density: np.ndarray | float,
    wind: Wind = CALM,
    dt: float = 0.1,
    t_max: float = 10.0,
    method: Method = "euler",
    ground_height_m: np.ndarray | float = 0.0,
    keep_states: bool = False,
) -> Flight:
    """Fly a batch through the equations of motion in the air (`BallInAir`) down to a ground plane, for t_max at
    most: the common case of `integrate`."""
    field = BallInAir(coefficient_model, density, wind)
    steps = int(round(t_max / dt))
    record = "states" if keep_states else "summary"
    return integrate(state, field, dt, steps, method, GroundPlane(np.asarray(ground_height_m, dtype=float)), record)
