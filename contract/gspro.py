"""GSPro Open Connect v1 shot messages (fields in docs/service.md), as a launch-monitor connector sends them.

The protocol is not ours, so unknown fields are ignored (connectors add their own) and known ones are matched in any
letter case (connectors in the wild send `APIVersion` and `Backspin`); the values we use are type- and range-checked
like every other launch (GSPRO_RANGES, quoted in the error message). The BallData of a heartbeat or of a message
that says it carries none is not read (connectors pad it with zeros). Speeds are mph, angles degrees (HLA + =
right), spins rpm. BackSpin and SideSpin are used only when TotalSpin is absent (or zero while they are not);
+ SideSpin curves the ball right. HTTP (`POST /v1/gspro`) and TCP (`service.open_connect`) answer through the bay
runtime (`service.runtime`, with `shot_request`, `shot_reply` and `invalid_message`).
"""

from __future__ import annotations

from typing import Annotated

from golfflight.contract.bay import BayConditions, flown_in
from golfflight.contract.flying import fly_request
from golfflight.contract.inputs import spin_from_components
from golfflight.contract.refusals import answer_to, describe_errors, encodable
from golfflight.contract.requests import BALL_SPEED_MPH, SIDE_SPIN_RPM, ShotRequest, total_spin_rpm
from golfflight.contract.results import ShotResult
from golfflight.errors import FlightError, InputError
from golfflight.flight import limits
from golfflight.flight.constants import MPH_TO_MPS
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.limits import Range
from pydantic import BaseModel, ConfigDict, Field, WithJsonSchema, field_validator, model_validator


def _spelled_as_fields(data, fields) -> dict:
    """`data` with each key that matches a field but for letter case renamed to the field (unknown keys kept); a
    field given twice with different values is refused."""
    if not isinstance(data, dict) or all(key in fields for key in data):
        return data  # every key spelled as its field already: nothing to rename (a message as connectors send it)
    names = {name.casefold(): name for name in fields}
    renamed: dict = {}
    for key, value in data.items():
        name = names.get(key.casefold(), key) if isinstance(key, str) else key
        if name in renamed and renamed[name] != value:
            raise InputError(f"{name} is given twice, in two spellings, with different values")
        renamed[name] = value
    return renamed


class _Lenient(BaseModel):
    """Ignores unknown fields and the letter case of known ones; refuses non-finite numbers and values of the wrong
    JSON type."""

    model_config = ConfigDict(extra="ignore", allow_inf_nan=False, strict=True)

    @model_validator(mode="before")
    @classmethod
    def _any_case(cls, data):
        return _spelled_as_fields(data, cls.model_fields)


GSPRO_RANGES: dict[str, Range] = {
    "Speed": BALL_SPEED_MPH,
    "SpinAxis": limits.SPIN_AXIS_DEG,
    "TotalSpin": limits.SPIN_RPM,
    "BackSpin": limits.SPIN_RPM,
    "SideSpin": SIDE_SPIN_RPM,
    "HLA": limits.LAUNCH_DIRECTION_DEG,
    "VLA": limits.LAUNCH_ANGLE_DEG,
}
"""Allowed range of every BallData value used, by field name."""


def _in(name: str, description: str):
    bounds = GSPRO_RANGES[name]
    return Annotated[
        float | None, Field(ge=bounds.low, le=bounds.high, description=f"{description} ({bounds.describe()})")
    ]


class GSProBallData(_Lenient):
    Speed: _in("Speed", "ball speed, mph") = None
    SpinAxis: _in("SpinAxis", "spin axis, + = right") = None
    TotalSpin: _in("TotalSpin", "total spin, rpm") = None
    BackSpin: _in("BackSpin", "back spin, rpm") = None
    SideSpin: _in("SideSpin", "side spin, rpm, + = right") = None
    HLA: _in("HLA", "horizontal launch angle, + = right") = None
    VLA: _in("VLA", "vertical launch angle") = None
    CarryDistance: float | None = Field(None, description="the monitor's own carry; not used")


MAX_CLUB_DATA_FIELDS = 24
"""Most ClubData values kept for the screens (GSPro's ClubData has ten); longer text is cut to MAX_CLUB_TEXT."""
MAX_CLUB_TEXT = 40

ClubValue = float | int | str | bool | None
"""A ClubData value as the screens show it."""


