"""The flat, one-row-per-shot form of the flight contract: launch and condition columns in, result columns out.

`golfflight simulate` (CSV) and `golfflight sweep` (CSV, Parquet, grids) read and write the same columns, so both
go through this module: a row's cells become a `ShotRequest` dict (`request_of_cells`), are validated by the
request model with every problem naming its column and allowed range (`check`; `check_cells` does both for a row),
and a result comes back as one flat row (`flat_row`). The standard library and the request models only: the serving
install runs `simulate`.
"""

from __future__ import annotations

import math
import re

from golfflight.contract.refusals import describe_errors
from golfflight.contract.requests import WEATHER_FIELDS, ShotRequest
from golfflight.contract.results import POINT_MODELS, FlatFlight, FlightResult
from pydantic import ValidationError

AIR_COLUMNS = {name: name for name in (*WEATHER_FIELDS, "density_kg_m3")}
"""Air columns are the request's air fields, every unit form (temperature_c or temperature_f, altitude_m or
altitude_ft) under its own name."""
WIND_COLUMNS = {
    "wind_speed_mps": "speed_mps",
    "wind_speed_mph": "speed_mph",
    "wind_from_deg": "from_deg",
    "wind_profile": "profile",
    "wind_reference_height_m": "reference_height_m",
}
GROUND_COLUMNS = {
    "ground_surface": "surface",
    "stimp_ft": "stimp_ft",
    "ground_elevation_m": "elevation_m",
    "ground_elevation_ft": "elevation_ft",
    "slope_deg": "slope_deg",
    "slope_dir_deg": "slope_dir_deg",
}
LAUNCH_COLUMNS = (
    "ball_speed_mps",
    "ball_speed_mph",
    "launch_angle_deg",
    "launch_direction_deg",
    "spin_rpm",
    "spin_axis_deg",
    "back_spin_rpm",
    "side_spin_rpm",
)
IDENTITY_COLUMNS = ("session", "player", "source", "club", "timestamp", "shot_number", "split", "group", "ball")
"""Who, when, where from: canonical shot-record columns and the bay session's (GET /v1/session.csv) that say nothing
about the launch or its conditions; `simulate` passes them over and echoes them in front of each result."""
OBSERVED_COLUMNS = ("carry_x_m", "carry_y_m", "apex_m", "flight_time_s", "landing_angle_deg")
"""Canonical shot-record outcome columns: passed over, not echoed (a result's own columns take some of the names)."""
PASSED_OVER = (*IDENTITY_COLUMNS, *OBSERVED_COLUMNS)
"""Columns that say nothing about the launch or its conditions."""

PUTT = "putt"
"""`simulate`'s column (and the session CSV's) for a putt: 1, true or yes rolls the ball on the shot's ground from the
start, as a bay's shot with the putter does; `sweep` flies no putts and refuses the column."""

REQUEST_COLUMNS = ("normalized", *LAUNCH_COLUMNS, *AIR_COLUMNS, *WIND_COLUMNS, *GROUND_COLUMNS)
"""Every column that goes into a shot's request."""

KNOWN_COLUMNS = frozenset({"shot_id", *REQUEST_COLUMNS, *PASSED_OVER})

TEXT_COLUMNS = frozenset(
    {"shot_id", "session", "player", "club", "timestamp", "split", "source", "group", "ball", "wind_profile",
     "ground_surface"}
)
"""Columns whose cells are words (echoed as text); `normalized` is a flag; every other known column is a number."""

SECTION_COLUMNS = {"air": AIR_COLUMNS, "wind": WIND_COLUMNS, "ground": GROUND_COLUMNS}
"""The request's condition objects and their columns (column -> field)."""

REQUEST_TO_COLUMN = {
    **{f"air.{field}": column for column, field in AIR_COLUMNS.items()},
    **{f"wind.{field}": column for column, field in WIND_COLUMNS.items()},
    **{f"ground.{field}": column for column, field in GROUND_COLUMNS.items()},
}
"""Request field -> column, to name the column of a refused value."""


REQUIRED_COLUMNS = (("ball_speed_mps", "ball_speed_mph"), ("launch_angle_deg",), ("spin_rpm", "back_spin_rpm"))
"""What every row needs, as columns: a ball speed, a launch angle and a spin, each in one of its forms (a column's
absence would otherwise surface as one problem a row, or a chunk of rows of which none could fly)."""


