"""What a shot request may say: pydantic request models (SI inside, imperial only in fields named for it).

Every number is range-checked against `flight.limits` (NaN and infinity refused), types are strict (no "55" for
55), unknown fields are refused, and each launch quantity comes in exactly one form: ball_speed_mps or
ball_speed_mph; spin_rpm (+ spin_axis_deg) or back_spin_rpm (+ side_spin_rpm). The one-form rules are also written
into the OpenAPI schema (oneOf / not), so a schema-driven client or fuzzer builds the requests the service takes.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from golfflight.contract.clubs import ClubName
from golfflight.errors import InputError
from golfflight.flight import limits
from golfflight.flight.conditions import NORMALIZED_HUMIDITY_PCT, NORMALIZED_TEMPERATURE_C
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS
from golfflight.flight.ground import SURFACES, check_slope_held, surface
from golfflight.flight.limits import Range
from pydantic import BaseModel, ConfigDict, Field, model_validator

MAX_BATCH_SHOTS = 10_000
"""Most shots one POST /v1/shots/batch may carry."""

MAX_BATCH_TRAJECTORIES = 100
"""Most shots of one batch that may ask for a trajectory (each can be 20,000 points at 1 kHz)."""

BALL_SPEED_MPH = Range(limits.BALL_SPEED_MPS.low / MPH_TO_MPS, limits.BALL_SPEED_MPS.high / MPH_TO_MPS, "mph")
SIDE_SPIN_RPM = Range(-limits.SPIN_RPM.high, limits.SPIN_RPM.high, "rpm")
WIND_SPEED_MPH = Range(limits.WIND_SPEED_MPS.low / MPH_TO_MPS, limits.WIND_SPEED_MPS.high / MPH_TO_MPS, "mph")
GROUND_ELEVATION_FT = Range(limits.GROUND_ELEVATION_M.low / FOOT_M, limits.GROUND_ELEVATION_M.high / FOOT_M, "ft")
TEMPERATURE_F = Range(limits.TEMPERATURE_C.low * 9 / 5 + 32, limits.TEMPERATURE_C.high * 9 / 5 + 32, "degF")
ALTITUDE_FT = Range(limits.ALTITUDE_M.low / FOOT_M, limits.ALTITUDE_M.high / FOOT_M, "ft")

RANGES: dict[str, Range] = {
    "ball_speed_mps": limits.BALL_SPEED_MPS,
    "ball_speed_mph": BALL_SPEED_MPH,
    "launch_angle_deg": limits.LAUNCH_ANGLE_DEG,
    "launch_direction_deg": limits.LAUNCH_DIRECTION_DEG,
    "spin_rpm": limits.SPIN_RPM,
    "spin_axis_deg": limits.SPIN_AXIS_DEG,
    "back_spin_rpm": limits.SPIN_RPM,
    "side_spin_rpm": SIDE_SPIN_RPM,
    "temperature_c": limits.TEMPERATURE_C,
    "temperature_f": TEMPERATURE_F,
    "altitude_m": limits.ALTITUDE_M,
    "altitude_ft": ALTITUDE_FT,
    "pressure_hpa": limits.PRESSURE_HPA,
    "humidity_pct": limits.HUMIDITY_PCT,
    "density_kg_m3": limits.AIR_DENSITY_KG_M3,
    "speed_mps": limits.WIND_SPEED_MPS,
    "speed_mph": WIND_SPEED_MPH,
    "from_deg": limits.WIND_FROM_DEG,
    "reference_height_m": limits.WIND_REFERENCE_HEIGHT_M,
    "rate_hz": limits.TRAJECTORY_RATE_HZ,
    "stimp_ft": limits.STIMP_FT,
    "elevation_m": limits.GROUND_ELEVATION_M,
    "elevation_ft": GROUND_ELEVATION_FT,
    "slope_deg": limits.SLOPE_DEG,
    "slope_dir_deg": limits.SLOPE_DIR_DEG,
}
"""Allowed range of every numeric request field, by name (also quoted in 422 answers)."""


def _in(name: str, description: str, optional: bool = False):
    """A float field bounded by RANGES[name], its range quoted in the OpenAPI description."""
    bounds = RANGES[name]
    return Annotated[
        float | None if optional else float,
        Field(ge=bounds.low, le=bounds.high, description=f"{description} ({bounds.describe()})"),
    ]


class Strict(BaseModel):
    """Refuses unknown fields, non-finite numbers and values of the wrong JSON type."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)