def club_values(club_data: dict | None) -> dict[str, ClubValue] | None:
    """A connector's ClubData as the screens keep it: its plain values (numbers, text cut short and made writable as
    UTF-8, flags), at most MAX_CLUB_DATA_FIELDS of them; nested objects are left out. A lone surrogate (a JSON
    escape such as \\ud800) would otherwise reach the viewer's event, which cannot be written out."""
    if not club_data:
        return None
    kept: dict[str, ClubValue] = {}
    for key, value in club_data.items():
        if len(kept) == MAX_CLUB_DATA_FIELDS:
            break
        name = encodable(str(key)[:MAX_CLUB_TEXT])
        if isinstance(value, str):
            kept[name] = encodable(value[:MAX_CLUB_TEXT])
        elif value is None or isinstance(value, (bool, int, float)):
            kept[name] = value
    return kept or None


class GSProOptions(_Lenient):
    ContainsBallData: bool = True
    ContainsClubData: bool = False
    LaunchMonitorIsReady: bool | None = None
    LaunchMonitorBallDetected: bool | None = None
    IsHeartBeat: bool = False


UNITS = {"yards": "Yards", "meters": "Meters"}
"""GSPro Open Connect's `Units`, by their folded spelling."""

SHOT_NUMBER_MAX = 2**31 - 1
"""The largest ShotNumber: GSPro keeps it in a 32-bit signed integer."""


class GSProMessage(_Lenient):
    """One Open Connect v1 message (ClubData is kept for the bay's screens, as `club_values` makes it, and not used:
    the flight needs the ball only)."""

    DeviceID: str | None = None
    Units: str | None = None
    ShotNumber: int | None = Field(None, ge=0, le=SHOT_NUMBER_MAX)
    APIversion: str | None = None
    BallData: GSProBallData | None = None
    ClubData: Annotated[
        dict[str, ClubValue] | None,
        WithJsonSchema({"anyOf": [{"type": "object"}, {"type": "null"}], "description": "the club's numbers, any "
                        "values: plain ones are kept for the screens, nested ones left out (`club_values`)"},
                       mode="validation"),
    ] = None
    ShotDataOptions: GSProOptions = Field(default_factory=GSProOptions)

    @field_validator("ClubData", mode="before")
    @classmethod
    def _club_data_shown(cls, value):
        return club_values(value) if isinstance(value, dict) else value

    @field_validator("Units")
    @classmethod
    def _units_known(cls, value: str | None) -> str | None:
        """GSPro's two unit systems, in any letter case. They change no number read here (BallData is mph and
        degrees either way, as in GSPro) nor answered (the flight comes in yards and metres both); anything else is
        refused rather than ignored, as a connector sending it expects something that will not happen."""
        if value is not None and value.casefold() not in UNITS:
            raise InputError(f"must be {' or '.join(UNITS.values())}, GSPro Open Connect's two, in any letter case")
        return value

    @field_validator("ShotNumber", mode="before")
    @classmethod
    def _shot_number_in_range(cls, value):
        """Refuse a ShotNumber out of range with the range written out: a bound quoted the usual way
        (`flight.limits.limit_text`, four significant digits) would read "less than or equal to 2147000000"."""
        if isinstance(value, int) and not isinstance(value, bool) and not 0 <= value <= SHOT_NUMBER_MAX:
            raise InputError(f"Input should be a whole number from 0 to {SHOT_NUMBER_MAX}")
        return value

    @model_validator(mode="before")
    @classmethod
    def _ball_data_only_for_a_shot(cls, data):
        """Leave out the BallData of a heartbeat or of a message whose options say it carries none."""
        data = _spelled_as_fields(data, cls.model_fields)
        if not isinstance(data, dict):
            return data
        options = _spelled_as_fields(data.get("ShotDataOptions"), GSProOptions.model_fields)
        if not isinstance(options, dict):
            return data
        if options.get("IsHeartBeat") is True or options.get("ContainsBallData") is False:
            data = {key: value for key, value in data.items() if key != "BallData"}
        return data

    @property
    def is_heartbeat(self) -> bool:
        return self.ShotDataOptions.IsHeartBeat


