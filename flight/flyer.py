"""The one way a coefficient model is flown: `Flyer`, a model with its step rule, step, maximum flight time and air.

`load_flyer` is the only code that finds and assembles a model bundle: the lookup (`flight.bundle_location`), the
card's step, maximum flight time (its t_sim, or the shot records' limit if longer), air and ball, checked against
`flight.constants`. A Flyer puts its model in a given air (`in_air`: the graph fed at that air's Reynolds scale).
`Flyer.flight` is the one batch flight: a state through `flight.integrator.integrate` in given air and wind, down to
ground planes. `fly_batch` plans launches [N, LAUNCH_WIDTH] x conditions x grounds into it: each shot down to its
ground's plane (the state interpolated linearly to it), failing alone if it is still in the air at the maximum
flight time, then bounced and rolled to rest on that ground (`flight.ground`) unless the flight alone was asked for.
The engine's batches (`flight.engine`), discovery, accuracy, evaluation, the reference world and the ground fit all
fly through it, so every one of them flies the same shot to the same numbers.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path
from typing import NamedTuple, Protocol

import numpy as np
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.constants import BALL_MASS_KG, BALL_RADIUS_M
from golfflight.flight.field import BallInAir, ScaledCoefficients
from golfflight.flight.ground import GroundPhase, GroundSpec, batch_surface, elevations, ground_phase
from golfflight.flight.integrator import FORWARD_EULER, GroundPlane, StepRule, integrate, record_for
from golfflight.flight.limits import FLIGHT_TIME_S
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.flight.outcomes import (
    BatchFlights,
    EulerStates,
    Flight,
    Rest,
    landing_figures,
)
from golfflight.flight.per_shot import PerShot
from golfflight.flight.physics import CoefficientModel, ExtraAcceleration, State, initial_state
from golfflight.flight.wind import CALM, Wind
from golfflight.weights_schema.bundle import CARD_FILE, BundleError
from golfflight.weights_schema.model_card import ModelCard

MAX_FLIGHT_TIME_S = FLIGHT_TIME_S.high
"""Longest flight simulated (20 s, the shot records' limit) unless a card's t_sim is longer; a shot still in the air
then gets a FlightError."""

BATCH_THREADS = 1
"""ORT threads of a batch step. One: on the 2-core machine, with other work running (a training job, a second
worker), two threads took 96-120 us a shot against 35-42 for one (docs/benchmarks.md); a quiet machine gains
about 1.5x from a second thread, so pass batch_threads=2 where the cores are the engine's alone."""

NON_FINITE = "the model gave a non-finite flight for this launch"


class Launch(NamedTuple):
    """Launch-monitor values of one shot, SI (paper eq. 12's inputs)."""

    ball_speed_mps: float
    launch_angle_deg: float
    launch_direction_deg: float
    spin_rpm: float
    spin_axis_deg: float


LAUNCH_WIDTH = len(Launch._fields)
"""The width of a launches array [N, LAUNCH_WIDTH], its columns in Launch's order (`shots.records.LAUNCH_COLUMNS`
and `contract.columns.LAUNCH_COLUMNS` name the columns of files)."""


class ModelInAir(Protocol):
    """A coefficient model that can be put in air of another kinematic viscosity (its Reynolds numbers)."""

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray: ...

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray) -> CoefficientModel: ...


@dataclass(frozen=True)
class AirInputs:
    """What the equations need of a shot's conditions: density, the wind at its reference height, whether it follows
    the log profile (and the profile's reference height and roughness), and the kinematic viscosity."""

    density_kg_m3: float
    wind_x_mps: float
    wind_y_mps: float
    log_profile: bool
    reference_height_m: float
    roughness_m: float
    kinematic_viscosity_m2_s: float


@lru_cache(maxsize=1024)
def air_inputs(conditions: Conditions) -> AirInputs:
    """The AirInputs of a shot's conditions; cached because a batch or a stream of shots mostly shares a few."""
    wind_x, wind_y = conditions.wind_at_reference_mps
    wind, air = conditions.wind, conditions.air
    return AirInputs(
        density_kg_m3=air.density_kg_m3,
        wind_x_mps=wind_x,
        wind_y_mps=wind_y,
        log_profile=wind.profile == "log" and (wind_x != 0.0 or wind_y != 0.0),
        reference_height_m=wind.reference_height_m,
        roughness_m=wind.roughness_m,
        kinematic_viscosity_m2_s=air.kinematic_viscosity_m2_s,
    )


