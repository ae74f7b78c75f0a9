"""A bundle flown in torch, on a CPU or a GPU: `TorchEngine`, the engine's torch backend (`FlightEngine.from_bundle(...,
backend="torch")`): the served engine's batch path (`FlightEngine.fly_batch`) on torch tensors, for `golfflight
sweep --engine torch`. No training code: the flight core alone.

The coefficient network is the bundle's ONNX graph run by torch (`flight.torch_network`, checked against ONNX Runtime
on the bundle checker's probes), in float32 as the graph runs; the flight is the flight core's own, on the device's
tensors: the equations (`flight.physics`), the vector field (`flight.field.BallInAir`), forward Euler and the
integrator (`flight.integrator.integrate`: its landing interpolated into the crossing step, its apex's parabola), in
float32 or float64. What the engine takes, this takes: every shot's air (`flight.conditions.batch_air`: density, and its
kinematic viscosity as the Reynolds scale of the network's inputs), its wind (uniform, or the log profile at the
ball's height each step) and its ground's elevation, down to the engine's maximum flight time. A part's shots fly
together; every LANDING_CHECK_STEPS steps those that have come down are set aside once they are SET_ASIDE_SHARE of
those flying (`flight.integrator.SetAside`: asking which shots are down waits for the device, so not every step; a
sweep's shots land from one to ten seconds after the launch), the part stopping once every shot has come down; a
shot never down by the maximum flight time, or whose figures are not finite, fails with the engine's message (the
batch is flown in parts that fit the device).

The ground phase (bounce and roll) of the landing states in float64 is the engine's own: on a GPU its formulas run on
the device (`flight.ground.phase.roll_to_rest` on tensors), on a CPU on NumPy's arrays (`flight.ground.ground_phase`).
`seconds` holds the time spent in each stage (`STAGES`: preparing a batch's launch states and air on the CPU, the
device's flight, the figures and ground phase), summed over the threads that fly batches on one engine at once (a
sweep's pieces in flight: `parts_at_once` share the device's memory). A part's size is `part_shots`. Nothing of the
serving install or the sweep package imports this module (`golfflight sweep --engine torch` and `--engine ray
--device` do, from the command line, and each Ray actor of the latter when it unpickles the `TorchEngineMaker` it is
sent).
"""

from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass
from functools import partial

import numpy as np
import torch
from golfflight.errors import InputError
from golfflight.flight.conditions import BatchAir
from golfflight.flight.devices import keep_freed_memory, resolve_device
from golfflight.flight.field import BallInAir
from golfflight.flight.flyer import landed_columns, load_flyer
from golfflight.flight.ground import GroundPhase, Surface, ground_phase
from golfflight.flight.ground.phase import plane_normals, roll_to_rest
from golfflight.flight.integrator import GroundPlane, SetAside, SummaryRecord, integrate
from golfflight.flight.outcomes import BatchFlights, Flight
from golfflight.flight.physics import State, reynolds_scale
from golfflight.flight.problem import FlightProblem
from golfflight.flight.rollout import LANDING_CHECK_STEPS, InAir, step_rule
from golfflight.flight.torch_network import network_from_bundle

DTYPES = {"float32": torch.float32, "float64": torch.float64}
"""The physics' precisions by name (the network always runs in float32, as the bundle's graph does)."""

CPU_PART_SHOTS = 4096
"""Shots flown at once on a CPU (on the project's shared 2-core machine parts of 16,384 flew slower a shot than parts
of 4,096 when each part kept every step's states; a part now keeps its current state and marks only)."""

DEVICE_MEMORY_SHARE = 0.5
"""Share of a GPU's free memory one part may take (the ground phase and torch's own blocks need the rest)."""

BYTES_PER_SHOT = 4096
"""A step's memory a shot, as estimated: the network's two 256-wide and two 128-wide float32 activations (3 kB), the
state, the integrator's marks and the equations' temporaries (`bench_gpu.py` measures the peak on a GPU)."""

STAGES = ("prepare", "flight", "ground")
"""A batch's stages, timed apart (`TorchEngine.seconds`): its launch states, air and grounds as arrays (CPU), its flight
to the landings back in NumPy (the device, transfers included), its figures and ground phase (the CPU, and the device
where the ground phase runs there)."""

SET_ASIDE_SHARE = 0.125
"""The share of a part's flying shots that must have come down before the rest fly on without them (each setting
aside gathers the rest's states and air: not worth it for a few)."""

LANDING_FIELDS = ("landed", "landing_position", "landing_velocity", "landing_spin", "flight_time_s", "apex_m",
                  "apex_time_s")
