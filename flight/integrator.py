"""The one batch integrator every NumPy flight goes through: a step rule x a vector field x an event x a record.

- step rule (`StepRule`): `ForwardEuler` (paper eq. 13, what Phys-NN+ is trained and served with) or `RungeKutta4`
  (the reference world), each an object called as rule(state, field, dt) -> next state;
- vector field (`flight.field`): the right-hand side bound to the batch's per-ball values;
- event (`GroundPlane`): where the phase ends for a ball; at the first step that crosses it the state is
  interpolated linearly to the event (exact for Euler's straight segments);
- record (`Record`): `SummaryRecord` (landing, apex, times; each ball leaves the batch as it lands) or
  `StatesRecord` (also every step's state of every ball until the last one lands: a landed ball flies on below its
  ground, so that states at fixed times exist for the whole batch). The loop asks the record which balls are still
  flying and hands it each new state; it never branches on which record it has.

The apex is interpolated between steps (`flight.outcomes.parabola_apex`). A later phase (bounce and roll on the
ground) starts from the landing state this returns, with its own field and event, through the same `integrate`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
from golfflight.flight.field import BallInAir, VectorField, take
from golfflight.flight.outcomes import Flight, parabola_apex
from golfflight.flight.physics import CoefficientModel, State
from golfflight.flight.wind import CALM, Wind


class StepRule(Protocol):
    """How one step advances a batch: the next state from this one, the field and the step."""

    name: str

    def __call__(self, state: State, field: VectorField, dt: float) -> State: ...


def _advance(state: State, rate: State, dt: float) -> State:
    return State(state.position + dt * rate.position, state.velocity + dt * rate.velocity, state.spin + dt * rate.spin)


@dataclass(frozen=True)
class ForwardEuler:
    """One forward-Euler step (paper eq. 13): what Phys-NN+ is trained and served with."""

    name: str = "euler"

    def __call__(self, state: State, field: VectorField, dt: float) -> State:
        return _advance(state, field(state), dt)


@dataclass(frozen=True)
class RungeKutta4:
    """One classical fourth-order Runge-Kutta step: the reference world's."""

    name: str = "rk4"

    def __call__(self, state: State, field: VectorField, dt: float) -> State:
        k1 = field(state)
        k2 = field(_advance(state, k1, dt / 2))
        k3 = field(_advance(state, k2, dt / 2))
        k4 = field(_advance(state, k3, dt))
        return State(
            state.position + dt / 6 * (k1.position + 2 * k2.position + 2 * k3.position + k4.position),
            state.velocity + dt / 6 * (k1.velocity + 2 * k2.velocity + 2 * k3.velocity + k4.velocity),
            state.spin + dt / 6 * (k1.spin + 2 * k2.spin + 2 * k3.spin + k4.spin),
        )


FORWARD_EULER, RUNGE_KUTTA_4 = ForwardEuler(), RungeKutta4()
STEP_RULES: dict[str, StepRule] = {rule.name: rule for rule in (FORWARD_EULER, RUNGE_KUTTA_4)}
"""The step rules by the names a card, a report or `simulate(method=...)` gives them."""
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


class SummaryRecord:
    """Landing, apex and times only: each ball leaves the batch as it lands, so later steps cost less."""

    history: list[State] | None = None

    def __init__(self, state: State, field: VectorField, event: GroundPlane) -> None:
        self.ids, self.field, self.event = np.arange(state.position.shape[0]), field, event

    def flying(self, values: np.ndarray) -> np.ndarray:
        """The rows of `values` (one per ball of the batch) of the balls still in the air: all of them."""
        return values

    def landed(self, crossed: np.ndarray) -> np.ndarray:
        """Which balls of the batch landed during the step, of those that crossed the event: all of them."""
        return crossed

    def keep(self, new: State, landed: np.ndarray) -> State:
        """The batch's next state: the balls that landed during the step leave it."""
        if not landed.any():
            return new
        stay = np.flatnonzero(~landed)
        self.ids, self.field, self.event = self.ids[stay], self.field.take(stay), self.event.take(stay)
        return new.take(stay)

    @property
    def finished(self) -> bool:
        return self.ids.size == 0


class StatesRecord(SummaryRecord):
    """Also every step's state of every ball until the last one lands; a landed ball flies on below its ground."""

    def __init__(self, state: State, field: VectorField, event: GroundPlane) -> None:
        super().__init__(state, field, event)
        self.in_air, self.history = np.ones(len(self.ids), dtype=bool), [state]

    def flying(self, values: np.ndarray) -> np.ndarray:
        return values[self.in_air]

    def landed(self, crossed: np.ndarray) -> np.ndarray:
        return crossed & self.in_air

    def keep(self, new: State, landed: np.ndarray) -> State:
        self.history.append(new)
        self.in_air &= ~landed
        return new

    @property
    def finished(self) -> bool:
        return not self.in_air.any()


Record = type[SummaryRecord]
"""What `integrate` records: `SummaryRecord` or `StatesRecord`, made once a flight."""


def record_for(keep_states: bool) -> Record:
    """The record that keeps every step's states, or the one that keeps the summary only."""
    return StatesRecord if keep_states else SummaryRecord


class _Landings:
    """Each ball's state interpolated to its event, the time of it, and its last step above the event."""

    def __init__(self, n: int) -> None:
        self.state = State(*(np.full((n, 3), np.nan) for _ in range(3)))
        self.time_s, self.last_step = np.full(n, np.nan), np.full(n, -1)

    def add(self, ids: np.ndarray, frac: np.ndarray, before: State, after: State, step: int, dt: float) -> None:
        for name in ("position", "velocity", "spin"):
            start, end = getattr(before, name), getattr(after, name)
            getattr(self.state, name)[ids] = start + frac[:, None] * (end - start)
        self.time_s[ids], self.last_step[ids] = (step - 1 + frac) * dt, step - 1


def integrate(
    state: State,
    field: VectorField,
    dt: float,
    steps: int,
    rule: StepRule = FORWARD_EULER,
    event: GroundPlane = GroundPlane(),
    record: Record = SummaryRecord,
) -> Flight:
    """Step a batch from `state` until every ball has met the event or `steps` steps have passed; balls that never
    meet it keep NaN landing values (`landed` False)."""
    recorder = record(state, field, event)
    landings, apex = _Landings(state.position.shape[0]), _Apex(state.position[:, 2])
    for i in range(1, steps + 1):
        new = rule(state, recorder.field, dt)
        z_before, z_after = state.position[:, 2], new.position[:, 2]
        apex.update(recorder.flying(recorder.ids), i, recorder.flying(z_before), recorder.flying(z_after))
        landed = recorder.landed(recorder.event.crossed(z_before, z_after))
        if landed.any():
            frac = recorder.event.fraction(z_before, z_after, landed)
            landings.add(recorder.ids[landed], frac, state.take(landed), new.take(landed), i, dt)
        state = recorder.keep(new, landed)
        if recorder.finished:
            break
    apex_m, apex_time_s = apex.interpolated(dt)
    history = recorder.history
    times = None if history is None else dt * np.arange(len(history))
    at = landings.state
    return Flight(
        landings.last_step >= 0, at.position, at.velocity, at.spin, landings.time_s, apex_m, apex_time_s, times,
        history, landings.last_step,
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
    event = GroundPlane(np.asarray(ground_height_m, dtype=float))
    return integrate(state, field, dt, steps, STEP_RULES[method], event, record_for(keep_states))
