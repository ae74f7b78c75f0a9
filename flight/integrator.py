"""The one batch integrator every batch flight goes through, on NumPy arrays or on a torch device's tensors (the
torch engine's): a step rule x a vector field x an event x a record.

- step rule (`StepRule`): `ForwardEuler` (paper eq. 13, what Phys-NN+ is trained and served with) or `RungeKutta4`
  (the reference world), each an object called as rule(state, field, dt) -> next state;
- vector field (`flight.field`): the right-hand side bound to the batch's per-ball values;
- event (`GroundPlane`): where the phase ends for a ball; at the first step that crosses it the state is
  interpolated linearly to the event (exact for Euler's straight segments);
- record (`Recorder`): `SummaryRecord` (landing, apex, times; landed balls leave the batch now and then,
  `SetAside`), `StatesRecord` (also every step's state of every ball until the last one lands: a landed ball flies
  on below its ground, so that states at fixed times exist for the whole batch), or training's differentiable
  fixed-horizon trajectory (`flight.rollout.TrajectoryRecord`). The loop hands the record each step's old and new
  states: the record marks them (`_Marks`: the apex and the landing as they happen), keeps what it keeps and says
  when the flight is finished; the loop never branches on which record it has.

The landing and the apex are `flight.events`' one rule (the apex interpolated between steps, `parabola_apex`). A
later phase (bounce and roll on the ground) starts from the landing state this returns, with its own field and
event.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
from golfflight.flight import xp
from golfflight.flight.field import VectorField
from golfflight.flight.events import came_down, crossing_fraction, parabola_apex, rose_above
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import State


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
"""The step rules by the names a card or a report gives them."""
Method = Literal["euler", "rk4"]


@dataclass(frozen=True)
class GroundPlane:
    """The event that ends the flight: a ball coming down through z = height_m (shared, or one per ball)."""

    height_m: np.ndarray | float = 0.0

    def crossed(self, z_before: np.ndarray, z_after: np.ndarray) -> np.ndarray:
        """Which balls came down through the plane during the step (`flight.events.came_down`)."""
        return came_down(z_before, z_after, self.height_m)

    def fraction(self, z_before: np.ndarray, z_after: np.ndarray, crossed: np.ndarray) -> np.ndarray:
        """How far into the step (0..1) each ball met the plane, where it `crossed` it
        (`flight.events.crossing_fraction`)."""
        return crossing_fraction(z_before, z_after, self.height_m, crossed)

    def take(self, index: np.ndarray) -> GroundPlane:
        return GroundPlane(xp.rows(self.height_m, index))


APEX_MARKS = ("peak", "peak_step", "before", "after")
LANDING_MARKS = ("position", "velocity", "spin", "frac", "last_step")
"""What `_Marks` holds of each ball, besides whether it is down."""


class _Marks:
    """What the flight has said of each ball so far: its highest state's height and step and the heights one step
    before and after it (the apex's parabola); its state interpolated to the event, its last step above the event
    and how far into the next step it met the event (-1 and NaN until then); whether it is down. A step's marks ask
    which balls rose or landed only where that is answered at once (`xp.may_hold`), so a GPU's flight never waits
    in the middle of a step."""

    def __init__(self, state: State) -> None:
        z = state.position[:, 2]
        n = len(z)
        self.peak, self.peak_step = xp.copy(z), xp.zeros_like(z, integer=True)
        self.before, self.after = xp.full(n, math.nan, z), xp.full(n, math.nan, z)
        self.rose = False  # whether some ball may have risen to a new peak in the last step
        self.unlanded(n, z)

    def unlanded(self, n: int, like) -> None:
        """No ball of these has landed yet."""
        self.position, self.velocity, self.spin = (xp.full((n, 3), math.nan, like) for _ in range(3))
        self.frac, self.last_step = xp.full(n, math.nan, like), xp.zeros_like(like, integer=True) - 1
        self.down = xp.falses(n, like)

    def update(self, step: int, old: State, new: State, event: GroundPlane) -> None:
        """Mark the step from `old` to `new` (the balls not yet down): a new peak, the height after the peak, a
        landing."""
        z_before, z_after = old.position[:, 2], new.position[:, 2]
        aloft = ~self.down  # a ball down flies on until it is set aside: a low, spinning one may rise again
        higher = rose_above(z_after, self.peak) & aloft
        if self.rose:  # some ball's peak was the last step's state: its height after the peak is this step's
            self.after = xp.where((self.peak_step == step - 1) & ~higher, z_after, self.after)
        self.rose = xp.may_hold(higher)
        if self.rose:
            self.peak, self.before = xp.where(higher, z_after, self.peak), xp.where(higher, z_before, self.before)
            self.peak_step, self.after = xp.where(higher, step, self.peak_step), xp.where(higher, math.nan, self.after)
        landed = event.crossed(z_before, z_after) & aloft
        if not xp.may_hold(landed):
            return
        rows = xp.rows_of(landed)
        frac = event.take(rows).fraction(z_before[rows], z_after[rows], landed[rows])
        for name in ("position", "velocity", "spin"):
            interpolated = xp.lerp(getattr(old, name)[rows], getattr(new, name)[rows], frac)
            setattr(self, name, xp.put(landed, rows, getattr(self, name), interpolated))
        self.frac = xp.put(landed, rows, self.frac, frac)
        self.last_step = xp.put(landed, rows, self.last_step, step - 1)
        self.down = self.down | landed

    def take(self, index: np.ndarray) -> _Marks:
        """The marks of some balls not yet down: their apex's; they have no landing yet."""
        other = _Marks.__new__(_Marks)
        for name in APEX_MARKS:
            setattr(other, name, getattr(self, name)[index])
        other.rose = self.rose
        other.unlanded(len(other.peak), other.peak)
        return other

    def put(self, into: _Marks, ids: np.ndarray, index: np.ndarray) -> None:
        """Write the marks of these balls (`index` here) into the batch's (`ids` there)."""
        for name in APEX_MARKS + LANDING_MARKS:
            getattr(into, name)[ids] = getattr(self, name)[index]

    def flight(self, dt: float, times_s=None, states: list[State] | None = None) -> Flight:
        """The integrator's Flight of these marks (the apex the parabola through the peak and its neighbours)."""
        apex_m, apex_time_s = parabola_apex(self.before, self.peak, self.after, self.peak_step * dt, dt)
        time_s = (self.last_step + self.frac) * dt
        return Flight(self.last_step >= 0, self.position, self.velocity, self.spin, time_s, apex_m, apex_time_s,
                      times_s, states, self.last_step)


@dataclass(frozen=True)
class SetAside:
    """When a `SummaryRecord` sets landed balls aside: at every `every_steps`-th step, once `share` of the balls
    flying are down (0: any), while at least `keep_rows` would fly on. Each setting aside gathers the rest's states
    and per-ball values, so a device sets aside now and then rather than at every step (whose question, which balls
    are down, would stop its queue of work); until then a landed ball flies on below its ground, its marks kept.
    NumPy's default is every third step: a batch of 1,024 mixed shots, against the integrator before its marks,
    took 1.04 of its time setting aside at every step, 0.99 every second and 0.98 every third (interleaved A/B,
    16-30 rounds): each setting aside's gathers cost more than a landed ball's extra steps."""

    every_steps: int = 3
    share: float = 0.0
    keep_rows: int = 1


class SummaryRecord:
    """Landing, apex and times only: landed balls leave the batch (`SetAside`), so later steps cost less."""

    history: list[State] | None = None

    def __init__(self, state: State, field: VectorField, event: GroundPlane, set_aside: SetAside = SetAside()):
        self.marks, self.set_aside, self.finished = _Marks(state), set_aside, False
        self.field, self.event = field, event
        self.ids, self.batch = None, self.marks  # ids: the flying balls' rows of the batch (None: every row)

    def keep(self, old: State, new: State, step: int) -> State:
        """Mark the step from `old` to `new`; the batch's next state, after setting aside the balls down, when
        `set_aside` says so."""
        self.marks.update(step, old, new, self.event)
        rule = self.set_aside
        if step % rule.every_steps:
            return new
        down = self.marks.down
        count, flying = int(down.sum()), len(down)
        self.finished = count == flying
        if self.finished or count <= rule.share * flying or flying - count < rule.keep_rows:
            return new
        stay = xp.nonzero(~down)
        if self.ids is None:
            self.ids = stay  # the batch's marks are these marks so far: the balls leaving have theirs there
        else:
            leave = xp.nonzero(down)
            self.marks.put(self.batch, self.ids[leave], leave)
            self.ids = self.ids[stay]
        self.marks, self.field, self.event = self.marks.take(stay), self.field.take(stay), self.event.take(stay)
        return new.take(stay)

    def flight(self, dt: float) -> Flight:
        if self.ids is not None:
            self.marks.put(self.batch, self.ids, slice(None))
        return self.batch.flight(dt)


class StatesRecord(SummaryRecord):
    """Also every step's state of every ball until the last one lands; a landed ball flies on below its ground."""

    def __init__(self, state: State, field: VectorField, event: GroundPlane) -> None:
        super().__init__(state, field, event)
        self.history = [state]

    def keep(self, old: State, new: State, step: int) -> State:
        self.marks.update(step, old, new, self.event)
        self.history.append(new)
        self.finished = bool(self.marks.down.all())
        return new

    def flight(self, dt: float) -> Flight:
        return self.marks.flight(dt, dt * np.arange(len(self.history)), self.history)


class Recorder(Protocol):
    """What `integrate` hands each step: the field it steps (a record may set balls aside), whether the flight is
    finished, and what the flight comes to."""

    field: VectorField
    finished: bool

    def keep(self, old: State, new: State, step: int) -> State: ...

    def flight(self, dt: float): ...


Record = Callable[[State, VectorField, GroundPlane], Recorder]
"""What `integrate` records: `SummaryRecord` (or one with its own `SetAside`), `StatesRecord` or training's
`flight.rollout.TrajectoryRecord`, made once a flight."""


def record_for(keep_states: bool) -> Record:
    """The record that keeps every step's states, or the one that keeps the summary only."""
    return StatesRecord if keep_states else SummaryRecord


def integrate(
    state: State,
    field: VectorField,
    dt: float,
    steps: int,
    rule: StepRule = FORWARD_EULER,
    event: GroundPlane = GroundPlane(),
    record: Record = SummaryRecord,
) -> Flight:
    """Step a batch from `state` until every ball has met the event (or the record says it is finished) or `steps`
    steps have passed: the record's flight, a `Flight` where balls that never meet the event keep NaN landing values
    (`landed` False), or training's `Trajectory` from its own record. NumPy arrays or torch tensors (`flight.xp`)
    alike."""
    recorder = record(state, field, event)
    for i in range(1, steps + 1):
        state = recorder.keep(state, rule(state, recorder.field, dt), i)
        if recorder.finished:
            break
    return recorder.flight(dt)