def step_count(max_time_s: float, dt_s: float) -> int:
    """Steps of dt_s that reach max_time_s (a whole number of steps up to rounding)."""
    return math.ceil(max_time_s / dt_s - 1e-9)


class _FlownBatch(NamedTuple):
    """A batch's columns, the integrator's flight and the ground phase of its rolled shots (in shot order)."""

    columns: BatchFlights
    flight: Flight
    phase: GroundPhase | None


class Flyer:
    """A coefficient model flown by one step rule at one step, for at most one flight time, in its nominal air unless
    told otherwise. `card` and `bundle_dir` are a bundle's (None for a closed-form model)."""

    def __init__(
        self,
        model: ModelInAir,
        dt_s: float,
        max_flight_time_s: float,
        density_kg_m3: float,
        kinematic_viscosity_m2_s: float,
        rule: StepRule = FORWARD_EULER,
        card: ModelCard | None = None,
        bundle_dir: Path | None = None,
    ) -> None:
        self.model, self.rule, self.card, self.bundle_dir = model, rule, card, bundle_dir
        self.dt_s, self.max_flight_time_s = float(dt_s), float(max_flight_time_s)
        self.density_kg_m3, self.kinematic_viscosity_m2_s = float(density_kg_m3), float(kinematic_viscosity_m2_s)
        self.max_steps = step_count(self.max_flight_time_s, self.dt_s)

    def replaced(
        self, model: ModelInAir | None = None, rule: StepRule | None = None, dt_s: float | None = None
    ) -> Flyer:
        """This Flyer with another model, step rule or step, the rest kept (discovery flies a learned form, or RK4)."""
        return Flyer(
            self.model if model is None else model,
            self.dt_s if dt_s is None else dt_s,
            self.max_flight_time_s,
            self.density_kg_m3,
            self.kinematic_viscosity_m2_s,
            self.rule if rule is None else rule,
            self.card,
            self.bundle_dir,
        )

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray | None = None) -> CoefficientModel:
        """The model in air of this kinematic viscosity (a float, or one per ball); None: its nominal air."""
        viscosity = self.kinematic_viscosity_m2_s if kinematic_viscosity_m2_s is None else kinematic_viscosity_m2_s
        return self.model.in_air(viscosity)

    def flight(
        self,
        state: State,
        density_kg_m3: float | np.ndarray | None = None,
        kinematic_viscosity_m2_s: float | np.ndarray | None = None,
        wind: Wind = CALM,
        ground_height_m: float | np.ndarray = 0.0,
        keep_states: bool = False,
        max_time_s: float | None = None,
        coefficient_scale: np.ndarray | None = None,
        correction: ExtraAcceleration | None = None,
    ) -> Flight:
        """THE batch flight: the integrator's Flight from `state` in this air (None: the nominal) and wind down to
        ground planes, for the maximum flight time (or `max_time_s`, for a caller that compares states at fixed
        times); the coefficients times `coefficient_scale` [N,3] and an extra acceleration where given (discovery's
        effects and corrections). `fly_batch` plans launches and conditions into this call."""
        density = self.density_kg_m3 if density_kg_m3 is None else density_kg_m3
        model = self.in_air(kinematic_viscosity_m2_s)
        if coefficient_scale is not None:
            model = ScaledCoefficients(model, coefficient_scale)
        field = BallInAir(model, density, wind, correction)
        steps = self.max_steps if max_time_s is None else step_count(max_time_s, self.dt_s)
        event = GroundPlane(np.asarray(ground_height_m, dtype=float))
        return integrate(state, field, self.dt_s, steps, self.rule, event, record_for(keep_states))

    def unlanded_message(self, apex_m: float, height_m: float) -> str:
        """Why a shot never came down through its ground's plane: it never rose above it, or it was still in the air
        at the cap."""
        if apex_m <= height_m:
            return f"the ball never rose to its landing ground: apex {apex_m:.1f} m, ground.elevation_m {height_m:g} m"
        return f"the ball was still in the air after {self.max_steps * self.dt_s:g} s (the simulation cap)"

    def fly_batch(
        self,
        launches: Sequence[Launch] | np.ndarray,
        conditions: Sequence[Conditions] | Conditions = STANDARD,
        grounds: Sequence[GroundSpec | None] | GroundSpec | None = None,
        keep_states: bool = False,
    ) -> BatchFlights:
        """Shots (launches an [N, LAUNCH_WIDTH] array or a sequence of Launch), each in its conditions, down to its
        ground and rolled to rest there (grounds None: the flights alone, down to z = 0), as columns; a shot that has
        not landed by the maximum flight time, or whose flight is not finite, fails (`errors`). With `keep_states`,
        each shot's states through its bounces and roll (`BatchFlights.states`). `.shots()` gives one ShotFlight a
        shot."""
        columns, flight, phase = self._fly(launches, conditions, keep_states, grounds)
        if flight.states is None:
            return columns
        history = (np.stack([s.position for s in flight.states]), np.stack([s.velocity for s in flight.states]))
        rolled_row = np.cumsum(columns.rolled) - 1
        states: list[EulerStates | None] = [None] * len(columns.rolled)
        errors = dict(columns.errors)
        for i in range(len(states)):
            if i in errors:
                continue
            kept = self._shot_states(history, flight, i)
            if columns.rolled[i]:
                kept = kept.through_rest(phase, int(rolled_row[i]), float(columns.flight_time_s[i]))
            if kept.finite:
                states[i] = kept
            else:
                errors[i] = NON_FINITE
        return replace(columns, states=states, errors=errors)

    def _fly(
        self,
        launches: Sequence[Launch] | np.ndarray,
        conditions: Sequence[Conditions] | Conditions,
        keep_states: bool,
        grounds: Sequence[GroundSpec | None] | GroundSpec | None,
    ) -> _FlownBatch:
        """The batch flight behind `fly_batch`."""
        n = len(launches)
        per_shot = PerShot.of(conditions, n, "conditions")
        shot_grounds = PerShot.of(grounds, n, "grounds")
        heights = elevations(shot_grounds)
        start = initial_state(*np.asarray(launches, dtype=float).reshape(n, LAUNCH_WIDTH).T)
        air = batch_air(per_shot)
        flight = self.flight(start, air.density_kg_m3, air.kinematic_viscosity_m2_s, air.wind, heights, keep_states)
        roll = partial(ground_phase, keep_path=keep_states)
        columns, phase = landed_columns(flight, shot_grounds, self.unlanded_message, roll)
        return _FlownBatch(columns, flight, phase)

    def _shot_states(self, history: tuple[np.ndarray, np.ndarray], flight: Flight, shot: int) -> EulerStates:
        """One shot's states up to its landing, the interpolated landing last (history: every step's positions and
        velocities, [T, N, 3] each)."""
        last = int(flight.last_step[shot])
        return EulerStates.to_landing(history[0][: last + 1, shot], history[1][: last + 1, shot],
                                      flight.landing_position[shot], flight.landing_velocity[shot], self.dt_s,
                                      flight.flight_time_s[shot])