class GSProReply(BaseModel):
    """Open Connect's reply: Code 200 with the flight for a shot; 500 with a Message for an invalid message or a
    failed flight; 503 while the model loads. Over HTTP a heartbeat gets Code 200 and Code 500 comes with status
    422; over TCP a heartbeat gets no reply. The flight is the HTTP service's own result, so whatever it gains
    (the ground phase's total and roll) the reply carries too."""

    Code: int
    Message: str
    ShotNumber: int | None = None
    Flight: ShotResult | None = None


def launch_from_ball_data(ball: GSProBallData) -> Launch:
    """The SI launch of a message's BallData; InputError naming the field when one it needs is missing, or
    when BackSpin and SideSpin make a spin out of range."""
    missing = [name for name in ("Speed", "VLA") if getattr(ball, name) is None]
    uses_components = not ball.TotalSpin and (ball.BackSpin or ball.SideSpin)
    if ball.TotalSpin is None and ball.BackSpin is None:
        missing.append("TotalSpin (or BackSpin)")
    if missing:
        raise InputError(f"BallData is missing {', '.join(missing)}")
    if uses_components:
        total_spin_rpm(ball.BackSpin or 0.0, ball.SideSpin or 0.0)
        spin, axis = spin_from_components(ball.BackSpin or 0.0, ball.SideSpin or 0.0)
    else:
        spin, axis = ball.TotalSpin or 0.0, ball.SpinAxis or 0.0
    return Launch(ball.Speed * MPH_TO_MPS, ball.VLA, ball.HLA or 0.0, spin, axis)


def shot_number_of(data) -> int | None:
    """The ShotNumber of a message that failed validation, when it carries a valid one (any letter case), so that
    every refusal of a shot names the shot as a shot's reply does; None otherwise."""
    if not isinstance(data, dict):
        return None
    for key, value in data.items():
        if isinstance(key, str) and key.casefold() == "shotnumber":
            valid = isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= SHOT_NUMBER_MAX
            return value if valid else None
    return None


def invalid_message(errors: list) -> str:
    """The Message of Code 500 for a message that failed validation: each problem with its field, value and range."""
    return "; ".join(detail["message"] for detail in describe_errors(errors, GSPRO_RANGES))


def shot_request(message: GSProMessage) -> ShotRequest:
    """The /v1/shots request of a message's ball (launch only: Open Connect carries no conditions, the bay gives
    them); InputError naming the field when one it needs is missing (`launch_from_ball_data`). Built without re-validation: GSProBallData
    has checked every value against GSPRO_RANGES."""
    launch = launch_from_ball_data(message.BallData)
    return ShotRequest.model_construct(
        ball_speed_mps=launch.ball_speed_mps,
        launch_angle_deg=launch.launch_angle_deg,
        launch_direction_deg=launch.launch_direction_deg,
        spin_rpm=launch.spin_rpm,
        spin_axis_deg=launch.spin_axis_deg,
    )


def shot_reply(message: GSProMessage, result: ShotResult) -> GSProReply:
    """Code 200 with a shot's flight."""
    return GSProReply(Code=200, Message="shot received", ShotNumber=message.ShotNumber, Flight=result)


def failed_reply(message: GSProMessage, error: Exception) -> GSProReply:
    """The reply saying why the shot could not fly, its code from `contract.refusals.FAILURES` (500; 503 while the
    service cannot answer)."""
    return GSProReply(Code=answer_to(error).open_connect_code, Message=str(error), ShotNumber=message.ShotNumber)


def fly_message(engine: FlightEngine, message: GSProMessage, bay: BayConditions | None = None) -> GSProReply:
    """The reply to a message with BallData: Code 200 with its flight in the bay's conditions and saying what it flew
    in (`contract.bay.flown_in`; without a bay: standard air, calm, rolled to rest on a level fairway; with the
    putter selected, a putt if a putt can leave as it did), or Code 500 saying why it could not fly. Open Connect
    carries ball data only: its shots always fly in the bay's air, wind and ground. The served bay flies messages
    through `service.runtime`, which keeps the flight's states for its screens too."""
    try:
        request, echo = flown_in(shot_request(message), bay or BayConditions(), connector=True)
        result, _ = fly_request(engine, request, putt=echo.putt, flat=False)
    except (ValueError, FlightError) as error:
        return failed_reply(message, error)
    result.flown_in = echo
    return shot_reply(message, result)
