"""The runtime simulator: a model bundle's ONNX coefficients inside the equations of `flight.physics`.

Forward Euler at the card's step, one ONNX Runtime call per step for everything still in the air, fed v_rel and
omega times the air's Reynolds scale (`flight.physics.reynolds_scale`, 1 in the card's air). One shot runs
on plain Python floats with the network's inputs and output bound once to preallocated float32 buffers
(IOBinding, one thread): per-call overheads, not arithmetic, decide single-shot latency (docs/benchmarks.md).
A batch runs on NumPy [N] arrays and drops each shot from the batch as it lands. Either way a shot stops at its
landing (first downward crossing of its ground's plane, z = elevation, the state interpolated linearly to it, exact
for Euler's straight segments), flies on past the card's t_sim if it is still in the air, and fails alone if it has
not landed by MAX_FLIGHT_TIME_S. Then, unless asked for the flight alone (ground None), it bounces and rolls to rest
on that ground (`flight.ground`).
"""

from __future__ import annotations

import math
import os
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, fields
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

import numpy as np
from golfflight.flight.bundle_check import open_session, session_options
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.constants import RPM_TO_RADPS
from golfflight.flight.field import BallInAir
from golfflight.flight.ground import GroundPhase, GroundSpec, Surface, ground_phase, ground_phase_one
from golfflight.flight.integrator import GroundPlane, integrate
from golfflight.flight.limits import FLIGHT_TIME_S
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.flight.outcomes import Flight, landing_angle_deg, parabola_apex
from golfflight.flight.physics import euler_step, initial_state, reynolds_scale
from golfflight.flight.wind import Wind, log_profile_factor
from golfflight.weights_schema.model_card import ModelCard

MAX_FLIGHT_TIME_S = FLIGHT_TIME_S.high
"""Longest flight simulated (20 s, the shot records' limit); a shot still in the air then gets a FlightError."""


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


class FlightError(Exception):
    """A shot the engine could not fly to the ground (the message says why); a batch reports it for that shot."""


@dataclass(frozen=True)
class EulerStates:
    """States of one shot: times [K], positions and velocities [K,3]: the integrator's steps to the interpolated
    landing and, when the shot was rolled, the ground phase's states to the rest (an impact twice: in and out)."""

    times_s: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray


@dataclass(frozen=True)
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


@dataclass(frozen=True)
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


def _summary(x, y, vx, vy, vz, wx, wy, wz):
    """(carry, landing angle, landing speed, landing spin) from a landing state (floats or arrays)."""
    return (
        np.hypot(x, y),
        landing_angle_deg(vx, vy, vz),
        (vx * vx + vy * vy + vz * vz) ** 0.5,
        (wx * wx + wy * wy + wz * wz) ** 0.5 / RPM_TO_RADPS,
    )


@lru_cache(maxsize=1024)
def _physics_inputs(conditions: Conditions) -> tuple[float, float, float, bool, float, float, float]:
    """(density, wind x, wind y at the reference height, log profile?, reference height, roughness, kinematic
    viscosity) of a shot's conditions; cached because a batch or a stream of shots mostly shares a few."""
    wind_x, wind_y = conditions.wind_at_reference_mps
    wind, air = conditions.wind, conditions.air
    log_profile = wind.profile == "log" and (wind_x != 0.0 or wind_y != 0.0)
    return (
        air.density_kg_m3,
        wind_x,
        wind_y,
        log_profile,
        wind.reference_height_m,
        wind.roughness_m,
        air.kinematic_viscosity_m2_s,
    )


def _rest(phase: GroundPhase, i: int, carry: float) -> Rest:
    """Shot i's rest from a ground phase of the tee at the origin."""
    x, y, _ = phase.rest_position[i].tolist()
    total = math.hypot(x, y)
    return Rest(x, y, total, total - carry, int(phase.bounces[i]), float(phase.time_s[i]))