def _given(*names: str) -> dict:
    """JSON Schema: every one of `names` is present and a number (null counts as absent, as in the models)."""
    return {"required": list(names), "properties": {name: {"type": "number"} for name in names}}


def _one_of(*forms: tuple[str, tuple[str, ...]]) -> dict:
    """JSON Schema: exactly one form is used; each form names its own field and the fields it excludes."""
    return {
        "oneOf": [
            {"required": [field], "properties": {field: {"type": "number"}, **{x: {"type": "null"} for x in excluded}}}
            for field, excluded in forms
        ]
    }


def _not_together(*pairs: tuple[str, str]) -> dict:
    """JSON Schema: no pair is given together."""
    return {"not": {"anyOf": [_given(*pair) for pair in pairs]}}


def total_spin_rpm(back_spin_rpm: float, side_spin_rpm: float) -> float:
    """The spin that back and side spin make; InputError naming `spin_rpm`, the total (whole rpm) and its range when
    it is over `flight.limits.SPIN_RPM`: the one check of a request, a GSPro message and `golfflight fly`."""
    total = math.hypot(back_spin_rpm, side_spin_rpm)
    if total > limits.SPIN_RPM.high:
        raise InputError("back and side spin make a total over the range", field="spin_rpm", value=round(total),
                         allowed=limits.SPIN_RPM.describe())
    return total


def _exactly_one(model: BaseModel, quantity: str, *names: str) -> None:
    given = [name for name in names if getattr(model, name) is not None]
    if len(given) != 1:
        found = ", ".join(given) if given else "none"
        raise InputError(f"{quantity}: give exactly one of {' or '.join(names)} (got {found})")


def _at_most_one(model: BaseModel, quantity: str, *names: str) -> str | None:
    """The one of `names` that `model` gives, or None when it gives none; InputError naming both when it gives two."""
    given = [name for name in names if getattr(model, name) is not None]
    if len(given) > 1:
        raise InputError(f"{quantity}: give {' or '.join(given)}, not both")
    return given[0] if given else None


TEMPERATURE_FIELDS = ("temperature_c", "temperature_f")
ALTITUDE_FIELDS = ("altitude_m", "altitude_ft")
WEATHER_FIELDS = (*TEMPERATURE_FIELDS, *ALTITUDE_FIELDS, "pressure_hpa", "humidity_pct")
"""The weather values an explicit density replaces, every unit form of each."""


class AirRequest(Strict):
    """The air: weather values (altitude or station pressure) or an explicit density; omitted = ICAO standard. The
    temperature in at most one form, temperature_c or temperature_f, and the altitude in at most one, altitude_m or
    altitude_ft."""

    model_config = ConfigDict(
        json_schema_extra=_not_together(
            TEMPERATURE_FIELDS,
            ALTITUDE_FIELDS,
            *((altitude, "pressure_hpa") for altitude in ALTITUDE_FIELDS),
            *(("density_kg_m3", w) for w in WEATHER_FIELDS),
        )
    )

    temperature_c: _in("temperature_c", "air temperature", True) = None
    temperature_f: _in("temperature_f", "air temperature, instead of temperature_c", True) = None
    altitude_m: _in("altitude_m", "height above sea level, standard atmosphere", True) = None
    altitude_ft: _in("altitude_ft", "height above sea level, standard atmosphere, instead of altitude_m", True) = None
    pressure_hpa: _in("pressure_hpa", "station pressure (not reduced to sea level)", True) = None
    humidity_pct: _in("humidity_pct", "relative humidity", True) = None
    density_kg_m3: _in("density_kg_m3", "air density, instead of the weather values", True) = None

    @model_validator(mode="after")
    def _one_source(self) -> AirRequest:
        _at_most_one(self, "air temperature", *TEMPERATURE_FIELDS)
        altitude = _at_most_one(self, "altitude", *ALTITUDE_FIELDS)
        if altitude is not None and self.pressure_hpa is not None:
            raise InputError(f"air: give {altitude} or pressure_hpa, not both")
        weather = [n for n in WEATHER_FIELDS if getattr(self, n) is not None]
        if self.density_kg_m3 is not None and weather:
            raise InputError(f"air: density_kg_m3 replaces the weather values; drop {', '.join(weather)}")
        return self


