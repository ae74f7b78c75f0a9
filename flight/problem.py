"""What a flight needs, stated once: `FlightProblem`, and `Engine`, the one protocol every engine flies it by.

Every way in (a request, a sweep row, a discovery setup, an accuracy set's launches, the reference world's sessions)
states its shots as one FlightProblem, and every engine answers it: the served engine's single shot on floats
(`flight.engine.FlightEngine.fly`), the NumPy batch (`flight.flyer.Flyer`) and the torch engine
(`flight.torch_engine.TorchEngine`), so a new input or a new engine is one translation, not one per pair.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple, Protocol

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.conditions import NOMINAL_AIR, STANDARD, BatchAir, Conditions, batch_air
from golfflight.flight.ground import GroundSpec, elevations
from golfflight.flight.outcomes import BatchFlights
from golfflight.flight.per_shot import PerShot
from golfflight.flight.physics import ExtraAcceleration, State, initial_state


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

Grounds = PerShot[GroundSpec | None] | np.ndarray | float
"""Where the balls come down: one GroundSpec a shot (bounced and rolled to rest on it; None: the flight alone, down to
z = 0), or only the heights of the planes they are flown down to (no ground phase)."""


@dataclass(frozen=True)
class FlightProblem:
    """N balls to fly: their launch state, air and wind (one Conditions a shot, or the equations' columns), ground,
    per-ball coefficient scales [N, 3] and an extra acceleration where given, and what to keep: every state
    (`keep_states`, one flag for all or one a shot) and the time flown (`max_time_s`; None: the engine's maximum
    flight time)."""

    start: State
    air: PerShot[Conditions] | BatchAir = NOMINAL_AIR
    grounds: Grounds = 0.0
    coefficient_scale: np.ndarray | None = None
    correction: ExtraAcceleration | None = None
    keep_states: bool | np.ndarray = False
    max_time_s: float | None = None

    @classmethod
    def of(
        cls,
        launches: Sequence[Launch] | np.ndarray,
        conditions: PerShot[Conditions] | Sequence[Conditions] | Conditions = STANDARD,
        grounds: PerShot[GroundSpec | None] | Sequence[GroundSpec | None] | GroundSpec | None = None,
        keep_states: bool | np.ndarray = False,
    ) -> FlightProblem:
        """Shots from launch-monitor values (Launches, or an array [N, LAUNCH_WIDTH]), each in its conditions and
        on its ground (one for all, a sequence, or a PerShot). InputError where a sequence's length is not N."""
        array = np.asarray(launches, dtype=float)
        n = len(array)
        if array.size != n * LAUNCH_WIDTH:
            raise InputError(f"launches: an array [N, {LAUNCH_WIDTH}] of {', '.join(Launch._fields)}")
        start = initial_state(*array.reshape(n, LAUNCH_WIDTH).T)
        air, on = PerShot.of(conditions, n, "conditions"), PerShot.of(grounds, n, "grounds")
        return cls(start, air, on, keep_states=keep_states)

    def __len__(self) -> int:
        return len(self.start.position)

    @cached_property
    def columns(self) -> BatchAir:
        """The air and wind as the equations take them (`flight.conditions.batch_air` of the conditions, each distinct
        one read once)."""
        return batch_air(self.air) if isinstance(self.air, PerShot) else self.air

    @cached_property
    def heights(self) -> np.ndarray | float:
        """The height of each ball's ground plane (m)."""
        return elevations(self.grounds) if isinstance(self.grounds, PerShot) else self.grounds

    @cached_property
    def ground_specs(self) -> PerShot[GroundSpec | None]:
        """Each shot's GroundSpec, None for every shot flown down to a plane alone."""
        if isinstance(self.grounds, PerShot):
            return self.grounds
        return PerShot.of(None, len(self), "grounds")

    def keeps(self, shot: int | None = None) -> bool:
        """Whether `shot`'s states are kept (None: any shot's)."""
        if isinstance(self.keep_states, (bool, np.bool_)):
            return bool(self.keep_states)
        return bool(np.any(self.keep_states) if shot is None else self.keep_states[shot])


class Engine(Protocol):
    """What flies a FlightProblem to rest: the served engine (single shots on floats, `FlightEngine.fly`, beside this),
    the NumPy batch (`Flyer`) and the torch engine (`TorchEngine`); `.shots()` of the answer gives one ShotFlight or
    FlightError a shot, in order."""

    def fly_batch(self, problem: FlightProblem) -> BatchFlights:
        """Every shot of `problem` down to its ground and rolled to rest there, as columns."""
        ...
