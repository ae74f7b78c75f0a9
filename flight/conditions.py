"""The conditions a shot flies in (air and wind), as the engine needs them, and the normalized reference.

Requests describe air the way people know it (temperature, altitude or station pressure, humidity) or give a
density outright; `flight.air.Air` turns that into the two numbers the equations use: the density (dynamic
pressure) and the kinematic viscosity (Reynolds number, `flight.physics.reynolds_scale`). Anything
left out takes the ICAO standard value (15 degC, sea level, dry: 1.225 kg/m^3), the air the models were trained
in, so a request without conditions reproduces the training simulator.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from golfflight.flight.air import Air
from golfflight.flight.per_shot import PerShot
from golfflight.flight.wind import CALM, Wind, wind_vector

STANDARD_AIR = Air.standard()
"""ICAO standard air (15 degC, sea level, dry): the air the models were trained in."""
NORMALIZED_TEMPERATURE_C = 25.0
"""TrackMan's normalized temperature (77 degF)."""
NORMALIZED_HUMIDITY_PCT = 50.0
"""The normalized flight's humidity: our choice, as TrackMan publish none."""


@dataclass(frozen=True)
class Conditions:
    """Air and wind of one shot."""

    air: Air = STANDARD_AIR
    wind: Wind = CALM

    @property
    def wind_at_reference_mps(self) -> tuple[float, float]:
        """Horizontal air velocity (x, y) at the wind's reference height (m/s)."""
        vx, vy, _ = wind_vector(self.wind.speed_mps, self.wind.from_deg).tolist()
        return vx, vy


STANDARD = Conditions()
"""ICAO standard air, calm: the conditions the models were trained in."""

NORMALIZED_REFERENCE = Conditions(Air.from_conditions(NORMALIZED_TEMPERATURE_C, 0.0, NORMALIZED_HUMIDITY_PCT))
"""TrackMan's normalized conditions (77 degF, sea level, calm air) with our 50 % humidity."""


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


class BatchAir(NamedTuple):
    """A batch's air as the equations take it: density and kinematic viscosity (a float or [N]; None: the flying
    model's nominal air), the wind of every shot (or air whose motion depends on the ball's height)."""

    density_kg_m3: np.ndarray | float | None
    kinematic_viscosity_m2_s: np.ndarray | float | None
    wind: Wind = CALM


NOMINAL_AIR = BatchAir(None, None)
"""The flying model's own air, calm."""


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
