"""The served engine: a bundle's `flight.flyer.Flyer` and its single-shot latency twin.

Both take a `flight.problem.FlightProblem`. A batch is the Flyer's (`fly_batch`: NumPy [N] arrays through
`flight.integrator`). A single shot (`fly`: each shot of a small problem in turn) runs on
plain Python floats with the network's inputs and output bound once to preallocated float32 buffers (IOBinding, one
thread): per-call overheads, not arithmetic, decide single-shot latency (docs/benchmarks.md). It is the same forward
Euler at the Flyer's step, fed v_rel and omega times the air's Reynolds scale, landing and peaking by the batch's
one rule (`flight.events`: asked only on a step that reaches the ground's height or ends a climb, so the loop pays
for it nothing per step) and failing at the same maximum flight time; tests/test_engine.py and
tests/test_landing_rule.py hold the paths to each other. It stays a loop of its own because flying one shot through
`flight.integrator.integrate` costs several times more (`benchmarks/bench_single_path.py`, docs/benchmarks.md).
"""

from __future__ import annotations

import math
import os
import threading
import time

import numpy as np
from golfflight.errors import FlightError, InputError
from golfflight.flight.bundle_check import open_session, session_options
from golfflight.flight.conditions import Conditions, air_inputs
from golfflight.flight.flyer import BATCH_THREADS, MAX_FLIGHT_TIME_S, NON_FINITE, Flyer, load_flyer
from golfflight.flight.ground import GroundSpec, ground_phase_one, putt_phase
from golfflight.flight.events import came_down, crossing_fraction, parabola_apex, rose_above
from golfflight.flight.outcomes import BatchFlights, EulerStates, Rest, ShotFlight, landing_figures
from golfflight.flight.per_shot import PerShot
from golfflight.flight.physics import State, euler_step, reynolds_scale
from golfflight.flight.problem import FlightProblem, Launch
from golfflight.flight.wind import log_profile_factor
from golfflight.weights_schema.model_card import ModelCard

__all__ = [
    "BATCH_THREADS",
    "MAX_FLIGHT_TIME_S",
    "BatchFlights",
    "EulerStates",
    "FlightEngine",
    "FlightProblem",
    "Launch",
    "Rest",
    "ShotFlight",
]


BEFORE_LAUNCH = (math.nan,) * 9
"""The single shot's state before its launch: none, so the launch state is never taken for a top it rose into."""