"""What a part's Flight brings back from the device: its landings and apexes."""


class TorchEngine:
    """A bundle's coefficient network on a torch device, flying batches as `FlightEngine.fly_batch` does
    (module docstring)."""

    def __init__(self, bundle_dir: str | os.PathLike, device: str = "cpu", dtype: str = "float32",
                 part_shots: int | None = None, parts_at_once: int = 1, compile_step: bool = False,
                 ground_on_device: bool | None = None, set_aside_share: float = SET_ASIDE_SHARE) -> None:
        """Load and verify the bundle (`flight.flyer.load_flyer`, the engine's checks: its step, maximum flight time,
        nominal air and error messages are this engine's) and rebuild its network in torch on `device`; `dtype`
        is the physics' precision; `part_shots` caps the shots flown at once (default: what the device's memory
        holds, shared by `parts_at_once` threads flying batches on this engine at once); `compile_step` fuses each
        Euler step's kernels with torch.compile (`rule`, compiled or eager, once for any part's size);
        `ground_on_device` bounces and rolls the landings on the device (`roll_to_rest`; default: on a GPU) instead
        of NumPy's on the CPU; `set_aside_share` is the share of a part's flying shots that must be down before they
        are set aside (1: never, every shot flies to the part's last step). `devices.DeviceError` for a device this
        machine lacks, InputError for a dtype it does not know or a share outside (0, 1]."""
        if dtype not in DTYPES:
            raise InputError(f"dtype {dtype!r}: choose from {', '.join(DTYPES)}")
        if not 0 < set_aside_share <= 1:
            raise InputError(f"set_aside_share {set_aside_share}: must be more than 0 and at most 1")
        self.device, self.dtype = resolve_device(device), DTYPES[dtype]
        if self.device.type == "cpu":
            keep_freed_memory()
        self.flyer = load_flyer(bundle_dir)
        self.card, self.sha256 = self.flyer.card, self.flyer.card.onnx.sha256
        self.network, _ = network_from_bundle(self.flyer.bundle_dir, self.device)
        self.part_limit, self.parts_at_once, self.set_aside_share = part_shots, parts_at_once, set_aside_share
        self.ground_on_device = self.device.type == "cuda" if ground_on_device is None else ground_on_device
        self.seconds = dict.fromkeys(STAGES, 0.0)
        self._timing = threading.Lock()
        self.rule = step_rule(compile_step)
        # a share of 1 never sets aside; one row left flying would be compiled again
        self.record = partial(SummaryRecord, set_aside=SetAside(LANDING_CHECK_STEPS, set_aside_share, keep_rows=2))

    def part_shots(self) -> int:
        """Shots flown at once: `part_shots` if given, else what the device's free memory holds (a GPU: free to the
        driver, or held in torch's cache unused, so that the last part's cached blocks count), or CPU_PART_SHOTS."""
        if self.part_limit is not None:
            return self.part_limit
        if self.device.type == "cpu":
            return CPU_PART_SHOTS
        free, _ = torch.cuda.mem_get_info(self.device)
        free += torch.cuda.memory_reserved(self.device) - torch.cuda.memory_allocated(self.device)  # torch's own cache
        return max(1024, int(free * DEVICE_MEMORY_SHARE / self.parts_at_once / BYTES_PER_SHOT))

    def fly_batch(self, problem: FlightProblem) -> BatchFlights:
        """`problem`'s shots down to their grounds and rolled to rest there (a shot with no GroundSpec: down to its
        plane, the flight alone), as `FlightEngine.fly_batch` gives them, without states (InputError for what this
        engine does not fly: `_check_torch`). One Conditions or GroundSpec for every shot is spread without a Python
        step a shot (a benchmark's millions)."""
        _check_torch(problem)
        n = len(problem)
        started = time.perf_counter()
        air, heights = problem.columns, np.zeros(n) + problem.heights  # [N], writable
        prepared = self._spent("prepare", started)
        size = self.part_shots()
        parts = [self._fly_part(problem.start.take(rows), air, heights, rows)
                 for rows in (slice(first, min(first + size, n)) for first in range(0, n, size))]
        flight = Flight(*(np.concatenate([getattr(part, name) for part in parts]) for name in LANDING_FIELDS))
        flown = self._spent("flight", prepared)
        columns = landed_columns(flight, problem.ground_specs, self.flyer.unlanded_message, self._roll())[0]
        self._spent("ground", flown)
        return columns

    def _roll(self):
        """The ground phase of a batch's landings: on the device (`roll_to_rest` on tensors) or NumPy's."""
        return self._ground_on_device if self.ground_on_device else ground_phase

    def _ground_on_device(self, position: np.ndarray, velocity: np.ndarray, spin: np.ndarray, surface: Surface,
                          slope_deg: np.ndarray, slope_dir_deg: np.ndarray) -> GroundPhase:
        """`flight.ground.ground_phase`'s rests of these landings (NumPy [N,3]) computed on the device in float64 by
        the same driver (`flight.ground.phase.roll_to_rest` on tensors) and brought back; the planes' normals are
        NumPy's."""
        def tensor(values: np.ndarray | float) -> torch.Tensor | float:
            if np.ndim(values) == 0:
                return float(values)
            return torch.as_tensor(values, dtype=torch.float64, device=self.device)

        normal = plane_normals(slope_deg, slope_dir_deg, len(position))
        on_device = Surface(*(tensor(getattr(surface, name)) for name in Surface.__dataclass_fields__))
        rest, hops, time_s = roll_to_rest(tensor(position), tensor(velocity), tensor(spin), tensor(normal), on_device)
        return GroundPhase(rest.cpu().numpy(), hops.cpu().numpy(), time_s.cpu().numpy())

    def _spent(self, stage: str, since: float) -> float:
        """Count the time since `since` to `stage` (from any thread); now."""
        now = time.perf_counter()
        with self._timing:
            self.seconds[stage] += now - since
        return now

    @torch.no_grad()
    def _fly_part(self, start: State, air: BatchAir, heights: np.ndarray, rows: slice) -> Flight:
        """One part's flights (the batch's `rows`) on the device through the flight core's integrator, from the
        launch until every shot has come down through its ground's plane or the maximum flight time has passed;
        their landings and apexes back in NumPy float64."""
        def tensor(array: np.ndarray) -> torch.Tensor:
            return torch.as_tensor(array, dtype=torch.bool if array.dtype == bool else self.dtype, device=self.device)

        scale = reynolds_scale(air.kinematic_viscosity_m2_s[rows], self.flyer.kinematic_viscosity_m2_s)
        network = InAir(self.network, tensor(scale[:, None]), run_in=torch.float32)  # the graph runs in float32
        field = BallInAir(network, tensor(air.density_kg_m3[rows]), air.wind.at_balls.take(rows).to(tensor))
        state = State(tensor(start.position), tensor(start.velocity), tensor(start.spin))
        flight = integrate(state, field, self.flyer.dt_s, self.flyer.max_steps, self.rule,
                           GroundPlane(tensor(heights[rows])), self.record)
        return Flight(*(getattr(flight, name).to(device="cpu", dtype=torch.float64 if name != "landed" else None)
                        .numpy() for name in LANDING_FIELDS))


