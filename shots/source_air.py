"""The air each real source was recorded in, where it is known: the level of a carry is set by the air it flew in,
so every source is trained and checked in its own air, never in a common guess.

Figures and their basis (`SourceAir.basis`):
- the PGA TOUR 2023 averages table: about 0.99 of ICAO standard density (what the PGA TOUR events behind TrackMan's
  2022-23 radar statistics average), written as ICAO air at 1 % lower pressure;
- tour events: the course's elevation from ShotLink's tee heights in the event's own pbp file (median `from_z`, feet)
  and the season's afternoon climate normals of the nearest city (NOAA 1991-2020: mean daily maximum, typical
  afternoon relative humidity), not the day's weather, which the files do not record;
- TrackMan's modelled indoor rows: TrackMan's normalisation air, 77 F at sea level (TrackMan's published normalize
  conditions; humidity not stated, 50 %);
- TrackMan's normalized 7-iron export: its stated 1,135 ft and 77 F (humidity not stated, 50 %).
Range sessions (the driver file's outdoor rows) recorded no air: they have none here, and training fits theirs.
"""

from __future__ import annotations

from dataclasses import dataclass

from golfflight.flight.air import Air, pressure_at_altitude
from golfflight.flight.constants import FOOT_M


@dataclass(frozen=True)
class SourceAir:
    """A source's air as record conditions (temperature, altitude or station pressure, humidity) and its basis."""

    temperature_c: float
    humidity_pct: float
    basis: str
    altitude_m: float | None = None
    pressure_hpa: float | None = None

    def air(self) -> Air:
        pressure = None if self.pressure_hpa is None else self.pressure_hpa * 100.0
        return Air.from_conditions(self.temperature_c, self.altitude_m or 0.0, self.humidity_pct, pressure)

    def record_conditions(self) -> dict[str, float]:
        """The `shots.records.ShotRecord` condition columns that reproduce this air."""
        conditions = {"temperature_c": self.temperature_c, "humidity_pct": self.humidity_pct}
        if self.pressure_hpa is not None:
            conditions["pressure_hpa"] = self.pressure_hpa
        else:
            conditions["altitude_m"] = self.altitude_m or 0.0
        return conditions

    def density_ratio(self) -> float:
        """Density over ICAO standard density."""
        return float(self.air().density_kg_m3 / Air.standard().density_kg_m3)


TOUR_TABLE_DENSITY_RATIO = 0.99

PGA_2023_TABLE = SourceAir(
    temperature_c=15.0, humidity_pct=0.0,
    pressure_hpa=float(pressure_at_altitude(0.0)) / 100.0 * TOUR_TABLE_DENSITY_RATIO,
    basis="0.99 of ICAO standard density (what the PGA TOUR events behind TrackMan's 2022-23 radar statistics "
          "average; docs/training_real.md)",
)
TOUR_CHAMPIONSHIP_2020 = SourceAir(
    temperature_c=29.0, humidity_pct=60.0, altitude_m=988.0 * FOOT_M,
    basis="East Lake GC, Atlanta: tee height 988 ft (median from_z of pbp_2020_060_688.csv); early September "
          "afternoon normals of Atlanta, 29 C and 60 % humidity",
)
PLAYERS_2020 = SourceAir(
    temperature_c=24.0, humidity_pct=65.0, altitude_m=7.0 * FOOT_M,
    basis="TPC Sawgrass, Ponte Vedra Beach: tee height 7 ft (median from_z of pbp_2020_011_011.csv); mid-March "
          "afternoon normals of Jacksonville, 24 C and 65 % humidity",
)
SENTRY_2022 = SourceAir(
    temperature_c=25.0, humidity_pct=70.0, altitude_m=211.0 * FOOT_M,
    basis="Kapalua Plantation Course, Maui: tee height 211 ft (median from_z of pbp_2021_016_656.csv); early "
          "January afternoon normals of west Maui, 25 C and 70 % humidity",
)
TRACKMAN_NORMALIZATION = SourceAir(
    temperature_c=25.0, humidity_pct=50.0, altitude_m=0.0,
    basis="TrackMan's normalisation air, 77 F at sea level (TrackMan's published normalize conditions; humidity "
          "not stated: 50 %)",
)
TRACKMAN_NORMALIZED_7IRON = SourceAir(
    temperature_c=25.0, humidity_pct=50.0, altitude_m=1135.0 * FOOT_M,
    basis="the export's stated normalisation, 1,135 ft and 77 F (humidity not stated: 50 %)",
)

KNOWN_AIR: dict[str, SourceAir] = {
    "pga-2023-table": PGA_2023_TABLE,
    "tour-championship-2020": TOUR_CHAMPIONSHIP_2020,
    "players-2020": PLAYERS_2020,
    "sentry-2022": SENTRY_2022,
    "trackman-model": TRACKMAN_NORMALIZATION,
    "trackman-normalized-7iron": TRACKMAN_NORMALIZED_7IRON,
}
"""Every source whose air is known, by source name."""

UNKNOWN_AIR_SOURCES = ("trackman-outdoor",)
"""Real sources that recorded no air (range sessions): their air is fitted with them (a density factor in the
reference world's calibration, a free mean in real-data training), so they cannot set the level of a carry."""