class ReferenceAir(Strict):
    """Reference air of the normalized flight (calm); omitted fields take TrackMan's 25 degC, sea level. SI only
    (no temperature_f or altitude_ft, unlike AirRequest): a replay's reference air is a published standard, not a
    reading in the units at hand."""

    model_config = ConfigDict(json_schema_extra=_not_together(("altitude_m", "pressure_hpa")))

    temperature_c: _in("temperature_c", "air temperature") = NORMALIZED_TEMPERATURE_C
    altitude_m: _in("altitude_m", "height above sea level", True) = None
    pressure_hpa: _in("pressure_hpa", "station pressure", True) = None
    humidity_pct: _in("humidity_pct", "relative humidity") = NORMALIZED_HUMIDITY_PCT

    @model_validator(mode="after")
    def _one_source(self) -> ReferenceAir:
        if self.altitude_m is not None and self.pressure_hpa is not None:
            raise InputError("normalized: give altitude_m or pressure_hpa, not both")
        return self


class WindRequest(Strict):
    """A steady wind, by the direction it blows FROM: 0 = headwind, 90 = from the right, 180 = tailwind; its speed in
    exactly one form, speed_mps or speed_mph."""

    model_config = ConfigDict(
        json_schema_extra=_one_of(("speed_mps", ("speed_mph",)), ("speed_mph", ("speed_mps",)))
    )

    speed_mps: _in("speed_mps", "wind speed at the reference height", True) = None
    speed_mph: _in("speed_mph", "wind speed at the reference height, instead of speed_mps", True) = None
    from_deg: _in("from_deg", "direction the wind blows from, clockwise seen from behind the golfer") = 0.0
    profile: Literal["uniform", "log"] = Field(
        "uniform", description="uniform: the same at every height; log: V(h) = V_ref ln(h/z0)/ln(h_ref/z0), z0 = 2 cm"
    )
    reference_height_m: _in("reference_height_m", "height the speed is measured at (log profile)") = 10.0

    @model_validator(mode="after")
    def _one_form(self) -> WindRequest:
        _exactly_one(self, "wind speed", "speed_mps", "speed_mph")
        return self


class TrajectoryRequest(Strict):
    """{} for the integrator's states, {"rate_hz": 60} for positions resampled at that rate."""

    rate_hz: _in("rate_hz", "resampling rate, positions from t = 0 to the landing", True) = None


SurfaceName = Literal[tuple(SURFACES)]


class GroundRequest(Strict):
    """The ground the ball comes down on, bounces and rolls to rest on (flight.ground, docs/ground.md); omitted =
    level fairway at the tee's elevation. Its elevation in at most one form, elevation_m or elevation_ft (neither:
    elevation_m 0, the tee's; with elevation_ft, elevation_m is None). A slope may be no steeper than the surface
    holds a ball still on."""

    model_config = ConfigDict(json_schema_extra=_not_together(("elevation_m", "elevation_ft")))

    surface: SurfaceName = Field("fairway", description=f"one of {', '.join(SURFACES)}")
    stimp_ft: _in("stimp_ft", "green speed, the stimpmeter reading; green only (default 10)", True) = None
    elevation_m: _in(
        "elevation_m", "landing ground above (+) or below (-) the tee's ground; the carry is there", True
    ) = 0.0
    elevation_ft: _in(
        "elevation_ft", "landing ground above (+) or below (-) the tee's ground, instead of elevation_m", True
    ) = None
    slope_deg: _in("slope_deg", "slope of the ground around the landing point") = 0.0
    slope_dir_deg: _in(
        "slope_dir_deg", "direction it falls towards, clockwise from the target line: 0 = away, 90 = to the right"
    ) = 0.0

    @model_validator(mode="before")
    @classmethod
    def _feet_replace_the_default(cls, data):
        """elevation_ft given without elevation_m: elevation_m takes no default (it is not 0, it is not given)."""
        if isinstance(data, dict) and data.get("elevation_ft") is not None and "elevation_m" not in data:
            return {**data, "elevation_m": None}
        return data

    @model_validator(mode="after")
    def _holds_a_ball(self) -> GroundRequest:
        if self.elevation_m is not None and self.elevation_ft is not None:
            raise InputError("ground elevation: give elevation_m or elevation_ft, not both")
        if self.stimp_ft is not None and self.surface != "green":
            raise InputError(f"stimp_ft: a green's reading; surface {self.surface!r} takes none")
        check_slope_held(self.slope_deg, surface(self.surface, self.stimp_ft).rolling_resistance, self.surface)
        return self


