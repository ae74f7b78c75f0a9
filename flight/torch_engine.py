"""A bundle flown in torch, on a CPU or a GPU: `TorchEngine`, the engine's torch backend (`FlightEngine.from_bundle(...,
backend="torch")`): the served engine's batch path (`FlightEngine.fly_batch`) on torch tensors, for `golfflight
sweep --engine torch`. No training code: the flight core alone.

The coefficient network is the bundle's ONNX graph run by torch (`flight.torch_network`, checked against ONNX Runtime
on the bundle checker's probes), in float32 as the graph runs; the equations of motion are the flight core's
(`flight.physics`, through `rollout.euler_step`, the forward-Euler step `euler_rollout` repeats), in float32 or
float64. What the engine takes, this takes: every shot's air (density, and its kinematic
viscosity as the Reynolds scale of the network's inputs), its wind (uniform, or the log profile evaluated at the
ball's height each step) and its ground's elevation, down to the engine's maximum flight time. The landing and apex
are training's `hard_landing` and `apex`, which hold the integrator's rules (the state interpolated linearly to the
ground's plane between the two steps around the first downward crossing; the parabola through the highest state and
its neighbours), on heights measured from each shot's ground. A part's shots fly together; every LANDING_CHECK_STEPS
steps those that have come down are set aside once they are SET_ASIDE_SHARE of those flying (`Aloft`: a sweep's
shots land from one to ten seconds after the launch, and a part otherwise flies every shot for its longest flight),
the part stopping once every shot has come down; a shot never down by the maximum flight time, or whose figures are
not finite, fails with the engine's message (the batch is flown in parts that fit the device).

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
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import torch
from golfflight.errors import InputError
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.devices import resolve_device
from golfflight.flight.flyer import LAUNCH_WIDTH, Landings, Launch, air_inputs, landed_columns, load_flyer
from golfflight.flight.ground import GroundPhase, GroundSpec, Surface, elevations, ground_phase
from golfflight.flight.ground.phase import plane_normals, roll_to_rest
from golfflight.flight.outcomes import BatchFlights
from golfflight.flight.per_shot import PerShot
from golfflight.flight.physics import initial_state, reynolds_scale
from golfflight.flight.rollout import LANDING_CHECK_STEPS, Trajectory, apex, euler_step, hard_landing
from golfflight.flight.torch_network import network_from_bundle
from golfflight.flight.wind import log_profile_factor

DTYPES = {"float32": torch.float32, "float64": torch.float64}
"""The physics' precisions by name (the network always runs in float32, as the bundle's graph does)."""

CPU_PART_SHOTS = 4096
"""Shots flown at once on a CPU: about 30 MB of states at the engine's 200 steps in float32 (on the project's shared
2-core machine parts of 16,384 flew slower a shot than parts of 4,096: their states leave the caches)."""

DEVICE_MEMORY_SHARE = 0.5
"""Share of a GPU's free memory one part's states may take (the network's activations and the landing's gathers
need the rest)."""

STATE_COPIES = 3
"""Each part keeps every step's positions, velocities and spins ([steps + 1, N, 3] each)."""

WORKING_BYTES_PER_SHOT = 4096
"""A step's transient memory a shot, beside the kept states, as estimated: the network's two 256-wide and two
128-wide float32 activations (3 kB) and the equations' temporaries (`bench_gpu.py` measures the peak on a GPU)."""

STAGES = ("prepare", "flight", "ground")
"""A batch's stages, timed apart (`TorchEngine.seconds`): its launch states, air and grounds as arrays (CPU), its flight
to the landings back in NumPy (the device, transfers included), its figures and ground phase (the CPU, and the device
where the ground phase runs there)."""

SET_ASIDE_SHARE = 0.125
"""The share of a part's flying shots that must have come down before the rest fly on without them (each setting
aside gathers the rest's states and air: not worth it for a few)."""


@dataclass(frozen=True)
class ShotInputs:
    """A batch's shots in the equations' terms, NumPy [N] or [N,3] arrays: the launch state, each shot's air
    density, Reynolds scale, wind at its reference height and log profile (flag, reference height, roughness),
    and ground elevation."""

    position: np.ndarray
    velocity: np.ndarray
    spin: np.ndarray
    density: np.ndarray
    reynolds_scale: np.ndarray
    wind: np.ndarray
    log_profile: np.ndarray
    reference_height_m: np.ndarray
    roughness_m: np.ndarray
    ground_m: np.ndarray

    def part(self, start: int, stop: int) -> ShotInputs:
        """The shots start..stop-1."""
        return ShotInputs(*(getattr(self, name)[start:stop] for name in self.__dataclass_fields__))


