"""Air: pressure at altitude (US Standard Atmosphere 1976), moist-air density (Tetens 1930) and viscosity (Sutherland).

Every function works on floats or NumPy arrays alike, so a batch of shots can each have their own air.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from golfflight.flight import xp
from numpy.typing import ArrayLike

SEA_LEVEL_PRESSURE_PA = 101325.0
DRY_AIR_GAS_CONSTANT = 287.05  # J/(kg K)
WATER_VAPOUR_GAS_CONSTANT = 461.5  # J/(kg K)
ZERO_CELSIUS_K = 273.15
STANDARD_TEMPERATURE_C = 15.0
STANDARD_HUMIDITY_PCT = 0.0


def pressure_at_altitude(altitude_m: ArrayLike) -> np.ndarray:
    """Station pressure (Pa) of the US Standard Atmosphere at a height above sea level."""
    return SEA_LEVEL_PRESSURE_PA * (1.0 - 2.25577e-5 * np.asarray(altitude_m, dtype=float)) ** 5.255876


def altitude_for_pressure(pressure_pa: ArrayLike) -> np.ndarray:
    """Inverse of `pressure_at_altitude`: the standard-atmosphere height (m) of a station pressure."""
    ratio = np.asarray(pressure_pa, dtype=float) / SEA_LEVEL_PRESSURE_PA
    return (1.0 - ratio ** (1.0 / 5.255876)) / 2.25577e-5


def vapour_pressure(temperature_c: ArrayLike, humidity_pct: ArrayLike) -> np.ndarray:
    """Partial pressure of water vapour (Pa) from relative humidity (Tetens' saturation formula)."""
    t = np.asarray(temperature_c, dtype=float)
    saturation_hpa = 6.1078 * np.exp(17.27 * t / (t + 237.3))
    return np.asarray(humidity_pct, dtype=float) / 100.0 * saturation_hpa * 100.0


def air_density(temperature_c: ArrayLike, pressure_pa: ArrayLike, humidity_pct: ArrayLike = 0.0) -> np.ndarray:
    """Density (kg/m^3) of moist air: dry-air and vapour partial pressures as two ideal gases."""
    temperature_k = np.asarray(temperature_c, dtype=float) + ZERO_CELSIUS_K
    vapour = vapour_pressure(temperature_c, humidity_pct)
    dry = np.asarray(pressure_pa, dtype=float) - vapour
    return dry / (DRY_AIR_GAS_CONSTANT * temperature_k) + vapour / (WATER_VAPOUR_GAS_CONSTANT * temperature_k)


def dynamic_viscosity(temperature_c: ArrayLike) -> np.ndarray:
    """Dynamic viscosity of air (Pa s), Sutherland's law."""
    temperature_k = np.asarray(temperature_c, dtype=float) + ZERO_CELSIUS_K
    return 1.458e-6 * temperature_k**1.5 / (temperature_k + 110.4)


def _plain(value: np.ndarray) -> float | np.ndarray:
    """A float for one air (what the engine's per-step loop wants), the array itself for a batch."""
    return float(value) if np.ndim(value) == 0 else value


def _density_and_viscosity(
    temperature_c: ArrayLike, altitude_m: ArrayLike, humidity_pct: ArrayLike, pressure_pa: ArrayLike | None
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """Moist-air density at a station pressure (or, if none, an altitude) and mu(temperature) / density."""
    pressure = pressure_at_altitude(altitude_m) if pressure_pa is None else np.asarray(pressure_pa, dtype=float)
    density = air_density(temperature_c, pressure, humidity_pct)
    return _plain(density), _plain(dynamic_viscosity(temperature_c) / density)


_one_air = lru_cache(maxsize=1024)(_density_and_viscosity)
"""The same for one air of plain numbers, cached because a stream of shots mostly shares a few airs."""


@dataclass(frozen=True)
class Air:
    """The air a shot flies through: its density and its kinematic viscosity (for Reynolds numbers), floats for one
    air or arrays for a batch. The only air type: requests, conditions and data sets all build one of these."""

    density_kg_m3: float | np.ndarray
    kinematic_viscosity_m2_s: float | np.ndarray

    @classmethod
    def from_conditions(
        cls,
        temperature_c: ArrayLike = STANDARD_TEMPERATURE_C,
        altitude_m: ArrayLike = 0.0,
        humidity_pct: ArrayLike = STANDARD_HUMIDITY_PCT,
        pressure_pa: ArrayLike | None = None,
    ) -> Air:
        """Air at a temperature, humidity and either a station pressure or (if none given) an altitude."""
        given = (temperature_c, altitude_m, humidity_pct) + (() if pressure_pa is None else (pressure_pa,))
        one = all(xp.is_number(value) for value in given)
        formulas = _one_air if one else _density_and_viscosity
        return cls(*formulas(temperature_c, altitude_m, humidity_pct, pressure_pa))

    @classmethod
    def from_density(cls, density_kg_m3: ArrayLike, temperature_c: ArrayLike = STANDARD_TEMPERATURE_C) -> Air:
        """Air of a given density; its viscosity is still Sutherland's at the temperature (ICAO 15 degC unless
        given), so a density alone moves the dynamic pressure and the Reynolds number as thinner air would."""
        density = density_kg_m3 if xp.is_number(density_kg_m3) else np.asarray(density_kg_m3, dtype=float)
        return cls(density, _plain(dynamic_viscosity(temperature_c) / density))

    @classmethod
    def standard(cls) -> Air:
        """ICAO standard air: 15 degC, sea level, dry (rho = 1.225 kg/m^3). The density models are trained at."""
        return cls.from_conditions(STANDARD_TEMPERATURE_C, 0.0, STANDARD_HUMIDITY_PCT)
