"""The differentiable fixed-horizon rollout training needs (paper sections 2.1, 2.3), on the flight core's equations.

The equations of motion and the Euler step are the flight core's (`flight.field.BallInAir`, `flight.integrator`),
written once over floats, NumPy and torch (`flight.xp`), and so is the loop: the rollout is the integrator with
training's record (`TrajectoryRecord`, every state kept as one graph). This module adds what training alone needs:
that record, the soft landing, and the landing and apex read back differentiably by the integrator's one rule
(`flight.events`: `came_down`, `crossing_fraction`, `rose_above`, `parabola_apex`, over all steps at once), batched over
shots and dtype-agnostic (float64 for the parity tests, float32 for training). Wind is uniform (one air velocity per
shot): real-data training fits it as a per-group nuisance, where a uniform wind is the simplest stand-in for the
profile. The landing and the apex are measured as `flight.integrator` measures them (`hard_landing`, `apex`), so
training fits the figures the runtime reports.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import torch
from golfflight.flight import xp
from golfflight.flight.field import BallInAir
from golfflight.flight.events import came_down, crossing_fraction, parabola_apex, rose_above
from golfflight.flight.integrator import FORWARD_EULER, GroundPlane, StepRule, integrate
from golfflight.flight.physics import State
from golfflight.flight.wind import CALM, WindAtBalls

DT_S = 0.1
"""Euler step of the paper (section 2.3.2): the step the models are trained and served with."""

T_SIM_S = 10.0
"""Simulated time (section 2.3.2): longer than any flight in the data, so 100 network calls."""

LANDING_CHECK_STEPS = 10
"""Steps between the checks whether every shot has come down (each waits for the device: not every step)."""

LANDING_SEARCH_START_S = 1.0
"""The soft-argmax landing (`soft_landing`, training's L_p) searches from i_s = floor(1 s / dt) on, so the tee
(r_z = 1 cm) is never taken for the landing."""

SOFT_ARGMAX_TEMPERATURE_M = 0.5
"""Default soft-argmax temperature (m of |r_z|). The weights then share out between the steps around the ground
crossing much like a linear interpolation (so the landing time gets a gradient): over 2,000 Ferguson flights the
soft landing was on average 0.16 m from the interpolated one, against 0.27 m at 0.25 m and 0.20 m at 1 m."""

CALM_AT_BALLS = CALM.at_balls
"""Calm air as the equations read it (a plain field, not `Wind`'s cached one: torch.compile cannot enter its lock)."""

Coefficients = Callable[[torch.Tensor, torch.Tensor], torch.Tensor]
"""(v_rel [N,3], omega [N,3]) -> [N,4] = C_L, C_D, C_M, C_Q, as in `flight.physics.CoefficientModel`."""


@dataclass
class Trajectory:
    """Euler states at t = 0, dt, ..., t_sim: positions, velocities, spins, each [T+1, N, 3]."""

    positions: torch.Tensor
    velocities: torch.Tensor
    spins: torch.Tensor
    dt: float

    @property
    def apex_m(self) -> torch.Tensor:
        """Apex height per shot [N], measured as the runtime measures it (`apex`)."""
        return apex(self).height_m


@dataclass
class Apex:
    """Apex per shot: height [N] (m) and time [N] (s) of the vertex of the parabola through the highest state."""

    height_m: torch.Tensor
    time_s: torch.Tensor


@dataclass
class Landing:
    """Hard landing per shot: state interpolated to r_z = 0; `landed` False where no downward crossing was found."""

    position: torch.Tensor
    velocity: torch.Tensor
    spin: torch.Tensor
    time_s: torch.Tensor
    landed: torch.Tensor


@dataclass(frozen=True)
class InAir:
    """A coefficient model in each shot's air: fed (k v_rel, k omega) at the shot's Reynolds scale k [N,1]
    (`flight.physics.reynolds_scale`), its coefficients times `coefficient_scale` [N,4] where given (a ball type's
    drag and lift relative to the ball the model learned). `run_in`: the dtype the model runs in (a bundle's graph:
    float32, as it was exported), its coefficients given back in the physics' dtype; None: the physics' own.
    Training's model, and the torch engine's network (`take`: some shots' share, as the integrator sets shots
    aside)."""

    model: Coefficients
    reynolds_scale: torch.Tensor | float = 1.0
    coefficient_scale: torch.Tensor | None = None
    run_in: torch.dtype | None = None

    def __call__(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        inputs = v_rel * self.reynolds_scale, omega * self.reynolds_scale
        if self.run_in is None:
            values = self.model(*inputs)
        else:
            values = self.model(*(x.to(self.run_in) for x in inputs)).to(v_rel.dtype)
        return values if self.coefficient_scale is None else values * self.coefficient_scale

    def take(self, index: torch.Tensor) -> InAir:
        scale = None if self.coefficient_scale is None else self.coefficient_scale[index]
        return InAir(self.model, xp.rows(self.reynolds_scale, index), scale, self.run_in)


def step_rule(compiled: bool) -> StepRule:
    """The forward-Euler step training and the torch engine fly, or, `compiled`, the same with its kernels fused by
    torch.compile, forward and backward (`dynamic=True`: one compilation for every batch size)."""
    return torch.compile(_euler, dynamic=True) if compiled else FORWARD_EULER


def _euler(state: State, field: BallInAir, dt: float) -> State:
    """FORWARD_EULER as a plain function, the form torch.compile takes."""
    return FORWARD_EULER(state, field, dt)


class TrajectoryRecord:
    """The integrator's record of training's rollout (`euler_rollout`): every step's state of every shot, kept in
    one graph, no shot set aside and nothing marked (the landing and apex are read back from the states,
    `hard_landing` and `apex`). With `stop_after_s`, the flight is finished at the first check (every
    LANDING_CHECK_STEPS steps) at or after that time where every shot has come down: started above the event's
    plane and below it now."""

    def __init__(self, state: State, field: BallInAir, event: GroundPlane, dt: float,
                 stop_after_s: float | None = None) -> None:
        self.field, self.event, self.dt, self.stop_after_s = field, event, dt, stop_after_s
        self.states, self.finished = [state], False
        self.started_up = state.position[:, 2].detach() > event.height_m

    def keep(self, old: State, new: State, step: int) -> State:
        self.states.append(new)
        self.finished = (self.stop_after_s is not None and step % LANDING_CHECK_STEPS == 0
                         and step * self.dt >= self.stop_after_s
                         and bool((self.started_up & (new.position[:, 2].detach() <= self.event.height_m)).all()))
        return new

    def flight(self, dt: float) -> Trajectory:
        return Trajectory(*(torch.stack([getattr(state, name) for state in self.states])
                            for name in ("position", "velocity", "spin")), dt)


def euler_rollout(
    position: torch.Tensor,
    velocity: torch.Tensor,
    spin: torch.Tensor,
    coefficients: Coefficients,
    density: torch.Tensor | float,
    dt: float = DT_S,
    t_sim: float = T_SIM_S,
    reynolds_scale: torch.Tensor | float = 1.0,
    wind: torch.Tensor | None = None,
    coefficient_scale: torch.Tensor | None = None,
    step: StepRule = FORWARD_EULER,
    stop_after_s: float | None = None,
) -> Trajectory:
    """Forward Euler for every shot together (fixed shapes stay batched, differentiable) through the flight core's
    integrator (`flight.integrator.integrate`, its field `BallInAir` with the model in each shot's air, `InAir`, and
    uniform `wind`, [N,3] air velocity, None = calm) over the whole t_sim, or, with `stop_after_s`, to the first check
    at or after that time where every shot has come down (`TrajectoryRecord`). What reads the states only up to each
    shot's landing and up to `stop_after_s` (`hard_landing`, `apex`, `positions_at` up to that time) then reads the
    same numbers, and the steps after the last landing are not flown. `step`: `step_rule`'s, eager or compiled."""
    air = CALM_AT_BALLS if wind is None else WindAtBalls(wind)
    field = BallInAir(InAir(coefficients, reynolds_scale, coefficient_scale), density, air)
    record = partial(TrajectoryRecord, dt=dt, stop_after_s=stop_after_s)
    return integrate(State(position, velocity, spin), field, dt, round(t_sim / dt), step, GroundPlane(), record)


def _search_start(trajectory: Trajectory, start_s: float) -> int:
    return min(int(start_s / trajectory.dt + 1e-9), trajectory.positions.shape[0] - 1)


def soft_landing(
    trajectory: Trajectory,
    temperature_m: float = SOFT_ARGMAX_TEMPERATURE_M,
    start_s: float = LANDING_SEARCH_START_S,
) -> torch.Tensor:
    """Differentiable landing point [N,2] (x, y): soft-argmax of -|r_z| from i_s on (paper eq. 15), used in training.

    The weights softmax(-|r_z| / temperature) over the steps average the horizontal positions; as the
    temperature goes to zero this becomes the position of the step nearest the ground (the hard argmax).
    """
    tail = trajectory.positions[_search_start(trajectory, start_s) :]
    weights = torch.softmax(-tail[:, :, 2].abs() / temperature_m, dim=0)
    return (weights[:, :, None] * tail[:, :, :2]).sum(dim=0)


def _first_crossing(z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Per shot of heights z [T+1, N]: the step before the first step that came down through r_z = 0
    (`flight.events.came_down`) and whether there is one; where there is none, the step before the last."""
    crossed = came_down(z[:-1], z[1:], 0.0)
    landed = crossed.any(dim=0)
    first = torch.argmax(crossed.to(torch.int8), dim=0)
    return torch.where(landed, first, z.shape[0] - 2), landed


def hard_landing(trajectory: Trajectory) -> Landing:
    """Landing as `flight.integrator` measures it: the state interpolated linearly to r_z = 0 between the two steps
    around the first downward crossing (differentiable in the states, the fraction included). Where no step crosses
    within t_sim, the last state, with `landed` False."""
    z = trajectory.positions[:, :, 2]
    before, landed = _first_crossing(z)
    shots = torch.arange(z.shape[1], device=z.device)
    z_before, z_after = z[before, shots], z[before + 1, shots]
    frac = torch.where(landed, crossing_fraction(z_before, z_after, 0.0, landed), torch.ones_like(z_before))

    def interpolate(states: torch.Tensor) -> torch.Tensor:
        old, new = states[before, shots], states[before + 1, shots]
        return old + frac[:, None] * (new - old)

    return Landing(
        interpolate(trajectory.positions),
        interpolate(trajectory.velocities),
        interpolate(trajectory.spins),
        (before + frac) * trajectory.dt,
        landed,
    )


def apex(trajectory: Trajectory) -> Apex:
    """Apex as `flight.integrator` measures it (`flight.events`): the last state up to the landing that rose above
    every state before it (`rose_above` against the running peak, all steps at once) and the vertex of the parabola
    through it and its two neighbours (`parabola_apex`); that state itself where it is the first or last state or the
    three do not bend down. Differentiable in the three heights."""
    z = trajectory.positions[:, :, 2]
    last = z.shape[0] - 1
    before, landed = _first_crossing(z)
    steps = torch.arange(last + 1, device=z.device)[:, None]
    flown = torch.where(steps <= torch.where(landed, before + 1, last), z.detach(), -torch.inf)
    rose = rose_above(flown[1:], torch.cummax(flown, dim=0).values[:-1])
    peak_step = torch.where(rose, steps[1:], 0).amax(dim=0)
    shots = torch.arange(z.shape[1], device=z.device)
    peak = z[peak_step, shots]
    earlier, later = z[(peak_step - 1).clamp_min(0), shots], z[(peak_step + 1).clamp_max(last), shots]
    inside = (peak_step > 0) & (peak_step < last)
    return Apex(*parabola_apex(earlier, peak, later, peak_step.to(z.dtype) * trajectory.dt, trajectory.dt, inside))


def positions_at(trajectory: Trajectory, times_s: torch.Tensor) -> torch.Tensor:
    """Positions [N,K,3] at times [N,K] (s), linear between the Euler steps around each time (differentiable in
    the positions); times beyond t_sim take the last state."""
    positions = trajectory.positions.transpose(0, 1)  # [N, T+1, 3]
    last = positions.shape[1] - 1
    steps = (times_s / trajectory.dt).clamp(0, last)
    before = steps.floor().long().clamp(max=last - 1)
    frac = (steps - before).unsqueeze(-1)
    index = before.unsqueeze(-1).expand(-1, -1, 3)
    old, new = positions.gather(1, index), positions.gather(1, index + 1)
    return old + frac * (new - old)