def unknown_columns(columns: list[str], also: frozenset[str] = frozenset()) -> list[str]:
    """The columns neither read, passed over, an earlier run's result (`EARLIER_RESULTS`) nor among `also`."""
    return [c for c in columns if c not in KNOWN_COLUMNS and c not in EARLIER_RESULTS and c not in also]


def missing_columns(columns: list[str]) -> list[str]:
    """Each required launch column that `columns` lacks (`a or b` where either form does)."""
    return [" or ".join(forms) for forms in REQUIRED_COLUMNS if not any(c in columns for c in forms)]


def columns_message(source: str, columns: list[str], also: frozenset[str] = frozenset()) -> str | None:
    """Why a table with these columns cannot be read, in one line, or None: no columns, or the launch columns it
    misses and the unknown ones it has (`also`: more columns the reader takes). `simulate` and `sweep` check a file's
    header with it before reading a row."""
    if not columns:
        return f"{source} line 1: no header row; launch columns are {', '.join(LAUNCH_COLUMNS)}"
    problems = []
    missing = missing_columns(columns)
    if missing:
        problems.append(
            f"missing columns: {', '.join(missing)} (every row needs a ball speed, a launch angle and a spin)"
        )
    unknown = unknown_columns(columns, also)
    if unknown:
        problems.append(f"unknown columns {unknown}; launch columns are {', '.join(LAUNCH_COLUMNS)}")
    return f"{source}: {'; '.join(problems)}" if problems else None


def number_or_text(text: str) -> float | str:
    try:
        return float(text)
    except ValueError:
        return text


def cell_value(value):
    """A cell as the request sees it: text stripped and read as a number where it is one, blanks None."""
    if isinstance(value, str):
        value = value.strip()
        return number_or_text(value) if value else None
    return value


def is_flag_set(value) -> bool:
    """The `normalized` column: 1, true or yes (any case) ask for the normalized flight."""
    return str(value).lower() in ("1", "1.0", "true", "yes")


_PLACES = {
    **{column: (None, column) for column in LAUNCH_COLUMNS},
    **{column: (section, field) for section, columns in SECTION_COLUMNS.items() for column, field in columns.items()},
    "normalized": (None, "normalized"),
}
"""Where each request column's cell goes in a ShotRequest dict (section, field), in the dict's order."""

_ORDER = {column: i for i, column in enumerate(_PLACES)}


def request_of_cells(cells: dict) -> dict:
    """A ShotRequest dict from one row's cells (as `cell_value` reads them; None or missing = not given): the launch
    fields, then the air, wind and ground objects, then `normalized`, each in the order of its columns (only the
    cells a row has are looked at: a sweep builds one for each of many rows)."""
    shot: dict = {}
    for column in sorted(_ORDER.keys() & cells.keys(), key=_ORDER.__getitem__):
        value = cells[column]
        if value is None:
            continue
        section, field = _PLACES[column]
        if column == "normalized":
            shot[field] = is_flag_set(value)
        elif section is None:
            shot[field] = value
        else:
            shot.setdefault(section, {})[field] = value
    return shot


def _of_cells(message: str) -> str:
    """A request model's message about the forms of a quantity said of a row's cells, where a blank cell is a value
    not given: "(got none)" reads "(neither given)"."""
    return message.replace("(got none)", "(neither given)")


QUANTITY = re.compile(r"([a-z ]+): (.*)", re.DOTALL)
"""A request validator's problem of the shot as a whole: the quantity in lower-case words, then the problem."""


def _shot_problem(message: str, csv_columns: bool) -> str:
    """A problem of the shot as a whole (a quantity given in neither or both of its forms): "spin columns: give
    exactly one of spin_rpm or back_spin_rpm (neither given)" (CSV), "spin fields: ..." (JSON), or "as a whole: ..." for
    something that is not a shot at all."""
    named = QUANTITY.match(message)
    if not named:
        return f"as a whole: {message}"
    quantity, text = named.groups()
    if csv_columns:
        return f"{quantity} columns: {_of_cells(text)}"
    return f"{quantity} fields: {text}"


def check(item, csv_columns: bool = True) -> ShotRequest | list[str]:
    """The validated request, or one problem per invalid value naming its column (or request field) and range, or
    the columns (fields) of a quantity given in neither or both forms."""
    try:
        return ShotRequest.model_validate(item)
    except ValidationError as error:
        problems = []
        for detail in describe_errors(error.errors()):
            field, message = detail["field"], detail["message"].split(": ", 1)[-1]
            if not detail["loc"]:  # about the shot as a whole, not one field of it
                problems.append(_shot_problem(message, csv_columns))
                continue
            if csv_columns and field in SECTION_COLUMNS:  # about several fields (two forms given): name the columns
                columns = {name: column for column, name in SECTION_COLUMNS[field].items()}
                message = re.sub(r"\b\w+\b", lambda word, named=columns: named.get(word[0], word[0]), message)
                problems.append(f"{field} columns: {_of_cells(message)}")
                continue
            where = f"column '{REQUEST_TO_COLUMN.get(field, field)}'" if csv_columns else f"field '{field}'"
            problems.append(f"{where}: {message}")
        return problems


