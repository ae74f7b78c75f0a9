"""A shot request in the engine's terms: its launch, conditions and ground in SI, whichever unit forms it used."""

from __future__ import annotations

import math

from golfflight.contract.requests import AirRequest, GroundRequest, ReferenceAir, ShotRequest, WindRequest
from golfflight.flight.air import Air
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS
from golfflight.flight.ground import LEVEL_FAIRWAY, GroundSpec, surface
from golfflight.flight.problem import Launch
from golfflight.flight.wind import CALM, Wind


def spin_from_components(back_spin_rpm: float, side_spin_rpm: float) -> tuple[float, float]:
    """(total spin rpm, spin axis deg) from back and side spin; + side spin tilts the axis right (a fade)."""
    return math.hypot(back_spin_rpm, side_spin_rpm), math.degrees(math.atan2(side_spin_rpm, back_spin_rpm))


def launch_of(shot: ShotRequest) -> Launch:
    """The SI launch of a request, whichever unit form it used."""
    speed = shot.ball_speed_mps if shot.ball_speed_mps is not None else shot.ball_speed_mph * MPH_TO_MPS
    if shot.spin_rpm is not None:
        spin, axis = shot.spin_rpm, shot.spin_axis_deg or 0.0
    else:
        spin, axis = spin_from_components(shot.back_spin_rpm, shot.side_spin_rpm or 0.0)
    return Launch(speed, shot.launch_angle_deg, shot.launch_direction_deg, spin, axis)


def air_of(air: AirRequest | ReferenceAir | None) -> Air:
    """Engine air from a request's air, whichever unit forms it used (Fahrenheit and feet taken as Celsius and
    metres); omitted values take ICAO standard air (station pressure wins over altitude)."""
    if air is None:
        return STANDARD.air
    given = {name: value for name, value in air.model_dump().items() if value is not None}
    if "density_kg_m3" in given:
        return Air.from_density(given["density_kg_m3"])
    if "temperature_f" in given:
        given["temperature_c"] = (given.pop("temperature_f") - 32.0) * 5.0 / 9.0
    if "altitude_ft" in given:
        given["altitude_m"] = given.pop("altitude_ft") * FOOT_M
    pressure_hpa = given.pop("pressure_hpa", None)
    return Air.from_conditions(**given, pressure_pa=None if pressure_hpa is None else pressure_hpa * 100.0)


def wind_speed_mps(wind: WindRequest) -> float:
    """The SI wind speed of a request's (or a bay's) wind, whichever unit form it used."""
    return wind.speed_mps if wind.speed_mps is not None else wind.speed_mph * MPH_TO_MPS


def wind_of(wind: WindRequest | None) -> Wind:
    speed = 0.0 if wind is None else wind_speed_mps(wind)
    if speed == 0.0:
        return CALM
    return Wind(speed, wind.from_deg, wind.profile, wind.reference_height_m)


def conditions_from(air: AirRequest | None, wind: WindRequest | None) -> Conditions:
    """Engine conditions from a request's (or a bay's) air and wind; neither = standard air, calm."""
    if air is None and wind is None:
        return STANDARD
    return Conditions(air_of(air), wind_of(wind))


def conditions_of(shot: ShotRequest) -> Conditions:
    return conditions_from(shot.air, shot.wind)


def elevation_m(ground: GroundRequest | None) -> float:
    """The SI elevation of a request's (or a bay's) ground, whichever unit form it used; 0 (the tee's) if none."""
    if ground is None or (ground.elevation_m is None and ground.elevation_ft is None):
        return 0.0
    return ground.elevation_m if ground.elevation_m is not None else ground.elevation_ft * FOOT_M


def ground_of(ground: GroundRequest | None) -> GroundSpec:
    """The engine's ground from a request's; omitted = level fairway at the tee's elevation."""
    if ground is None:
        return LEVEL_FAIRWAY
    return GroundSpec(
        surface(ground.surface, ground.stimp_ft), elevation_m(ground), ground.slope_deg, ground.slope_dir_deg
    )


def reference_of(shot: ShotRequest) -> ReferenceAir | None:
    """The reference air of the normalized flight, or None when none was asked for."""
    if shot.normalized is False:
        return None
    return ReferenceAir() if shot.normalized is True else shot.normalized


def lands_off_the_flat(shot: ShotRequest) -> bool:
    """Whether the shot's ground lies above or below the tee's, so that its flat flight is returned beside it."""
    return elevation_m(shot.ground) != 0.0