class FlightEngine:
    """A loaded model bundle (its `Flyer`) and the two ways to fly shots through it: `fly` (one, on floats) and
    `fly_batch` (many, the Flyer's: columns, `.shots()` one ShotFlight a shot)."""

    def __init__(self, bundle_dir: str | os.PathLike, batch_threads: int = BATCH_THREADS):
        """Load and verify a bundle (`flight.flyer.load_flyer`: card, ball, hash, graph interface, finite
        coefficients on a probe set: BundleError otherwise), then warm both paths up."""
        started = time.perf_counter()
        self.flyer: Flyer = load_flyer(bundle_dir, batch_threads)
        self.bundle_dir = self.flyer.bundle_dir
        self.card: ModelCard = self.flyer.card
        self.dt = self.flyer.dt_s
        self.t_sim = self.card.physics.t_sim_s
        self.nominal_viscosity = self.flyer.kinematic_viscosity_m2_s
        velocity_name, spin_name = (spec.name for spec in self.card.onnx.inputs)
        self._single_session = open_session(self.flyer.model.onnx_path, session_options(1))
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
        self.fly(FlightProblem.of([Launch(60.0, 12.0, 0.0, 3000.0, 0.0)]))  # first runs allocate inside ORT
        self.fly_batch(FlightProblem.of([Launch(60.0, 12.0, 0.0, 3000.0, 0.0)] * 8))
        self.load_seconds = time.perf_counter() - started

    @property
    def max_steps(self) -> int:
        """Steps to the maximum flight time, the Flyer's: both paths fail a shot still in the air after them."""
        return self.flyer.max_steps

    @property
    def variant(self) -> str:
        return self.card.variant

    @classmethod
    def from_bundle(cls, bundle_dir: str | os.PathLike, backend: str = "onnx", device: str = "cpu", **options):
        """The engine of a bundle on a backend: "onnx", ONNX Runtime on the CPU (this class: the served engine, its
        single shot and its batches), or "torch" on `device` ("cpu", "cuda", "cuda:N": `flight.torch_engine`'s
        TorchEngine, which flies batches as `fly_batch` does; torch is imported here only, so the serving install
        stays torch-free). `options` go to the engine's constructor. InputError for another backend, or a device
        with ONNX Runtime."""
        if backend == "onnx":
            if device != "cpu":
                raise InputError(f"device {device!r}: the onnx backend runs on the cpu; a GPU takes backend='torch'")
            return cls(bundle_dir, **options)
        if backend == "torch":
            from golfflight.flight.torch_engine import TorchEngine

            return TorchEngine(bundle_dir, device=device, **options)
        raise InputError(f"backend {backend!r}: choose onnx or torch")

    @property
    def sha256(self) -> str:
        """SHA-256 of the ONNX graph (checked against the card at load)."""
        return self.card.onnx.sha256

    def fly(self, problem: FlightProblem) -> list[ShotFlight]:
        """Each shot of `problem` on Python floats, down to its ground and rolled to rest there on floats too
        (`flight.ground.ground_phase_one`, which records the ground's path too where states are kept); a shot with
        no GroundSpec: the flight alone, down to z = 0 (InputError for what only a batch flies: `_check_single`).
        Raises FlightError for the first shot that has not landed by the Flyer's maximum flight time (or, from a
        broken model, any number of whose flight is not finite)."""
        _check_single(problem)
        grounds = problem.ground_specs
        return [self._fly_one(problem.start, shot, problem.air[shot], problem.keeps(shot), grounds[shot])
                for shot in range(len(problem))]

    def _fly_one(
        self, start: State, shot: int, conditions: Conditions, keep_states: bool, ground: GroundSpec | None
    ) -> ShotFlight:
        """Shot `shot` of a start state flown on floats (`fly`)."""
        x, y, z = start.position[shot].tolist()
        vx, vy, vz = start.velocity[shot].tolist()
        wx, wy, wz = start.spin[shot].tolist()
        air = air_inputs(conditions)
        density, wind_x, wind_y, log_wind = air.density_kg_m3, air.wind_x_mps, air.wind_y_mps, air.log_profile
        reference_height, roughness = air.reference_height_m, air.roughness_m
        k = reynolds_scale(air.kinematic_viscosity_m2_s, self.nominal_viscosity)
        air_x, air_y = wind_x, wind_y
        dt = self.dt
        height = 0.0 if ground is None else ground.elevation_m
        peak, peak_step, before_peak, after_peak = z, 0, math.nan, math.nan
        history = [(x, y, z, vx, vy, vz)] if keep_states else None
        velocity_in, spin_in, out = self._velocity_in[0], self._spin_in[0], self._coefficients_out[0]
        old = BEFORE_LAUNCH
        with self._single_lock:
            run, binding = self._single_session.run_with_iobinding, self._binding
            for step in range(1, self.max_steps + 1):
                if log_wind:
                    factor = log_profile_factor(z, reference_height, roughness)
                    air_x, air_y = wind_x * factor, wind_y * factor
                velocity_in[0], velocity_in[1], velocity_in[2] = (vx - air_x) * k, (vy - air_y) * k, vz * k
                spin_in[0], spin_in[1], spin_in[2] = wx * k, wy * k, wz * k
                run(binding)
                prior, old = old, (x, y, z, vx, vy, vz, wx, wy, wz)
                x, y, z, vx, vy, vz, wx, wy, wz = euler_step(*old, out.tolist(), density, air_x, air_y, dt)
                if old[5] <= 0.0 < prior[5] and rose_above(old[2], peak):  # old a top: rose into, not out of it
                    peak, peak_step, before_peak, after_peak = old[2], step - 1, prior[2], z
                if z <= height and came_down(old[2], z, height):
                    break
                if history is not None:
                    history.append((x, y, z, vx, vy, vz))
            else:
                raise FlightError(self.flyer.unlanded_message(peak, height))
        frac = crossing_fraction(old[2], z, height)
        land = [a + frac * (b - a) for a, b in zip(old, (x, y, z, vx, vy, vz, wx, wy, wz))]
        flight_time = (step - 1 + frac) * dt
        carry, angle, speed, spin = (float(v) for v in landing_figures(land[0], land[1], *land[3:]))
        states = None
        if history is not None:
            rows = np.array(history)
            states = EulerStates.to_landing(rows[:, :3], rows[:, 3:], land[:3], land[3:6], dt, flight_time)
        apex, apex_time = parabola_apex(before_peak, peak, after_peak, peak_step * dt, dt)
        numbers = (land[0], land[1], carry, apex, apex_time, flight_time, angle, speed, spin)
        if not (all(map(math.isfinite, numbers)) and (states is None or states.finite)):
            raise FlightError(NON_FINITE)
        rest = None
        if ground is not None:
            one = ground_phase_one(
                tuple(land[0:3]), tuple(land[3:6]), tuple(land[6:9]), ground.surface, ground.slope_deg,
                ground.slope_dir_deg, keep_path=states is not None,
            )
            rest = Rest.at(one.position[0], one.position[1], carry, one.bounces, one.time_s)
            if states is not None:
                states = states.followed_by(one.path, flight_time)
        return ShotFlight(
            landing_x_m=land[0], landing_y_m=land[1], carry_m=carry, lateral_m=land[0], apex_m=apex,
            apex_time_s=apex_time, flight_time_s=flight_time, landing_angle_deg=angle, landing_speed_mps=speed,
            landing_spin_rpm=spin, states=states, rest=rest,
        )

    def putt(self, launch: Launch, ground: GroundSpec, keep_states: bool = False) -> ShotFlight:
        """Skid and roll one putt to rest on `ground` (`flight.ground.putt_phase`): the ball never leaves it, so the
        flight's figures are its start's (landing at the tee, carry, apex, times and landing angle 0, the launch's
        speed and spin). A putt is played on that ground itself, from the point below the tee: its states lie on the
        ground's plane through (0, 0, ground.elevation_m), so a screen draws it on the green it rolls on. InputError
        for a slope steeper than the surface holds a ball on."""
        rolled = putt_phase(*launch, ground.surface, ground.slope_deg, ground.slope_dir_deg, keep_states)
        states = None
        if rolled.path is not None:
            path = rolled.path
            positions = path.positions + np.array([0.0, 0.0, ground.elevation_m])
            states = EulerStates(times_s=path.times_s, positions=positions, velocities=path.velocities)
        x, y, _ = rolled.position
        return ShotFlight(
            landing_x_m=0.0, landing_y_m=0.0, carry_m=0.0, lateral_m=0.0, apex_m=0.0, apex_time_s=0.0,
            flight_time_s=0.0, landing_angle_deg=0.0, landing_speed_mps=launch.ball_speed_mps,
            landing_spin_rpm=launch.spin_rpm, states=states, rest=Rest.at(x, y, 0.0, 0, rolled.time_s),
        )

    def fly_batch(self, problem: FlightProblem) -> BatchFlights:
        """Many shots through the Flyer (`Flyer.fly_batch`): their figures, rests and errors as columns (one
        ShotFlight or FlightError a shot, in order, from `.shots()`)."""
        return self.flyer.fly_batch(problem)


def _check_single(problem: FlightProblem) -> None:
    """InputError unless the single shot can fly `problem`: one Conditions a shot and its grounds as GroundSpecs,
    no coefficient scales, extra acceleration or time of its own (a batch, `fly_batch`, flies those)."""
    if (isinstance(problem.air, PerShot) and isinstance(problem.grounds, PerShot) and problem.max_time_s is None
            and problem.coefficient_scale is None and problem.correction is None):
        return
    batch_only = {
        "air as columns": not isinstance(problem.air, PerShot),
        "grounds as heights": not isinstance(problem.grounds, PerShot),
        "coefficient_scale": problem.coefficient_scale is not None,
        "correction": problem.correction is not None,
        "max_time_s": problem.max_time_s is not None,
    }
    given = [name for name, present in batch_only.items() if present]
    if given:
        raise InputError(f"problem: the single shot does not fly {', '.join(given)}; fly_batch does")