NUMERIC_REQUEST_COLUMNS = tuple(c for c in REQUEST_COLUMNS if c not in TEXT_COLUMNS and c != "normalized")
"""The request's number columns, where a NaN (a Parquet float, or a CSV cell reading NaN) is refused as not a
number."""


def check_cells(cells: dict) -> ShotRequest | list[str]:
    """The validated request of one row's cells (as `cell_value` reads them), or its problems: `check`'s, each naming
    its column, with a NaN cell said to be "not a number" (the model would call it not finite)."""
    checked = check(request_of_cells(cells))
    if not isinstance(checked, list):
        return checked
    nan = [c for c in NUMERIC_REQUEST_COLUMNS if isinstance(cells.get(c), float) and math.isnan(cells[c])]
    if not nan:
        return checked
    named = tuple(f"column '{c}':" for c in nan)
    return [f"column '{c}': not a number (got NaN)" for c in nan] + [p for p in checked if not p.startswith(named)]


AIR_DENSITY = "air_density_kg_m3"
"""The column of the air density a shot was flown in, from its air columns (ICAO standard air where it gives none):
`simulate` and `sweep` give it between a row's input columns and its flight's."""

ELEVATION_COLUMNS = ("ground_elevation_m", "ground_elevation_ft")
"""Columns that can put the ground off the tee's elevation, so that flat_* columns come back (`result_columns`)."""

LEFT_OUT = ("trajectory", "normalized", "flat", "conditions", "flown_in")
"""Result fields that are not flat numbers of the flight (the nested flights get prefixed columns instead)."""


def flat_row(result: dict) -> dict:
    """One flat row of a result: the flight's numbers, then normalized_* and flat_* ones, or the error."""
    row = {}
    for prefix, flight in (("", result), ("normalized_", result.get("normalized")), ("flat_", result.get("flat"))):
        if not flight:
            continue
        for key, value in flight.items():
            if key in POINT_MODELS:
                row.update({f"{prefix}{key}_{field}": number for field, number in value.items()})
            elif key not in LEFT_OUT:
                row[prefix + key] = value
    return row


def _flat_names(fields, prefix: str = "") -> list[str]:
    """The columns of a result model's fields, as `flat_row` names them: a point's coordinates as NAME_FIELD (NAME_x_m,
    NAME_y_m, NAME_x_yd, NAME_y_yd)."""
    names = []
    for key in fields:
        if key in POINT_MODELS:
            names += [f"{prefix}{key}_{field}" for field in POINT_MODELS[key].model_fields]
        elif key not in LEFT_OUT:
            names.append(prefix + key)
    return names


def result_columns(normalized: bool, flat: bool) -> list[str]:
    """The columns `flat_row` can give, in its order: the flight's, then normalized_* (if asked for) and flat_* (if
    any ground lies off the tee's elevation), then `error` for a shot the engine could not fly."""
    names = _flat_names(FlightResult.model_fields)
    if normalized:
        names += _flat_names(FlightResult.model_fields, "normalized_")
    if flat:
        names += _flat_names(FlatFlight.model_fields, "flat_")
    return [*names, "error"]


EARLIER_RESULTS = frozenset({"row", AIR_DENSITY, *result_columns(normalized=True, flat=True)})
"""The columns `simulate` writes besides its input's: a file with a result in it (simulate's own output, the bay's
session CSV) flies again, its earlier results passed over and not echoed (the new flight writes its own)."""


def condition_cells(request: ShotRequest, given_only: bool = False) -> dict:
    """A request's conditions (air, wind, ground) as the columns that give them, each as the request has it: every
    value, defaults included (a wind's profile), or with `given_only` those the request was given."""
    cells = {}
    for section, columns in SECTION_COLUMNS.items():
        part = getattr(request, section)
        if part is not None:
            named = {name: column for column, name in columns.items()}
            values = part.model_dump(exclude_none=True, exclude_unset=given_only)
            cells.update({named[k]: v for k, v in values.items() if k in named})
    return cells
