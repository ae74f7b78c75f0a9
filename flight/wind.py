"""Wind: speed and the direction it blows FROM, uniform or with a logarithmic profile over height.

Direction convention (degrees, clockwise seen from behind the golfer looking at the target):
0 = from the target (headwind), 90 = from the right, 180 = from behind (tailwind), 270 = from the left.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np
from golfflight.flight import xp
from numpy.typing import ArrayLike

STATION_HEIGHT_M = 10.0
"""Weather stations report wind at 10 m."""

FAIRWAY_ROUGHNESS_M = 0.02
"""Aerodynamic roughness length z0 of mown grass (0.01-0.03 m)."""


def wind_vector(speed_mps: ArrayLike, from_deg: ArrayLike) -> np.ndarray:
    """Horizontal velocity of the air ([..., 3], m/s, x right, y to the target) for a wind blowing FROM a direction."""
    theta = np.radians(np.asarray(from_deg, dtype=float))
    speed = np.asarray(speed_mps, dtype=float)
    return np.stack([-speed * np.sin(theta), -speed * np.cos(theta), np.zeros_like(speed * theta)], axis=-1)


def log_profile_factor(height_m, reference_height_m, roughness_m):
    """V(h)/V(h_ref) of the logarithmic wind profile; zero at and below the roughness length. Floats (the one-shot
    engine calls this every step), NumPy arrays or torch tensors (`flight.xp`)."""
    height = xp.maximum(height_m, roughness_m)
    return xp.log(height / roughness_m) / xp.log(reference_height_m / roughness_m)


def uniform_equivalent_factor(heights_m: np.ndarray, reference_height_m: float, roughness_m: float) -> float:
    """Log-profile speed at the ball over the stated speed, averaged over each flight's time aloft and then over
    the flights ([T, N] heights at equal time steps, NaN once landed): a uniform wind of this factor x the stated
    speed moves these flights about as the profile does."""
    aloft = np.isfinite(heights_m)
    factor = np.where(aloft, log_profile_factor(np.nan_to_num(heights_m), reference_height_m, roughness_m), 0.0)
    per_flight = factor.sum(axis=0) / np.maximum(aloft.sum(axis=0), 1)
    return float(np.mean(per_flight[aloft.any(axis=0)]))


@dataclass(frozen=True)
class Wind:
    """A steady wind. Every field may instead be an array with one value per shot of a batch (`profile` an array
    of "uniform"/"log"), so each shot of one batch can have its own wind."""

    speed_mps: float | np.ndarray = 0.0
    from_deg: float | np.ndarray = 0.0
    profile: Literal["uniform", "log"] | np.ndarray = "uniform"
    reference_height_m: float | np.ndarray = STATION_HEIGHT_M
    roughness_m: float | np.ndarray = FAIRWAY_ROUGHNESS_M

    @classmethod
    def from_components(cls, x_mps: ArrayLike, y_mps: ArrayLike, **profile) -> Wind:
        """The wind whose air moves at (x, y) m/s at the reference height (x right, y to the target)."""
        x, y = np.asarray(x_mps, dtype=float), np.asarray(y_mps, dtype=float)
        return cls(np.hypot(x, y), np.degrees(np.arctan2(-x, -y)) % 360.0, **profile)

    @cached_property
    def at_reference(self) -> np.ndarray:
        """Air velocity at the reference height ([..., 3]); worked out once, the integrators ask every step."""
        return wind_vector(self.speed_mps, self.from_deg)

    @cached_property
    def is_log(self) -> np.ndarray:
        """Which shots' wind follows the log profile (a boolean, or one per shot)."""
        return np.asarray(self.profile) == "log"

    @cached_property
    def at_balls(self) -> WindAtBalls:
        """This wind as the equations read it at every step."""
        log = None if not self.is_log.any() else True if self.is_log.all() else self.is_log
        return WindAtBalls(self.at_reference, log, self.reference_height_m, self.roughness_m, self.is_calm)

    def velocity(self, height_m: np.ndarray) -> np.ndarray:
        """Air velocity [N, 3] at the balls' heights [N]."""
        return np.broadcast_to(self.at_balls.velocity(height_m), np.shape(height_m) + (3,))

    @cached_property
    def is_calm(self) -> bool:
        """True when there is no wind anywhere in the batch."""
        return not np.any(np.asarray(self.speed_mps) != 0.0)

    def take(self, index: np.ndarray) -> Wind:
        """The wind of some of the shots (itself when it is the same for every shot)."""
        fields = (self.speed_mps, self.from_deg, self.profile, self.reference_height_m, self.roughness_m)
        if all(np.ndim(f) == 0 for f in fields):
            return self
        return Wind(*(f if np.ndim(f) == 0 else np.asarray(f)[index] for f in fields))


@dataclass(frozen=True)
class WindAtBalls:
    """A batch's wind as the equations read it at every step, NumPy or torch (`flight.xp`): the air's velocity at
    the reference height ([N,3], or [3] shared), which balls follow the log profile (flags [N], True for every
    ball, None for none) and the profile's reference height and roughness (a float or [N])."""

    at_reference: np.ndarray
    log: np.ndarray | bool | None = None
    reference_height_m: float | np.ndarray = STATION_HEIGHT_M
    roughness_m: float | np.ndarray = FAIRWAY_ROUGHNESS_M
    is_calm: bool = False

    def velocity(self, height_m):
        """Air velocity at the balls' heights [N]: [N,3], or the shared [3] of a uniform wind."""
        if self.log is None:
            return self.at_reference
        factor = log_profile_factor(height_m, self.reference_height_m, self.roughness_m)
        return self.at_reference * xp.where(self.log, factor, 1.0)[..., None]

    def take(self, index) -> WindAtBalls:
        """The wind of some of the balls."""
        at_reference = self.at_reference[index] if self.at_reference.ndim == 2 else self.at_reference
        log, height, roughness = (xp.rows(v, index) for v in (self.log, self.reference_height_m, self.roughness_m))
        return WindAtBalls(at_reference, log, height, roughness, self.is_calm)

    def to(self, convert) -> WindAtBalls:
        """The same wind with its arrays made another kind by `convert` (a device's tensors)."""
        at_reference, log, height, roughness = (
            convert(v) if xp.is_array(v) else v
            for v in (self.at_reference, self.log, self.reference_height_m, self.roughness_m)
        )
        return WindAtBalls(at_reference, log, height, roughness, self.is_calm)


CALM = Wind()
