"""The one way a coefficient model is flown: `Flyer`, a model with its step rule, step, maximum flight time and air.

`load_flyer` is the only code that finds and assembles a model bundle: the lookup (`flight.bundle_location`), the
card's step, maximum flight time (its t_sim, or the shot records' limit if longer), air and ball, checked against
`flight.constants`. A Flyer puts its model in a given air (`in_air`: the graph fed at that air's Reynolds scale).
`Flyer.flight` is the one batch flight: a `flight.problem.FlightProblem` through `flight.integrator.integrate`, down
to its ground planes. `fly_batch` (the `flight.problem.Engine` protocol) adds the rest: each shot down to its
ground's plane (the state interpolated linearly to it), failing alone if it is still in the air at the maximum
flight time, then bounced and rolled to rest on its ground (`flight.ground`) where the problem gives one.
The engine's batches (`flight.engine`), discovery, accuracy, evaluation, the reference world and the ground fit all
fly through it, so every one of them flies the same shot to the same numbers.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import NamedTuple, Protocol

import numpy as np
from golfflight.flight.bundle_location import model_dir
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
from golfflight.flight.physics import CoefficientModel
from golfflight.flight.problem import FlightProblem
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


class ModelInAir(Protocol):
    """A coefficient model that can be put in air of another kinematic viscosity (its Reynolds numbers)."""

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray: ...

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray) -> CoefficientModel: ...


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
    told otherwise. `card` and `bundle_dir` are a bundle's (None for a closed-form model); `label` names it in reports
    (default: the bundle's directory, or the model's class)."""

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
        label: str | None = None,
    ) -> None:
        self.model, self.rule, self.card, self.bundle_dir = model, rule, card, bundle_dir
        self.label = label or (f"`{bundle_dir}`" if bundle_dir is not None else type(model).__name__)
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
            self.label,
        )

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray | None = None) -> CoefficientModel:
        """The model in air of this kinematic viscosity (a float, or one per ball); None: its nominal air."""
        viscosity = self.kinematic_viscosity_m2_s if kinematic_viscosity_m2_s is None else kinematic_viscosity_m2_s
        return self.model.in_air(viscosity)

    def flight(self, problem: FlightProblem) -> Flight:
        """THE batch flight: the integrator's Flight of `problem`'s balls in their air (None: this Flyer's nominal)
        and wind down to their ground planes, for the maximum flight time or the problem's `max_time_s` (a caller that
        compares states at fixed times), its coefficients times the problem's scales and its extra acceleration where
        given (discovery's effects and corrections); no ground phase (`fly_batch` adds it)."""
        air = problem.columns
        density = self.density_kg_m3 if air.density_kg_m3 is None else air.density_kg_m3
        model = self.in_air(air.kinematic_viscosity_m2_s)
        if problem.coefficient_scale is not None:
            model = ScaledCoefficients(model, problem.coefficient_scale)
        field = BallInAir(model, density, air.wind, problem.correction)
        steps = self.max_steps if problem.max_time_s is None else step_count(problem.max_time_s, self.dt_s)
        event = GroundPlane(np.asarray(problem.heights, dtype=float))
        return integrate(problem.start, field, self.dt_s, steps, self.rule, event, record_for(problem.keeps()))

    def unlanded_message(self, apex_m: float, height_m: float) -> str:
        """Why a shot never came down through its ground's plane: it never rose above it, or it was still in the air
        at the cap."""
        if apex_m <= height_m:
            return f"the ball never rose to its landing ground: apex {apex_m:.1f} m, ground.elevation_m {height_m:g} m"
        return f"the ball was still in the air after {self.max_steps * self.dt_s:g} s (the simulation cap)"

    def fly_batch(self, problem: FlightProblem) -> BatchFlights:
        """`problem`'s shots down to their grounds and rolled to rest there (a shot with no GroundSpec: the flight
        alone), as columns; a shot that has not landed by the maximum flight time, or whose flight is not finite,
        fails (`errors`). Where states are kept, each shot's through its bounces and roll (`BatchFlights.states`).
        `.shots()` gives one ShotFlight a shot."""
        columns, flight, phase = self._fly(problem)
        if flight.states is None:
            return columns
        history = (np.stack([s.position for s in flight.states]), np.stack([s.velocity for s in flight.states]))
        rolled_row = np.cumsum(columns.rolled) - 1
        states: list[EulerStates | None] = [None] * len(columns.rolled)
        errors = dict(columns.errors)
        for i in range(len(states)):
            if i in errors or not problem.keeps(i):
                continue
            kept = self._shot_states(history, flight, i)
            if columns.rolled[i]:
                kept = kept.through_rest(phase, int(rolled_row[i]), float(columns.flight_time_s[i]))
            if kept.finite:
                states[i] = kept
            else:
                errors[i] = NON_FINITE
        return replace(columns, states=states, errors=errors)

    def _fly(self, problem: FlightProblem) -> _FlownBatch:
        """The batch flight behind `fly_batch`."""
        flight = self.flight(problem)
        roll = partial(ground_phase, keep_path=problem.keeps())
        columns, phase = landed_columns(flight, problem.ground_specs, self.unlanded_message, roll)
        return _FlownBatch(columns, flight, phase)

    def _shot_states(self, history: tuple[np.ndarray, np.ndarray], flight: Flight, shot: int) -> EulerStates:
        """One shot's states up to its landing, the interpolated landing last (history: every step's positions and
        velocities, [T, N, 3] each)."""
        last = int(flight.last_step[shot])
        return EulerStates.to_landing(history[0][: last + 1, shot], history[1][: last + 1, shot],
                                      flight.landing_position[shot], flight.landing_velocity[shot], self.dt_s,
                                      flight.flight_time_s[shot])


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