def _rests(phase: GroundPhase | None, shots: np.ndarray, n: int, carry: np.ndarray) -> Rest:
    """The rests of a batch's `shots` (rolled, in order) as a Rest of [n] arrays, NaN (bounces -1) for the others."""
    x, y, total, ground_time = (np.full(n, np.nan) for _ in range(4))
    bounces = np.full(n, -1, dtype=np.int64)
    if phase is not None:
        x[shots], y[shots] = phase.rest_position[:, 0], phase.rest_position[:, 1]
        total[shots] = [math.hypot(a, b) for a, b in zip(x[shots].tolist(), y[shots].tolist(), strict=True)]
        bounces[shots], ground_time[shots] = phase.bounces, phase.time_s
    return Rest(x, y, total, total - carry, bounces, ground_time)


@dataclass(frozen=True)
class BatchFlights:
    """A batch's outcomes as [N] arrays, named as ShotFlight's fields: what `FlightEngine.fly_batch` turns into one
    ShotFlight a shot, for callers that want columns. `rest` holds arrays too (NaN, bounces -1, where `rolled` is
    False: a flight alone, or a shot that failed); `errors` maps a failed shot to why (its numbers are meaningless)."""

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

    def take(self, shots) -> BatchFlights:
        """The flights of `shots` (indices), in that order."""
        shots = np.asarray(shots, dtype=np.intp)
        where = {int(s): k for k, s in enumerate(shots.tolist())}
        rest = Rest(*(getattr(self.rest, f.name)[shots] for f in fields(Rest)))
        arrays = {f.name: getattr(self, f.name)[shots] for f in fields(self) if f.name not in ("rest", "errors")}
        errors = {where[i]: message for i, message in self.errors.items() if i in where}
        return BatchFlights(**arrays, rest=rest, errors=errors)


def _through_rest(states: EulerStates, phase: GroundPhase, i: int, flight_time: float) -> EulerStates:
    """A flight's states continued through shot i's ground path (its first row, the landing, is the flight's last)."""
    path = phase.paths[i]
    return EulerStates(
        np.append(states.times_s, flight_time + path.times_s[1:]),
        np.vstack([states.positions, path.positions[1:]]),
        np.vstack([states.velocities, path.velocities[1:]]),
    )


def _batch_field(model: OnnxCoefficients, per_shot: list[Conditions]) -> BallInAir:
    """The equations of motion for a batch, each shot in its own air and wind."""
    density, _, _, _, reference_height, roughness, viscosity = np.array([_physics_inputs(c) for c in per_shot]).T
    wind = Wind(
        np.array([c.wind.speed_mps for c in per_shot], dtype=float),
        np.array([c.wind.from_deg for c in per_shot], dtype=float),
        np.array([c.wind.profile for c in per_shot]),
        reference_height,
        roughness,
    )
    return BallInAir(model.in_air(viscosity), density, wind)


