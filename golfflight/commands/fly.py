"""`golfflight fly`: one shot, a club's typical launch or your own, through the served model (the bundle `serve` and
`simulate` load: `--model DIR`, $GOLFFLIGHT_MODEL, models/default) or, with `--reference`, the reference world.

The shot is checked by the HTTP contract's own request model (`contract.requests.ShotRequest`, ranges from
`flight.limits`) before anything flies, so a value out of range is refused with the API's message, naming the
option and the allowed range (exit 2, one line); the result has the fields of POST /v1/shots.
"""

from __future__ import annotations

import argparse
import json
import math
import re

from pydantic import ValidationError

from golfflight.commands import COMMANDS
from golfflight.contract.clubs import FLIES_AS, GSPRO_CLUBS, club_code
from golfflight.contract.figures import FIGURES, Figure
from golfflight.errors import InputError
from golfflight.flight.constants import MPH_TO_MPS
from golfflight.flight.limits import WIND_SPEED_MPS, Range
from golfflight.shots.clubs import CLUB_NAMES, ClubLaunch, club_launch

WIND_SPEED_MPH = Range(WIND_SPEED_MPS.low, math.floor(WIND_SPEED_MPS.high / MPH_TO_MPS * 10) / 10, "mph")
"""The request's wind range (`flight.limits.WIND_SPEED_MPS`, 0 to 30 m/s) in mph, for --wind-speed-mph: 0 to 67.1."""

FLAGS = {
    "ball_speed_mps": "--ball-speed-mps",
    "ball_speed_mph": "--ball-speed-mph",
    "launch_angle_deg": "--launch-angle-deg",
    "launch_direction_deg": "--launch-direction-deg",
    "spin_rpm": "--spin-rpm",
    "spin_axis_deg": "--spin-axis-deg",
    "back_spin_rpm": "--back-spin-rpm",
    "side_spin_rpm": "--side-spin-rpm",
    "air.temperature_c": "--temperature-c",
    "air.altitude_m": "--altitude-m",
    "air.pressure_hpa": "--pressure-hpa",
    "air.humidity_pct": "--humidity-pct",
    "wind.speed_mps": "--wind-speed-mps",
    "wind.from_deg": "--wind-from-deg",
    "wind_speed_mph": "--wind-speed-mph",
}
"""Request field -> the option that sets it, to name the option in a refusal."""