@dataclass(frozen=True)
class Aloft:
    """The shots of a part the step still flies, as torch tensors on the device: their rows of the part (None: every
    row), their state, whether each has come down through its ground's plane, their air and ground, and their wind
    (`_wind`'s four)."""

    rows: torch.Tensor | None
    position: torch.Tensor
    velocity: torch.Tensor
    spin: torch.Tensor
    down: torch.Tensor
    density: torch.Tensor
    scale: torch.Tensor
    ground: torch.Tensor
    wind: tuple[torch.Tensor | None, ...]

    def step_inputs(self) -> tuple[torch.Tensor | None, ...]:
        """`flight_step`'s arguments after its coefficients and dt."""
        return (self.position, self.velocity, self.spin, self.down, self.density, self.scale, self.ground,
                *self.wind)

    def stepped(self, state: tuple[torch.Tensor, ...]) -> Aloft:
        """These shots with `flight_step`'s new position, velocity, spin and down."""
        position, velocity, spin, down = state
        return replace(self, position=position, velocity=velocity, spin=spin, down=down)

    def keep(self, states: list[torch.Tensor], step: int) -> None:
        """Write these shots' position, velocity and spin as the part's `step` ([steps + 1, N, 3] each); a shot set
        aside keeps the state it was set aside in, below its ground, so that the landing and apex read the same
        first crossing and highest state as if it had flown on."""
        for kept, now in zip(states, (self.position, self.velocity, self.spin), strict=True):
            if self.rows is None:
                kept[step] = now
            else:
                kept[step] = kept[step - 1]
                kept[step, self.rows] = now

    def still_up(self) -> Aloft:
        """The shots of these not yet down (waits for the device: which they are)."""
        up = torch.nonzero(self.down.logical_not()).squeeze(1)
        rows = up if self.rows is None else self.rows[up]
        wind = tuple(None if part is None else part[up] for part in self.wind)
        return Aloft(rows, self.position[up], self.velocity[up], self.spin[up], self.down[up], self.density[up],
                     self.scale[up], self.ground[up], wind)


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
        Euler step's kernels with torch.compile (`step`: `flight_step`, compiled or eager, once for any part's size);
        `ground_on_device` bounces and rolls the landings on the device (`roll_to_rest`; default: on a GPU) instead
        of NumPy's on the CPU; `set_aside_share` is the share of a part's flying shots that must be down before they
        are set aside (1: never, every shot flies to the part's last step). `devices.DeviceError` for a device this
        machine lacks, ValueError for a dtype it does not know or a share outside (0, 1]."""
        if dtype not in DTYPES:
            raise InputError(f"dtype {dtype!r}: choose from {', '.join(DTYPES)}")
        if not 0 < set_aside_share <= 1:
            raise InputError(f"set_aside_share {set_aside_share}: must be more than 0 and at most 1")
        self.device, self.dtype = resolve_device(device), DTYPES[dtype]
        self.flyer = load_flyer(bundle_dir)
        self.card, self.sha256 = self.flyer.card, self.flyer.card.onnx.sha256
        self.network, _ = network_from_bundle(self.flyer.bundle_dir, self.device)
        self.part_limit, self.parts_at_once, self.set_aside_share = part_shots, parts_at_once, set_aside_share
        self.ground_on_device = self.device.type == "cuda" if ground_on_device is None else ground_on_device
        self.seconds = dict.fromkeys(STAGES, 0.0)
        self._timing = threading.Lock()
        dt = self.flyer.dt_s

        def step(*state_and_air: torch.Tensor | None) -> tuple[torch.Tensor, ...]:
            return flight_step(self.coefficients, dt, *state_and_air)

        self.step = torch.compile(step, dynamic=True) if compile_step else step

    def coefficients(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        """C_L, C_D, C_M, C_Q [N,4] in the physics' dtype from the network run in float32, as the graph runs."""
        return self.network(v_rel.float(), omega.float()).to(v_rel.dtype)

    def part_shots(self) -> int:
        """Shots flown at once: `part_shots` if given, else what the device's free memory holds (a GPU: free to the
        driver, or held in torch's cache unused, so that the last part's cached blocks count), or CPU_PART_SHOTS."""
        if self.part_limit is not None:
            return self.part_limit
        if self.device.type == "cpu":
            return CPU_PART_SHOTS
        free, _ = torch.cuda.mem_get_info(self.device)
        free += torch.cuda.memory_reserved(self.device) - torch.cuda.memory_allocated(self.device)  # torch's own cache
        itemsize = torch.finfo(self.dtype).bits // 8
        per_shot = (self.flyer.max_steps + 1) * 3 * STATE_COPIES * itemsize + WORKING_BYTES_PER_SHOT
        return max(1024, int(free * DEVICE_MEMORY_SHARE / self.parts_at_once / per_shot))

    def fly_batch(
        self,
        launches: Sequence[Launch] | np.ndarray,
        conditions: Sequence[Conditions] | Conditions = STANDARD,
        grounds: Sequence[GroundSpec | None] | GroundSpec | None = None,
        keep_states: bool = False,
    ) -> BatchFlights:
        """Shots (an [N, LAUNCH_WIDTH] array or Launches), each in its conditions, down to its ground and rolled to
        rest there (grounds None: down to z = 0, the flight alone), as `FlightEngine.fly_batch` gives them, without
        states (InputError for `keep_states`: the sweep's engine keeps none). One Conditions or GroundSpec for every
        shot is spread without a Python step a shot (a benchmark's millions)."""
        if keep_states:
            raise InputError("keep_states: the torch engine keeps no states (FlightEngine.fly_batch does)")
        n = len(launches)
        if n == 0:
            raise InputError("no shots to fly")
        per_shot, shot_grounds = PerShot.of(conditions, n, "conditions"), PerShot.of(grounds, n, "grounds")
        started = time.perf_counter()
        inputs = self._inputs(np.asarray(launches, dtype=float).reshape(n, LAUNCH_WIDTH), per_shot, shot_grounds)
        prepared = self._spent("prepare", started)
        size = self.part_shots()
        parts = [self._fly_part(inputs.part(start, min(start + size, n))) for start in range(0, n, size)]
        landings = Landings(*(np.concatenate([getattr(p, name) for p in parts])
                              for name in Landings.__dataclass_fields__))
        flown = self._spent("flight", prepared)
        columns = self._columns(landings, shot_grounds)
        self._spent("ground", flown)
        return columns

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

    def _inputs(self, launches: np.ndarray, conditions: PerShot[Conditions],
                grounds: PerShot[GroundSpec | None]) -> ShotInputs:
        """The shots' launch states, air, wind and grounds as the engine's Flyer takes them (`air_inputs`, once for
        each distinct conditions)."""
        start = initial_state(*launches.T)
        air = PerShot([air_inputs(c) for c in conditions.objects], conditions.index)
        nominal = self.flyer.kinematic_viscosity_m2_s
        return ShotInputs(
            start.position, start.velocity, start.spin,
            density=air.column(lambda a: a.density_kg_m3),
            reynolds_scale=reynolds_scale(air.column(lambda a: a.kinematic_viscosity_m2_s), nominal),
            wind=air.column(lambda a: (a.wind_x_mps, a.wind_y_mps, 0.0)),
            log_profile=air.column(lambda a: a.log_profile, bool),
            reference_height_m=air.column(lambda a: a.reference_height_m),
            roughness_m=air.column(lambda a: a.roughness_m),
            ground_m=elevations(grounds),
        )

    @torch.no_grad()
    def _fly_part(self, shots: ShotInputs) -> Landings:
        """One part's flights on the device: forward Euler from the launch until every shot has come down through its
        ground's plane or the maximum flight time has passed (the shots down set aside as they land, `Aloft`), then
        training's landing and apex."""
        def tensor(array: np.ndarray) -> torch.Tensor:
            return torch.as_tensor(array, dtype=self.dtype, device=self.device)

        position, velocity, spin = tensor(shots.position), tensor(shots.velocity), tensor(shots.spin)
        density, scale, ground = tensor(shots.density), tensor(shots.reynolds_scale)[:, None], tensor(shots.ground_m)
        wind = _wind(tensor(shots.wind), torch.as_tensor(shots.log_profile, device=self.device),
                     tensor(shots.reference_height_m), tensor(shots.roughness_m))
        steps = self.flyer.max_steps
        states = [torch.empty((steps + 1, *position.shape), dtype=self.dtype, device=self.device) for _ in range(3)]
        for kept, now in zip(states, (position, velocity, spin), strict=True):
            kept[0] = now
        down = torch.zeros(len(position), dtype=torch.bool, device=self.device)
        aloft = Aloft(None, position, velocity, spin, down, density, scale, ground, wind)
        last = steps
        for step in range(1, steps + 1):
            aloft = aloft.stepped(self.step(*aloft.step_inputs()))
            aloft.keep(states, step)
            if step % LANDING_CHECK_STEPS == 0:
                up = int(aloft.down.logical_not().sum())
                if up == 0:
                    last = step
                    break
                if up <= len(aloft.down) * (1 - self.set_aside_share) and up > 1:  # (one row: compiled again)
                    aloft = aloft.still_up()
        positions = states[0][: last + 1]
        positions[:, :, 2] -= ground  # heights above each shot's ground: its plane is the landing's z = 0
        trajectory = Trajectory(positions, states[1][: last + 1], states[2][: last + 1], self.flyer.dt_s)
        landing, peak = hard_landing(trajectory), apex(trajectory)
        landing.position[:, 2] += ground

        def array(values: torch.Tensor) -> np.ndarray:
            return values.to(device="cpu", dtype=torch.float64).numpy()

        return Landings(
            landing.landed.cpu().numpy(), array(landing.position), array(landing.velocity), array(landing.spin),
            array(landing.time_s), array(peak.height_m + ground), array(peak.time_s),
        )

    def _columns(self, flight: Landings, grounds: PerShot[GroundSpec | None]) -> BatchFlights:
        """The batch's figures, errors and rests from its landings (`flight.flyer.landed_columns`, as the engine
        makes them), the landed shots with a ground bounced and rolled on the device or on the CPU."""
        roll = self._ground_on_device if self.ground_on_device else ground_phase
        return landed_columns(flight, grounds, self.flyer.unlanded_message, roll)[0]


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
        from golfflight.flight.engine import FlightEngine

        return FlightEngine.from_bundle(bundle_dir, "torch", self.device, dtype=self.dtype,
                                        parts_at_once=self.parts_at_once, compile_step=self.compile_step)


def _wind(at_reference: torch.Tensor, log_profile: torch.Tensor, reference_height_m: torch.Tensor,
          roughness_m: torch.Tensor) -> tuple[torch.Tensor | None, ...]:
    """A part's wind as `wind_at` takes it: (at_reference, log_profile, reference_height_m, roughness_m), None for
    what the part does not need (all four in calm air; the last three where no shot follows the log profile)."""
    if not bool(at_reference.any()):
        return None, None, None, None
    if not bool(log_profile.any()):
        return at_reference, None, None, None
    return at_reference, log_profile, reference_height_m, roughness_m


def wind_at(height_m: torch.Tensor, at_reference: torch.Tensor | None, log_profile: torch.Tensor | None,
            reference_height_m: torch.Tensor | None, roughness_m: torch.Tensor | None) -> torch.Tensor | None:
    """The air's velocity [N,3] at the balls' heights [N], as `flight.wind.Wind.velocity` gives it: the wind at its
    reference height, times the log profile's factor (`flight.wind.log_profile_factor`) for the shots that follow
    it; None in calm air."""
    if at_reference is None or log_profile is None:
        return at_reference
    factor = log_profile_factor(height_m, reference_height_m, roughness_m)
    return at_reference * torch.where(log_profile, factor, torch.ones_like(factor))[:, None]


def flight_step(coefficients, dt: float, position: torch.Tensor, velocity: torch.Tensor, spin: torch.Tensor,
                down: torch.Tensor, density: torch.Tensor, scale: torch.Tensor, ground: torch.Tensor,
                *wind: torch.Tensor | None) -> tuple[torch.Tensor, ...]:
    """One forward-Euler step of training's equations (`rollout.euler_step`) in each shot's air and wind
    (`wind_at`'s four), and whether each shot has come down through its ground's plane by its end (`down`, kept)."""
    moved, velocity, spin = euler_step(position, velocity, spin, coefficients, density, dt, scale,
                                       wind_at(position[:, 2], *wind))
    down = down | ((position[:, 2] > ground) & (moved[:, 2] <= ground))
    return moved, velocity, spin, down