class BatchAir(NamedTuple):
    """A batch's air as the equations take it: density and kinematic viscosity [N], the wind of every shot."""

    density_kg_m3: np.ndarray
    kinematic_viscosity_m2_s: np.ndarray
    wind: Wind


def batch_air(per_shot: PerShot[Conditions]) -> BatchAir:
    """Each shot's air and wind as [N] columns, read once for each distinct conditions (`air_inputs`)."""
    inputs = PerShot([air_inputs(c) for c in per_shot.objects], per_shot.index)
    wind = Wind(
        per_shot.column(lambda c: c.wind.speed_mps),
        per_shot.column(lambda c: c.wind.from_deg),
        per_shot.column(lambda c: c.wind.profile, None),
        inputs.column(lambda a: a.reference_height_m),
        inputs.column(lambda a: a.roughness_m),
    )
    return BatchAir(inputs.column(lambda a: a.density_kg_m3), inputs.column(lambda a: a.kinematic_viscosity_m2_s),
                    wind)


Roll = Callable[..., GroundPhase]
"""(position, velocity, spin [N,3], surface, slope_deg, slope_dir_deg) -> the ground phase of those landings
(`flight.ground.ground_phase`, or the same driver on a device)."""


def landed_columns(
    flight: Flight, grounds: PerShot[GroundSpec | None], unlanded: Callable[[float, float], str], roll: Roll
) -> tuple[BatchFlights, GroundPhase | None]:
    """A batch's columns from its flight (NumPy), for every backend: the figures (NaN where a shot never came down), an
    error a shot that never came down (`unlanded(apex_m, ground_m)`) or whose figures are not finite, and the rests
    of the landed shots with a ground, bounced and rolled by `roll` in one batch; and that ground phase."""
    n = len(flight.landed)
    x, y = flight.landing_position[:, 0], flight.landing_position[:, 1]
    carry, angle, speed, spin = landing_figures(x, y, *flight.landing_velocity.T, *flight.landing_spin.T)
    numbers = (x, y, carry, flight.apex_m, flight.apex_time_s, flight.flight_time_s, angle, speed, spin)
    finite = np.isfinite(np.stack(numbers)).all(axis=0)
    failed = np.flatnonzero(~(flight.landed & finite))
    heights = elevations(grounds) if failed.size else None  # the grounds' elevations only where a message needs one
    errors = {}
    for i in failed.tolist():
        errors[i] = unlanded(float(flight.apex_m[i]), float(heights[i])) if not flight.landed[i] else NON_FINITE
    rolled = flight.landed & finite & grounds.column(lambda g: g is not None, bool)
    shots = np.flatnonzero(rolled)
    phase = None
    if shots.size:
        on = grounds.take(shots)
        landing = (flight.landing_position[shots], flight.landing_velocity[shots], flight.landing_spin[shots])
        phase = roll(*landing, batch_surface(on), on.column(lambda g: g.slope_deg),
                     on.column(lambda g: g.slope_dir_deg))
    x, y, carry, angle, speed, spin, flight_time = (
        np.where(flight.landed, v, math.nan) for v in (x, y, carry, angle, speed, spin, flight.flight_time_s)
    )
    columns = BatchFlights(
        landing_x_m=x, landing_y_m=y, carry_m=carry, lateral_m=x, apex_m=flight.apex_m,
        apex_time_s=flight.apex_time_s, flight_time_s=flight_time, landing_angle_deg=angle,
        landing_speed_mps=speed, landing_spin_rpm=spin, rest=Rest.of_batch(phase, shots, n, carry),
        rolled=rolled, errors=errors,
    )
    return columns, phase


