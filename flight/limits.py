"""Physical ranges of every input quantity: one table that the shot records and the HTTP contract both enforce."""

from __future__ import annotations

from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal
from typing import NamedTuple

SIGNIFICANT_DIGITS = 4
"""Most significant digits a printed limit has: a limit converted from SI units (100 m/s is 223.69362920544023 mph)
reads 223.6, not its float's 17 digits."""


def limit_text(value: float, high: bool) -> str:
    """A range's end as every refusal and field description prints it: at most SIGNIFICANT_DIGITS significant digits,
    no exponent, rounded inwards (a high end down, a low end up) so that every number shown as allowed is accepted."""
    if value == 0:
        return "0"
    exact = Decimal(repr(float(value)))
    step = Decimal(1).scaleb(exact.adjusted() - SIGNIFICANT_DIGITS + 1)
    rounded = exact.quantize(step, rounding=ROUND_FLOOR if high else ROUND_CEILING)
    return f"{rounded.normalize():f}"


class Range(NamedTuple):
    """Inclusive bounds and the unit they are written in."""

    low: float
    high: float
    unit: str

    def describe(self) -> str:
        """The range as refusals and field descriptions quote it: "0.5 to 100 m/s" (ends by `limit_text`)."""
        return f"{limit_text(self.low, high=False)} to {limit_text(self.high, high=True)} {self.unit}".strip()


BALL_SPEED_MPS = Range(0.5, 100.0, "m/s")
LAUNCH_ANGLE_DEG = Range(-10.0, 80.0, "deg")
LAUNCH_DIRECTION_DEG = Range(-60.0, 60.0, "deg")
SPIN_RPM = Range(0.0, 15000.0, "rpm")
SPIN_AXIS_DEG = Range(-90.0, 90.0, "deg")

CARRY_X_M = Range(-300.0, 300.0, "m")
CARRY_Y_M = Range(-50.0, 450.0, "m")
APEX_M = Range(0.0, 120.0, "m")
FLIGHT_TIME_S = Range(0.0, 20.0, "s")
LANDING_ANGLE_DEG = Range(0.0, 90.0, "deg")

TEMPERATURE_C = Range(-30.0, 55.0, "degC")
ALTITUDE_M = Range(-500.0, 5000.0, "m")
PRESSURE_HPA = Range(500.0, 1100.0, "hPa")
HUMIDITY_PCT = Range(0.0, 100.0, "%")
WIND_SPEED_MPS = Range(0.0, 30.0, "m/s")
WIND_FROM_DEG = Range(0.0, 360.0, "deg")

AIR_DENSITY_KG_M3 = Range(0.5, 1.6, "kg/m^3")
WIND_REFERENCE_HEIGHT_M = Range(0.5, 100.0, "m")
TRAJECTORY_RATE_HZ = Range(1.0, 1000.0, "Hz")

GROUND_ELEVATION_M = Range(-100.0, 100.0, "m")
SLOPE_DEG = Range(0.0, 10.0, "deg")
"""The ground is an endless plane: on steeper ones a fast ball skips downhill and runs away (hundreds of metres),
which real hills end long before."""
SLOPE_DIR_DEG = Range(0.0, 360.0, "deg")
STIMP_FT = Range(4.0, 16.0, "ft")