def _check_torch(problem: FlightProblem) -> None:
    """InputError for a problem this engine does not fly: no shots, kept states (the sweep's engine keeps none),
    coefficient scales, an extra acceleration, a time of its own, or air without a density and viscosity a shot."""
    if len(problem) == 0:
        raise InputError("no shots to fly")
    air = problem.columns
    unflown = {
        "keep_states": problem.keeps(),
        "coefficient_scale": problem.coefficient_scale is not None,
        "correction": problem.correction is not None,
        "max_time_s": problem.max_time_s is not None,
        "nominal air (density or viscosity None)": air.density_kg_m3 is None or air.kinematic_viscosity_m2_s is None,
    }
    given = [name for name, present in unflown.items() if present]
    if given:
        raise InputError(f"problem: the torch engine does not fly {', '.join(given)} (FlightEngine.fly_batch does)")


@dataclass(frozen=True)
class TorchEngineMaker:
    """How a sweep's worker builds its own TorchEngine from a bundle path: `golfflight sweep --engine torch` in its
    process, and each Ray actor of `--engine ray --device ...` on its node, on the GPU Ray gave it ("cuda" is that
    actor's one visible GPU). Picklable, so that Ray sends it to the actors; `threads` sets torch's CPU threads first
    (an actor has one CPU); `parts_at_once` and `compile_step` as TorchEngine takes them."""

    device: str = "cpu"
    dtype: str = "float32"
    threads: int | None = None
    parts_at_once: int = 1
    compile_step: bool = False

    def __call__(self, bundle_dir: str | os.PathLike) -> TorchEngine:
        if self.threads is not None:
            torch.set_num_threads(self.threads)
        return TorchEngine(bundle_dir, device=self.device, dtype=self.dtype, parts_at_once=self.parts_at_once,
                           compile_step=self.compile_step)