def check_ball(card: ModelCard, card_path: Path) -> None:
    """The card's ball is the one `flight.constants` flies (the equations use those constants, not the card's):
    a bundle trained on another ball would be flown as the wrong ball, so it is refused."""
    physics = card.physics
    pairs = (
        (physics.ball_mass_kg, BALL_MASS_KG, "ball_mass_kg"),
        (physics.ball_radius_m, BALL_RADIUS_M, "ball_radius_m"),
    )
    wrong = [f"{name} {value:g} (the engine's {ours:g})" for value, ours, name in pairs
             if not math.isclose(value, ours, rel_tol=1e-9)]
    if wrong:
        raise BundleError(f"{card_path}: the card's ball is not the one the engine flies: {'; '.join(wrong)}")


def load_flyer(bundle: str | os.PathLike | None = None, batch_threads: int = BATCH_THREADS) -> Flyer:
    """THE way a model bundle is found and assembled: `bundle`, or None for the served default (the lookup of
    `flight.bundle_location`), loaded and verified (BundleError otherwise), its ball checked, flown forward Euler at
    its card's step for max(card t_sim, MAX_FLIGHT_TIME_S), in its card's air by default; `batch_threads` ORT threads
    a step."""
    directory = model_dir(bundle)
    model = OnnxCoefficients(directory, batch_threads)
    card = model.card
    check_ball(card, directory / CARD_FILE)
    physics = card.physics
    return Flyer(
        model,
        dt_s=physics.dt_s,
        max_flight_time_s=max(physics.t_sim_s, MAX_FLIGHT_TIME_S),
        density_kg_m3=physics.air_density_kg_m3,
        kinematic_viscosity_m2_s=physics.kinematic_viscosity_m2_s,
        card=card,
        bundle_dir=directory,
    )


class FixedCoefficients:
    """A closed-form coefficient model with no Reynolds-number input: the same in any air."""

    def __init__(self, model: CoefficientModel) -> None:
        self.model = model

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        return self.model(v_rel, omega)

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray) -> CoefficientModel:
        return self.model

