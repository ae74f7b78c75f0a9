"""A steady uniform wind: a condition of the venue, fitted as its x, y components so calm has no singularity."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from golfflight.discovery.effects.base import Context, Effect, Hiding, Parameter, Reported, World, unchanged
from golfflight.discovery.effects.parts import plus_minus, uniform
from golfflight.discovery.schema import CorrectionSettings, WindSetting
from golfflight.discovery.simulator import Setup
from golfflight.flight.wind import STATION_HEIGHT_M, Wind, wind_vector


def wind_from_components(x_mps: float, y_mps: float) -> tuple[float, float]:
    """(speed, direction it blows FROM, degrees clockwise from the target line) of an air velocity (x, y)."""
    return float(np.hypot(x_mps, y_mps)), float(np.degrees(np.arctan2(-x_mps, -y_mps)) % 360.0)


def _apply(theta: np.ndarray, conditions: Setup) -> Setup:
    out = conditions.copy()
    out.wind_xy_mps = out.wind_xy_mps + theta[:, :2]
    return out


def _describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
    speed, from_deg = wind_from_components(theta[0], theta[1])
    if speed > 0:
        along = theta[:2] / speed
        across = np.array([-along[1], along[0]])
        speed_sd = float(np.sqrt(max(along @ covariance[:2, :2] @ along, 0.0)))
        direction_sd = float(np.degrees(np.sqrt(max(across @ covariance[:2, :2] @ across, 0.0)) / speed))
    else:
        speed_sd, direction_sd = float(np.sqrt(np.trace(covariance[:2, :2]) / 2)), 180.0
    return {"speed_mps": speed, "from_deg": from_deg}, {"speed_mps": speed_sd, "from_deg": min(direction_sd, 180.0)}


def _phrase(p: dict[str, float], u: dict[str, float]) -> str:
    direction = p["from_deg"]
    kind = (
        "headwind"
        if min(direction, 360 - direction) < 30
        else "tailwind"
        if abs(direction - 180) < 30
        else "wind from the right"
        if direction < 180
        else "wind from the left"
    )
    return (
        f"a steady {plus_minus(p['speed_mps'], u['speed_mps'], ' m/s')} wind from "
        f"{plus_minus(direction, u['from_deg'], '°')} (mostly a {kind})"
    )


def _setting(settings: CorrectionSettings, p: dict[str, float], context: Context, wind_factor: float | None) -> None:
    """The wind as the service's option; with `wind_factor` (the log profile's uniform-equivalent factor along the
    corrected flights) also as a 10 m station reading with the log profile."""
    settings.wind = WindSetting(speed_mps=p["speed_mps"], from_deg=p["from_deg"])
    if wind_factor:
        settings.wind_at_station = WindSetting(
            speed_mps=p["speed_mps"] / wind_factor,
            from_deg=p["from_deg"],
            profile="log",
            reference_height_m=STATION_HEIGHT_M,
        )


def _reference(p: dict[str, float], world: World) -> World:
    return replace(world, wind=Wind(p["speed_mps"], p["from_deg"], profile=world.wind_profile))


WIND = Effect(
    "wind",
    (
        Parameter("wind_x_mps", "m/s", 0.0, -20.0, 20.0, 3.0, 0.3),
        Parameter("wind_y_mps", "m/s", 0.0, -20.0, 20.0, 3.0, 0.3),
    ),
    _apply,
    _describe,
    "a steady uniform wind (the air moves at (x, y); reported as speed and the direction it blows from)",
    kind="venue",
    words="wind",
    phrase=_phrase,
    setting=_setting,
    from_reported=lambda p: wind_vector(p["speed_mps"], p["from_deg"])[:2],
    hiding=Hiding(uniform(speed_mps=(2.0, 7.0), from_deg=(0.0, 360.0)), unchanged, _reference, _apply),
)