DECIMALS = {"m": 1, "s": 2, "deg": 1, "m/s": 1, "rpm": 0}
"""Decimals the table prints a figure with, by its unit (`contract.figures.Figure.unit`); a count prints whole."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "fly",
        help=COMMANDS["fly"].summary,
        description="One shot through the model `golfflight serve` flies (or, with --reference, the reference world); "
        "each launch value left out takes the club's tour-average launch. Values are checked against the API's "
        "ranges (flight/limits.py).",
    )
    parser.add_argument(
        "--club",
        default="Driver",
        help=f"start from this club's tour-average launch: {', '.join(CLUB_NAMES)} (any case), as typed: dr, 3w, "
        "7i, 7 iron, pw, ..., or a GSPro club code (DR, W3, H4, I7, PW, ...): the names the bay takes",
    )
    parser.add_argument(
        "--model", help="model bundle directory (default: as `golfflight serve`: $GOLFFLIGHT_MODEL, models/default)"
    )
    parser.add_argument("--reference", action="store_true", help="fly the reference world instead of the model")
    parser.add_argument("--ball-speed-mps", type=float)
    parser.add_argument("--ball-speed-mph", type=float, help="instead of --ball-speed-mps")
    parser.add_argument("--launch-angle-deg", type=float)
    parser.add_argument("--launch-direction-deg", type=float, help="+ = right of the target line (default 0)")
    parser.add_argument("--spin-rpm", type=float, help="total spin")
    parser.add_argument("--spin-axis-deg", type=float, help="with --spin-rpm: + = tilted right, the ball curves right")
    parser.add_argument("--back-spin-rpm", type=float, help="instead of --spin-rpm")
    parser.add_argument("--side-spin-rpm", type=float, help="with --back-spin-rpm: + = the ball curves right")
    parser.add_argument(
        "--temperature-c", type=float, help="default: ICAO standard air (15 degC, sea level), as the API"
    )
    parser.add_argument("--altitude-m", type=float)
    parser.add_argument("--pressure-hpa", type=float, help="station pressure, instead of --altitude-m")
    parser.add_argument("--humidity-pct", type=float)
    parser.add_argument("--wind-speed-mps", type=float)
    parser.add_argument("--wind-speed-mph", type=float, help="instead of --wind-speed-mps")
    parser.add_argument("--wind-from-deg", type=float, help="0 = headwind, 90 = from the right, 180 = tailwind")
    parser.add_argument("--json", action="store_true", help="print JSON (the request and the POST /v1/shots result)")
    parser.set_defaults(run=run)


def _one_of(args: argparse.Namespace, quantity: str, *names: str) -> None:
    given = [name for name in names if getattr(args, name) is not None]
    if len(given) > 1:
        flags = [f"--{name.replace('_', '-')}" for name in names]
        raise InputError(f"{quantity}: give {' or '.join(flags)}, not both")


def _with_flags(text: str) -> str:
    """A message with every request field it names replaced by the option that sets it."""
    by_name = {field.rsplit(".", 1)[-1]: flag for field, flag in FLAGS.items()}
    names = sorted(by_name, key=len, reverse=True)
    return re.sub(r"\b(" + "|".join(names) + r")\b", lambda m: by_name[m.group(1)], text)


def _in_request(shot: dict, field: str) -> bool:
    """Whether the request `shot` holds the dotted field `field` (`air.temperature_c`)."""
    for part in field.split("."):
        if not isinstance(shot, dict) or part not in shot:
            return False
        shot = shot[part]
    return True


def _refusal(errors: list[dict], shot: dict) -> str:
    """The API's 422 messages on one line (` | ` between them), each naming the option instead of the request
    field where the request `shot` holds that field (a value worked out of others, such as the spin that back and
    side spin make, keeps its field's name, as the API and Open Connect say it)."""
    problems = []
    for detail in errors:
        field, message = detail["field"], detail["message"]
        if field in FLAGS and message.startswith(f"{field}:"):
            problems.append(FLAGS[field] + message.removeprefix(field) if _in_request(shot, field) else message)
        elif field == "body" or detail["msg"].startswith(f"{field}:"):  # the message names what it is about
            problems.append(_with_flags(detail["msg"]))
        else:
            problems.append(_with_flags(message))
    return " | ".join(problems)


def wind_speed_mps(args: argparse.Namespace) -> float | None:
    """The wind speed in m/s from --wind-speed-mps or --wind-speed-mph (the latter checked as the API checks a
    field, against WIND_SPEED_MPH), or None when neither was given."""
    if args.wind_speed_mph is None:
        return args.wind_speed_mps
    from pydantic import Field, create_model

    from golfflight.contract.refusals import describe_errors
    from golfflight.contract.requests import Strict

    bounds = WIND_SPEED_MPH
    in_mph = create_model("WindInMph", __base__=Strict, wind_speed_mph=(float, Field(ge=bounds.low, le=bounds.high)))
    try:
        in_mph.model_validate({"wind_speed_mph": args.wind_speed_mph})
    except ValidationError as error:
        details = describe_errors(error.errors(), {"wind_speed_mph": bounds})
        refused = [{**detail, "field": "wind_speed_mph"} for detail in details]
        raise InputError(_refusal(refused, {"wind_speed_mph": args.wind_speed_mph})) from None
    return args.wind_speed_mph * MPH_TO_MPS


def club_named(text: str) -> ClubLaunch:
    """The tour-average launch `--club` starts from: the club's GSPro code (`contract.clubs.club_code`, the names
    every surface takes) and the launch that code flies as (`FLIES_AS`); InputError for an unknown name and for the
    putter, which has no flight to start from."""
    code = club_code(text)
    name = FLIES_AS[code]
    if name is None:
        raise InputError(f"--club {text!r}: the {GSPRO_CLUBS[code].lower()} has no tour-average launch to fly; give "
                         f"one of {', '.join(CLUB_NAMES)} or another club's name or GSPro code")
    return club_launch(name)


def request_of(args: argparse.Namespace) -> tuple[str, dict]:
    """(the club's canonical name, the POST /v1/shots request of the options): values left out take the club's
    launch; the air and wind are left out when no option sets them (ICAO standard air, calm, as the API)."""
    club = club_named(args.club)
    _one_of(args, "ball speed", "ball_speed_mps", "ball_speed_mph")
    _one_of(args, "spin", "spin_rpm", "back_spin_rpm")
    _one_of(args, "wind speed", "wind_speed_mps", "wind_speed_mph")
    shot: dict = {}
    if args.ball_speed_mph is not None:
        shot["ball_speed_mph"] = args.ball_speed_mph
    else:
        shot["ball_speed_mps"] = args.ball_speed_mps if args.ball_speed_mps is not None else club.ball_speed_mps
    shot["launch_angle_deg"] = args.launch_angle_deg if args.launch_angle_deg is not None else club.launch_angle_deg
    if args.launch_direction_deg is not None:
        shot["launch_direction_deg"] = args.launch_direction_deg
    if args.back_spin_rpm is not None or (args.spin_rpm is None and args.side_spin_rpm is not None):
        shot["back_spin_rpm"] = args.back_spin_rpm if args.back_spin_rpm is not None else club.spin_rpm
    else:
        shot["spin_rpm"] = args.spin_rpm if args.spin_rpm is not None else club.spin_rpm
    for name in ("spin_axis_deg", "side_spin_rpm"):
        if getattr(args, name) is not None:
            shot[name] = getattr(args, name)
    air = {
        name: getattr(args, name)
        for name in ("temperature_c", "altitude_m", "pressure_hpa", "humidity_pct")
        if getattr(args, name) is not None
    }
    if air:
        shot["air"] = air
    speed = wind_speed_mps(args)
    if speed is not None or args.wind_from_deg is not None:
        shot["wind"] = {"speed_mps": 0.0 if speed is None else speed}
        if args.wind_from_deg is not None:
            shot["wind"]["from_deg"] = args.wind_from_deg
    return club.name, shot


def checked(shot: dict):
    """The validated ShotRequest, or InputError with the API's messages naming the options."""
    from golfflight.contract.refusals import describe_errors
    from golfflight.contract.requests import ShotRequest

    try:
        return ShotRequest.model_validate(shot)
    except ValidationError as error:
        raise InputError(_refusal(describe_errors(error.errors()), shot)) from None


def fly_reference_shot(shot) -> dict:
    """A checked request flown by the reference world's Flyer (`shots.reference_world.reference_flyer`) in its air
    and wind and rolled to rest on the level fairway, as the engine flies a shot: the POST /v1/shots result fields."""
    from golfflight.contract.flying import flight_fields
    from golfflight.contract.inputs import conditions_of, launch_of
    from golfflight.errors import FlightError
    from golfflight.flight.ground import LEVEL_FAIRWAY
    from golfflight.flight.problem import FlightProblem
    from golfflight.shots.reference_world import reference_flyer

    problem = FlightProblem.of([launch_of(shot)], conditions_of(shot), LEVEL_FAIRWAY)
    flown = reference_flyer().fly_batch(problem).shots()[0]
    if isinstance(flown, FlightError):
        raise InputError(f"the reference world could not fly the shot: {flown}")
    fields = flight_fields(flown, None)
    fields["landing"], fields["rest"] = (point.model_dump() for point in (fields["landing"], fields["rest"]))
    return {key: value for key, value in fields.items() if value is not None}


def fly_model_shot(shot, model: str | None) -> tuple[dict, dict]:
    """A checked request flown by the served model as POST /v1/shots flies it: (the result, the model's identity)."""
    from golfflight.contract.flying import fly_request
    from golfflight.flight.bundle_location import model_dir
    from golfflight.errors import FlightError
    from golfflight.flight.engine import FlightEngine

    engine = FlightEngine(model_dir(model))
    try:
        result, _ = fly_request(engine, shot)
    except FlightError as error:
        raise InputError(str(error)) from None
    identity = {"bundle": str(engine.bundle_dir), "variant": engine.variant, "sha256": engine.sha256}
    return result.model_dump(exclude_none=True), identity


def table_row(figure: Figure, result: dict) -> str:
    """One figure of a result (POST /v1/shots' fields) as the table prints it: its words, its value in its unit, and
    its imperial twin's beside it (the result's own; nothing is converted here)."""
    if figure.kind is int:
        return f"  {figure.label:<18} {result[figure.name]:8d}"
    decimals = DECIMALS[figure.unit]
    row = f"  {figure.label:<18} {result[figure.name] + 0.0:8.{decimals}f} {figure.unit}"  # + 0.0: no -0.0
    if figure.twin is not None:
        row += f" {result[figure.twin] + 0.0:8.{decimals}f} {figure.twin.rsplit('_', 1)[1]}"
    return row


def run(args: argparse.Namespace) -> int:
    club, request = request_of(args)
    shot = checked(request)
    if args.reference:
        result, source = fly_reference_shot(shot), {"world": "reference"}
    else:
        result, source = fly_model_shot(shot, args.model)
    if args.json:
        print(json.dumps({"club": club, "model": source, "request": request, "flight": result}, indent=2))
        return 0
    flown_by = "the reference world" if args.reference else f"{source['variant']} model {source['bundle']}"
    launch = ", ".join(f"{key} {value:g}" for key, value in request.items() if isinstance(value, float))
    for part, values in request.items():
        if isinstance(values, dict):
            launch += f"; {part} " + ", ".join(f"{key} {value:g}" for key, value in values.items())
    print(f"{club} ({flown_by}): {launch}")
    for figure in FIGURES:
        if figure.point is None:
            print(table_row(figure, result))
    return 0
