"""The conditions a shot flies in (air and wind), as the engine needs them, and the normalized reference.

Requests describe air the way people know it (temperature, altitude or station pressure, humidity) or give a
density outright; `flight.air.Air` turns that into the two numbers the equations use: the density (dynamic
pressure) and the kinematic viscosity (Reynolds number, `flight.physics.reynolds_scale`). Anything
left out takes the ICAO standard value (15 degC, sea level, dry: 1.225 kg/m^3), the air the models were trained
in, so a request without conditions reproduces the training simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

from golfflight.flight.air import Air
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
