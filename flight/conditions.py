"""The conditions a shot flies in (air and wind), as the engine needs them, and the normalized reference.

Requests describe air the way people know it (temperature, altitude or station pressure, humidity) or give a
density outright; `AirConditions` turns that into the two numbers the equations use: the density (dynamic
pressure) and the kinematic viscosity (Reynolds number, `flight.physics.reynolds_scale`). Anything
left out takes the ICAO standard value (15 degC, sea level, dry: 1.225 kg/m^3), the air the models were trained
in, so a request without conditions reproduces the training simulator.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from golfflight.flight.air import air_density, dynamic_viscosity, pressure_at_altitude
from golfflight.flight.wind import CALM, Wind, wind_vector

STANDARD_TEMPERATURE_C = 15.0
STANDARD_HUMIDITY_PCT = 0.0


@dataclass(frozen=True)
class AirConditions:
    """Air from weather values (station pressure wins over altitude) or an explicit density."""

    temperature_c: float = STANDARD_TEMPERATURE_C
    altitude_m: float = 0.0
    pressure_hpa: float | None = None
    humidity_pct: float = STANDARD_HUMIDITY_PCT
    density: float | None = None

    @property
    def density_kg_m3(self) -> float:
        """Moist-air density (NOTES.md section 3), or the explicit density when one was given."""
        if self.density is not None:
            return self.density
        pressure_pa = pressure_at_altitude(self.altitude_m) if self.pressure_hpa is None else self.pressure_hpa * 100.0
        return float(air_density(self.temperature_c, pressure_pa, self.humidity_pct))

    @property
    def kinematic_viscosity_m2_s(self) -> float:
        """mu(temperature) / density: what sets a ball's Reynolds number at a given speed."""
        return float(dynamic_viscosity(self.temperature_c)) / self.density_kg_m3


@dataclass(frozen=True)
class Conditions:
    """Air and wind of one shot."""

    air: AirConditions = field(default_factory=AirConditions)
    wind: Wind = CALM

    @property
    def wind_at_reference_mps(self) -> tuple[float, float]:
        """Horizontal air velocity (x, y) at the wind's reference height (m/s)."""
        vx, vy, _ = wind_vector(self.wind.speed_mps, self.wind.from_deg).tolist()
        return vx, vy


STANDARD = Conditions()
"""ICAO standard air, calm: the conditions the models were trained in."""

NORMALIZED_REFERENCE = Conditions(AirConditions(temperature_c=25.0, altitude_m=0.0, humidity_pct=50.0))
"""TrackMan's normalized conditions (77 degF, sea level, calm air); 50 % humidity is our choice, as they publish none."""


def normalized(reference_air: AirConditions | None = None) -> Conditions:
    """The calm reference conditions a shot is replayed in for its normalized flight (TrackMan's by default)."""
    return NORMALIZED_REFERENCE if reference_air is None else Conditions(reference_air, CALM)
