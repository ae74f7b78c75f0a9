"""Where a flight comes down and what it then bounces and rolls on: one shot's ground, as the engine takes it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.ground.surfaces import SURFACES, Surface, check_slope_held
from golfflight.flight.limits import SLOPE_DEG
from golfflight.flight.per_shot import PerShot


@dataclass(frozen=True)
class GroundSpec:
    """A plane `elevation_m` above the tee's ground (z = 0; the flight lands where it comes down through it), sloped
    by `slope_deg` towards `slope_dir_deg` around the landing point (`flight.ground.phase.plane_normals`), of
    `surface`. InputError for a slope outside SLOPE_DEG or not below the steepest the surface holds a ball still on
    (`check_slope_held`)."""

    surface: Surface = field(default_factory=lambda: SURFACES["fairway"])
    elevation_m: float = 0.0
    slope_deg: float = 0.0
    slope_dir_deg: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.slope_deg <= SLOPE_DEG.high:
            raise InputError(f"slope_deg: {self.slope_deg:g} is outside {SLOPE_DEG.describe()}")
        check_slope_held(self.slope_deg, self.surface.rolling_resistance)


LEVEL_FAIRWAY = GroundSpec()
"""The ground when none is given: the fitted fairway, level, at the tee's elevation."""


def batch_surface(grounds: PerShot[GroundSpec]) -> Surface:
    """The surface a batch of shots (each with a ground) bounces and rolls on: the one they share, or the parameters
    of each shot's surface as [N] arrays (`Surface.stack` of the distinct surfaces, spread by shot)."""
    surfaces = {id(g.surface): g.surface for g in grounds.objects}
    if len(surfaces) == 1:
        return next(iter(surfaces.values()))
    return Surface.stack([g.surface for g in grounds.objects]).take(grounds.index)


def elevations(grounds: PerShot[GroundSpec | None]) -> np.ndarray:
    """Each shot's ground elevation [N]: its plane's, or the tee's (0) for a shot flown alone (no ground)."""
    return grounds.column(lambda g: 0.0 if g is None else g.elevation_m)
