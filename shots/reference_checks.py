"""Checks of the reference world that nothing is fitted to: a drive at altitude and in a 10 mph wind, against the
rules of thumb stated below (altitude, wind). `golfflight calibrate-reference` renders them under the calibration
tables, so they always describe the committed parameters."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.flight.air import Air
from golfflight.flight.constants import MPH_TO_MPS, YARD_M
from golfflight.flight.physics import initial_state
from golfflight.flight.reference_aero import CALIBRATED, ReferenceParameters
from golfflight.flight.wind import CALM, Wind
from golfflight.shots.clubs import CLUBS
from golfflight.shots.markdown import signed, table
from golfflight.shots.reference_world import CALIBRATION_AIR, fly_reference

HIGH_ALTITUDE_M = 2377.0
"""7,800 ft, the altitude of the rule of thumb: a 282 yd drive at sea level flies about 306 yd there (apex −6 yd,
land angle −9°)."""
ALTITUDE_RULE = {"carry_yd": 24.0, "apex_yd": -6.0, "land_deg": -9.0}
"""The rule of thumb's changes at HIGH_ALTITUDE_M against sea level: carry and apex in yards, land angle in degrees."""

WIND_DRIVE = {"ball_speed_mps": 155.0 * MPH_TO_MPS, "launch_angle_deg": 12.0, "spin_rpm": 2800.0}
"""The drive of the wind rule of thumb (on a 250 yd drive a 10 mph headwind costs about 13 yd, a tailwind adds 9)."""
WIND_SPEED_MPS = 10.0 * MPH_TO_MPS
WIND_RULE_YD = {"headwind": -13.0, "tailwind": 9.0}
"""The wind rule of thumb's carry change (yd) of WIND_DRIVE in a WIND_SPEED_MPS headwind or tailwind."""
WIND_FROM_DEG = {"headwind": 0.0, "tailwind": 180.0, "crosswind from the right": 90.0}


@dataclass(frozen=True)
class Outcome:
    """Carry along the target line, side (+ right), apex and land angle of one flight, in yards and degrees."""

    carry_yd: float
    side_yd: float
    apex_yd: float
    land_deg: float


def _fly(launch: dict[str, float], air: Air, wind: Wind, params: ReferenceParameters) -> Outcome:
    state = initial_state(**{k: np.array([v]) for k, v in launch.items()})
    flight = fly_reference(state, air, wind, params=params)
    return Outcome(float(flight.landing_position[0, 1]) / YARD_M, float(flight.lateral_m[0]) / YARD_M,
                   float(flight.apex_m[0]) / YARD_M, float(flight.landing_angle_deg[0]))


def driver_launch() -> dict[str, float]:
    """The synthetic sessions' driver launch (`shots.clubs.CLUBS`), straight."""
    club = next(c for c in CLUBS if c.name == "Driver")
    return {"ball_speed_mps": club.ball_speed_mps, "launch_angle_deg": club.launch_angle_deg,
            "launch_direction_deg": 0.0, "spin_rpm": club.spin_rpm, "spin_axis_deg": 0.0}


def altitude_check(params: ReferenceParameters = CALIBRATED) -> tuple[Outcome, Outcome]:
    """The driver at sea level and at HIGH_ALTITUDE_M, both in CALIBRATION_AIR's temperature and humidity."""
    high = Air.from_conditions(temperature_c=25.0, altitude_m=HIGH_ALTITUDE_M, humidity_pct=50.0)
    return (_fly(driver_launch(), CALIBRATION_AIR, CALM, params), _fly(driver_launch(), high, CALM, params))


def wind_check(params: ReferenceParameters = CALIBRATED) -> tuple[Outcome, dict[tuple[str, str], Outcome]]:
    """The rule's drive calm, and in a 10 mph wind (at the 10 m station height) from each side, uniform and with
    the log profile over fairway grass."""
    launch = dict(WIND_DRIVE, launch_direction_deg=0.0, spin_axis_deg=0.0)
    calm = _fly(launch, CALIBRATION_AIR, CALM, params)
    windy = {(name, profile): _fly(launch, CALIBRATION_AIR, Wind(WIND_SPEED_MPS, from_deg, profile), params)
             for name, from_deg in WIND_FROM_DEG.items() for profile in ("uniform", "log")}
    return calm, windy


def render_checks_markdown(params: ReferenceParameters = CALIBRATED) -> list[str]:
    """Markdown tables of both checks."""
    sea, high = altitude_check(params)
    change = (high.carry_yd - sea.carry_yd, high.apex_yd - sea.apex_yd, high.land_deg - sea.land_deg)
    rule = (ALTITUDE_RULE["carry_yd"], ALTITUDE_RULE["apex_yd"], ALTITUDE_RULE["land_deg"])
    launch = driver_launch()
    out = ["", "### Other checks, not fitted: altitude and wind", "",
           (f"The synthetic driver launch ({launch['ball_speed_mps']:g} m/s, {launch['launch_angle_deg']:g}°, "
            f"{launch['spin_rpm']:g} rpm) at sea level and at {HIGH_ALTITUDE_M:,.0f} m (7,800 ft), both 25 °C, 50 % "
            "humidity:"), ""]
    out += table(["", "carry (yd)", "max height (yd)", "land angle (°)"], [
        ["sea level", f"{sea.carry_yd:.1f}", f"{sea.apex_yd:.1f}", f"{sea.land_deg:.1f}"],
        [f"{HIGH_ALTITUDE_M:,.0f} m", f"{high.carry_yd:.1f}", f"{high.apex_yd:.1f}", f"{high.land_deg:.1f}"],
        ["change", *(signed(c) for c in change)],
        ["rule (`ALTITUDE_RULE`: 282 → 306 yd)", *(signed(r) for r in rule)],
    ])
    calm, windy = wind_check(params)
    out += ["", (f"The wind rule's drive (155 mph, 12°, 2,800 rpm; calm carry {calm.carry_yd:.1f} yd) in a 10 mph "
                 "wind at 10 m, uniform or with the log profile over fairway grass (z0 = 2 cm):"), ""]
    rows = []
    for name in WIND_FROM_DEG:
        uniform, log = windy[(name, "uniform")], windy[(name, "log")]
        rows.append([name, signed(uniform.carry_yd - calm.carry_yd), signed(log.carry_yd - calm.carry_yd),
                     signed(uniform.side_yd), signed(log.side_yd),
                     signed(WIND_RULE_YD[name]) if name in WIND_RULE_YD else "–"])
    out += table(["wind", "carry change, uniform (yd)", "log profile (yd)", "side, uniform (yd)", "log profile (yd)",
                  "rule (`WIND_RULE_YD`, yd)"], rows)
    return out