class FlightEngine:
    """A loaded model bundle and the two ways to fly shots through it: `fly` (one) and `fly_batch` (many)."""

    def __init__(self, bundle_dir: str | os.PathLike, batch_threads: int = BATCH_THREADS):
        """Load and verify a bundle (card, hash, graph interface, finite coefficients on a probe set: BundleError
        otherwise), then warm both paths up."""
        started = time.perf_counter()
        self.bundle_dir = Path(bundle_dir)
        self._batch_model = OnnxCoefficients(self.bundle_dir, batch_threads)
        self.card: ModelCard = self._batch_model.card
        self.dt = self.card.physics.dt_s
        self.t_sim = self.card.physics.t_sim_s
        self.nominal_viscosity = self.card.physics.kinematic_viscosity_m2_s
        self.max_steps = math.ceil(max(MAX_FLIGHT_TIME_S, self.t_sim) / self.dt - 1e-9)
        velocity_name, spin_name = (spec.name for spec in self.card.onnx.inputs)
        self._single_session = open_session(self._batch_model.onnx_path, session_options(1))
        self._single_lock = threading.Lock()
        self._velocity_in = np.zeros((1, 3), np.float32)
        self._spin_in = np.zeros((1, 3), np.float32)
        self._coefficients_out = np.zeros((1, 4), np.float32)
        self._binding = self._single_session.io_binding()
        for name, buffer in ((velocity_name, self._velocity_in), (spin_name, self._spin_in)):
            self._binding.bind_input(name, "cpu", 0, np.float32, list(buffer.shape), buffer.ctypes.data)
        self._binding.bind_output(
            self.card.onnx.outputs[0].name,
            "cpu",
            0,
            np.float32,
            list(self._coefficients_out.shape),
            self._coefficients_out.ctypes.data,
        )
        self.fly(Launch(60.0, 12.0, 0.0, 3000.0, 0.0))  # first runs allocate inside ORT: keep them off the clock
        self.fly_batch([Launch(60.0, 12.0, 0.0, 3000.0, 0.0)] * 8)
        self.load_seconds = time.perf_counter() - started

    def _unlanded_message(self, apex_m: float, height_m: float) -> str:
        """Why a shot never came down through its ground's plane: it never rose above it, or it was still in the air
        at the cap."""
        if apex_m <= height_m:
            return f"the ball never rose to its landing ground: apex {apex_m:.1f} m, ground.elevation_m {height_m:g} m"
        return f"the ball was still in the air after {self.max_steps * self.dt:g} s (the simulation cap)"

    @staticmethod
    def _states_finite(states: EulerStates | None) -> bool:
        """Whether every recorded state is finite (a broken model's NaN never reaches a client)."""
        return states is None or all(np.isfinite(a).all() for a in (states.times_s, states.positions, states.velocities))

    @property
    def variant(self) -> str:
        return self.card.variant

    @property
    def sha256(self) -> str:
        """SHA-256 of the ONNX graph (checked against the card at load)."""
        return self.card.onnx.sha256

    def fly(
        self,
        launch: Launch,
        conditions: Conditions = STANDARD,
        keep_states: bool = False,
        ground: GroundSpec | None = None,
    ) -> ShotFlight:
        """Fly one shot on Python floats down to its ground and roll it to rest there on floats too
        (`flight.ground.ground_phase_one`; with states kept, the batch ground phase, which records the path); ground
        None: the flight alone, down to z = 0. Raises FlightError if it has not landed by MAX_FLIGHT_TIME_S (or, from
        a broken model, if any number of its flight is not finite)."""
        start = initial_state(*(np.array([value], dtype=float) for value in launch))
        x, y, z = start.position[0].tolist()
        vx, vy, vz = start.velocity[0].tolist()
        wx, wy, wz = start.spin[0].tolist()
        density, wind_x, wind_y, log_wind, reference_height, roughness, viscosity = _physics_inputs(conditions)
        k = reynolds_scale(viscosity, self.nominal_viscosity)
        air_x, air_y = wind_x, wind_y
        dt = self.dt
        height = 0.0 if ground is None else ground.elevation_m
        apex, apex_step, before_apex, after_apex = z, 0, math.nan, math.nan
        history = [(x, y, z, vx, vy, vz)] if keep_states else None
        velocity_in, spin_in, out = self._velocity_in[0], self._spin_in[0], self._coefficients_out[0]
        with self._single_lock:
            run, binding = self._single_session.run_with_iobinding, self._binding
            for step in range(1, self.max_steps + 1):
                if log_wind:
                    factor = log_profile_factor(z, reference_height, roughness)
                    air_x, air_y = wind_x * factor, wind_y * factor
                velocity_in[0], velocity_in[1], velocity_in[2] = (vx - air_x) * k, (vy - air_y) * k, vz * k
                spin_in[0], spin_in[1], spin_in[2] = wx * k, wy * k, wz * k
                run(binding)
                old = (x, y, z, vx, vy, vz, wx, wy, wz)
                x, y, z, vx, vy, vz, wx, wy, wz = euler_step(*old, out.tolist(), density, air_x, air_y, dt)
                if z > apex:
                    apex, apex_step, before_apex, after_apex = z, step, old[2], math.nan
                elif apex_step == step - 1:
                    after_apex = z
                if z <= height < old[2]:
                    break
                if history is not None:
                    history.append((x, y, z, vx, vy, vz))
            else:
                raise FlightError(self._unlanded_message(apex, height))
        frac = (old[2] - height) / (old[2] - z)
        land = [a + frac * (b - a) for a, b in zip(old, (x, y, z, vx, vy, vz, wx, wy, wz))]
        flight_time = (step - 1 + frac) * dt
        carry, angle, speed, spin = (float(v) for v in _summary(land[0], land[1], *land[3:]))
        states = None
        if history is not None:
            history.append(tuple(land[:6]))
            rows = np.array(history)
            times = np.append(np.round(dt * np.arange(len(history) - 1), 9), flight_time)
            states = EulerStates(times, rows[:, :3], rows[:, 3:])
        apex, apex_time = parabola_apex(before_apex, apex, after_apex, apex_step * dt, dt)
        numbers = (land[0], land[1], carry, apex, apex_time, flight_time, angle, speed, spin)
        if not (all(map(math.isfinite, numbers)) and self._states_finite(states)):
            raise FlightError(NON_FINITE)
        rest = None
        if ground is not None and states is None:
            one = ground_phase_one(
                tuple(land[0:3]), tuple(land[3:6]), tuple(land[6:9]), ground.surface, ground.slope_deg,
                ground.slope_dir_deg,
            )
            x, y, _ = one.position
            total = math.hypot(x, y)
            rest = Rest(x, y, total, total - carry, one.bounces, one.time_s)
        elif ground is not None:
            landing = np.array([land[0:3]]), np.array([land[3:6]]), np.array([land[6:9]])
            phase = ground_phase(*landing, ground.surface, ground.slope_deg, ground.slope_dir_deg, True)
            rest = _rest(phase, 0, carry)
            states = _through_rest(states, phase, 0, flight_time)
        return ShotFlight(
            land[0], land[1], carry, land[0], apex, apex_time, flight_time, angle, speed, spin, states, rest
        )

    def fly_batch(
        self,
        launches: Sequence[Launch],
        conditions: Sequence[Conditions] | Conditions = STANDARD,
        keep_states: bool = False,
        grounds: Sequence[GroundSpec] | GroundSpec | None = None,
    ) -> list[ShotFlight | FlightError]:
        """Fly many shots through the flight core (`flight.integrator`): forward Euler, one ONNX Runtime call per
        step over the shots still in the air, each down to its ground; then bounce and roll them to rest together
        (grounds None: the flights alone, down to z = 0).

        Results are in the order of `launches`; a shot that has not landed by MAX_FLIGHT_TIME_S (or whose flight is
        not finite) gets a FlightError. The numbers are `fly_columns`'s, one object a shot.
        """
        if len(launches) == 0:
            return []
        columns, flight, phase = self._batch(launches, conditions, keep_states, grounds)
        history = None
        if flight.states is not None:
            history = (np.stack([s.position for s in flight.states]), np.stack([s.velocity for s in flight.states]))
        numbers = (columns.landing_x_m, columns.landing_y_m, columns.carry_m, columns.apex_m, columns.apex_time_s,
                   columns.flight_time_s, columns.landing_angle_deg, columns.landing_speed_mps, columns.landing_spin_rpm)
        rest = columns.rest
        rests = zip(*(a.tolist() for a in (rest.x_m, rest.y_m, rest.total_m, rest.roll_m, rest.bounces,
                                           rest.ground_time_s)), strict=True)
        rolled = columns.rolled.tolist()
        row = np.cumsum(columns.rolled) - 1
        results: list[ShotFlight | FlightError] = []
        for i, ((xi, yi, c, h, th, tf, a, v, w), r) in enumerate(zip(zip(*(a.tolist() for a in numbers)), rests)):
            if i in columns.errors:
                results.append(FlightError(columns.errors[i]))
                continue
            states = None if history is None else self._shot_states(history, flight, i)
            shot_rest = None
            if rolled[i]:
                shot_rest = Rest(*r)
                states = None if states is None else _through_rest(states, phase, int(row[i]), tf)
            flown = ShotFlight(xi, yi, c, xi, h, th, tf, a, v, w, states, shot_rest)
            results.append(flown if self._states_finite(states) else FlightError(NON_FINITE))
        return results

    def fly_columns(
        self,
        launches: Sequence[Launch] | np.ndarray,
        conditions: Sequence[Conditions] | Conditions = STANDARD,
        grounds: Sequence[GroundSpec | None] | GroundSpec | None = None,
    ) -> BatchFlights:
        """`fly_batch` without the per-shot objects: its numbers as arrays over the shots (launches an [N, 5] array
        or a sequence of Launch), for callers that want columns (`golfflight sweep`)."""
        return self._batch(launches, conditions, False, grounds)[0]

    def _batch(
        self,
        launches: Sequence[Launch] | np.ndarray,
        conditions: Sequence[Conditions] | Conditions,
        keep_states: bool,
        grounds: Sequence[GroundSpec | None] | GroundSpec | None,
    ) -> tuple[BatchFlights, Flight, GroundPhase | None]:
        """The batch flight behind `fly_batch` and `fly_columns`: its columns, the integrator's flight and the ground
        phase of the rolled shots (in shot order)."""
        n = len(launches)
        per_shot = [conditions] * n if isinstance(conditions, Conditions) else list(conditions)
        shot_grounds = [grounds] * n if grounds is None or isinstance(grounds, GroundSpec) else list(grounds)
        if len(per_shot) != n or len(shot_grounds) != n:
            raise ValueError(f"{len(per_shot)} conditions and {len(shot_grounds)} grounds for {n} launches")
        heights = np.array([0.0 if g is None else g.elevation_m for g in shot_grounds])
        start = initial_state(*np.asarray(launches, dtype=float).reshape(n, 5).T)
        field = _batch_field(self._batch_model, per_shot)
        record = "states" if keep_states else "summary"
        flight = integrate(start, field, self.dt, self.max_steps, "euler", GroundPlane(heights), record)
        x, y, _ = flight.landing_position.T
        carry, angle, speed, spin = _summary(x, y, *flight.landing_velocity.T, *flight.landing_spin.T)
        numbers = (x, y, carry, flight.apex_m, flight.apex_time_s, flight.flight_time_s, angle, speed, spin)
        finite = np.isfinite(np.stack(numbers)).all(axis=0)
        errors = {}
        for i in np.flatnonzero(~(flight.landed & finite)).tolist():
            unlanded = not flight.landed[i]
            errors[i] = self._unlanded_message(float(flight.apex_m[i]), float(heights[i])) if unlanded else NON_FINITE
        rolled = flight.landed & finite & np.array([g is not None for g in shot_grounds])
        shots = np.flatnonzero(rolled)
        phase = self._ground_phase(flight, shots, [shot_grounds[i] for i in shots], keep_states)
        rest = _rests(phase, shots, n, carry)
        columns = BatchFlights(x, y, carry, x, flight.apex_m, flight.apex_time_s, flight.flight_time_s, angle, speed,
                               spin, rest, rolled, errors)
        return columns, flight, phase

    @staticmethod
    def _ground_phase(
        flight: Flight, shots: np.ndarray, grounds: list[GroundSpec], keep_states: bool
    ) -> GroundPhase | None:
        """The ground phase of the landed `shots` of a batch flight, each on its ground, in one batch."""
        if not shots.size:
            return None
        distinct = {id(g.surface): g.surface for g in grounds}
        surface = next(iter(distinct.values())) if len(distinct) == 1 else Surface.stack([g.surface for g in grounds])
        return ground_phase(
            flight.landing_position[shots],
            flight.landing_velocity[shots],
            flight.landing_spin[shots],
            surface,
            np.array([g.slope_deg for g in grounds]),
            np.array([g.slope_dir_deg for g in grounds]),
            keep_states,
        )

    def _shot_states(self, history: tuple[np.ndarray, np.ndarray], flight: Flight, shot: int) -> EulerStates:
        """One shot's states up to its landing, the interpolated landing last."""
        last = int(flight.last_step[shot])
        positions = np.vstack([history[0][: last + 1, shot], flight.landing_position[shot]])
        velocities = np.vstack([history[1][: last + 1, shot], flight.landing_velocity[shot]])
        times = np.append(np.round(self.dt * np.arange(last + 1), 9), flight.flight_time_s[shot])
        return EulerStates(times, positions, velocities)