class ShotRequest(Strict):
    """One launch, its conditions, and what to return besides the flight. Back and side spin together may not
    exceed the total spin range."""

    model_config = ConfigDict(
        json_schema_extra={
            "allOf": [
                _one_of(("ball_speed_mps", ("ball_speed_mph",)), ("ball_speed_mph", ("ball_speed_mps",))),
                _one_of(
                    ("spin_rpm", ("back_spin_rpm", "side_spin_rpm")),
                    ("back_spin_rpm", ("spin_rpm", "spin_axis_deg")),
                ),
            ]
        }
    )

    ball_speed_mps: _in("ball_speed_mps", "ball speed", True) = None
    ball_speed_mph: _in("ball_speed_mph", "ball speed", True) = None
    launch_angle_deg: _in("launch_angle_deg", "vertical launch angle, + = up")
    launch_direction_deg: _in("launch_direction_deg", "horizontal launch angle, + = right") = 0.0
    spin_rpm: _in("spin_rpm", "total spin", True) = None
    spin_axis_deg: _in("spin_axis_deg", "spin axis tilt, + = right: the ball curves right; with spin_rpm", True) = None
    back_spin_rpm: _in("back_spin_rpm", "back spin, instead of spin_rpm", True) = None
    side_spin_rpm: _in("side_spin_rpm", "side spin, + = curves right; with back_spin_rpm", True) = None
    wind: WindRequest | None = None
    air: AirRequest | None = None
    normalized: bool | ReferenceAir = Field(
        False, description="true (or reference air): also return the flight in calm reference air (TrackMan's)"
    )
    trajectory: TrajectoryRequest | None = None
    ground: GroundRequest | None = None
    club: ClubName | None = Field(
        None, description="the club hit, if the shot is to count in its club's row of the bay's session summary (a "
        "shot that did not come from the bay's launch monitor counts in none without one); never changes the flight"
    )

    @model_validator(mode="after")
    def _one_form_each(self) -> ShotRequest:
        _exactly_one(self, "ball speed", "ball_speed_mps", "ball_speed_mph")
        _exactly_one(self, "spin", "spin_rpm", "back_spin_rpm")
        if self.spin_rpm is not None and self.side_spin_rpm is not None:
            raise InputError("spin: side_spin_rpm goes with back_spin_rpm; with spin_rpm give spin_axis_deg")
        if self.back_spin_rpm is not None and self.spin_axis_deg is not None:
            raise InputError("spin: spin_axis_deg goes with spin_rpm; with back_spin_rpm give side_spin_rpm")
        if self.back_spin_rpm is not None:
            total_spin_rpm(self.back_spin_rpm, self.side_spin_rpm or 0.0)
        return self


class BatchRequest(Strict):
    """Many shots, flown together; results come back in the same order."""

    shots: list[ShotRequest] = Field(
        min_length=1,
        max_length=MAX_BATCH_SHOTS,
        description=f"1 to {MAX_BATCH_SHOTS:,} shots, at most {MAX_BATCH_TRAJECTORIES} of them with a trajectory",
    )

    @model_validator(mode="after")
    def _few_trajectories(self) -> BatchRequest:
        asked = sum(shot.trajectory is not None for shot in self.shots)
        if asked > MAX_BATCH_TRAJECTORIES:
            raise InputError(
                f"shots: {asked} shots ask for a trajectory, at most {MAX_BATCH_TRAJECTORIES} may in one batch"
            )
        return self
