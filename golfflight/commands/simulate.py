"""`golfflight simulate`: fly shots through a model bundle from the command line, as POST /v1/shots/batch does.

Input: JSON (one shot, a list of shots, or {"shots": [...]}, in the HTTP request format) or a CSV of launches
(one row per shot, the request's launch fields as columns plus optional flat conditions: temperature_c,
altitude_m, pressure_hpa, humidity_pct, density_kg_m3, wind_speed_mps, wind_from_deg, wind_profile,
wind_reference_height_m, normalized, and the ground: ground_surface, stimp_ft, ground_elevation_m, slope_deg,
slope_dir_deg). A canonical shot file works as is: its identity and outcome columns are
passed over, its shot_id echoed. Output: {"results": [...]} as JSON, or a flat CSV when --out ends in .csv.

A bad shot (a value out of range or not a number, an extra cell, a shot_id seen before) refuses the file with its
line (CSV) or index (JSON) and field; --skip-bad-rows flies the rest and lists each one left out on stderr.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

from shots.records import reading

AIR_COLUMNS = {name: name for name in ("temperature_c", "altitude_m", "pressure_hpa", "humidity_pct", "density_kg_m3")}
WIND_COLUMNS = {
    "wind_speed_mps": "speed_mps",
    "wind_from_deg": "from_deg",
    "wind_profile": "profile",
    "wind_reference_height_m": "reference_height_m",
}
GROUND_COLUMNS = {
    "ground_surface": "surface",
    "stimp_ft": "stimp_ft",
    "ground_elevation_m": "elevation_m",
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
PASSED_OVER = (
    "session",
    "club",
    "timestamp",
    "split",
    "carry_x_m",
    "carry_y_m",
    "apex_m",
    "flight_time_s",
    "landing_angle_deg",
)
"""Canonical shot-record columns that say nothing about the launch or its conditions."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("simulate", help="fly shots from a JSON or CSV file through the model (no server)")
    parser.add_argument("input", help="JSON or CSV file of shots; - reads JSON from standard input")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.add_argument("--out", help="write here instead of standard output (.csv: a flat CSV, else JSON)")
    parser.add_argument(
        "--skip-bad-rows", action="store_true", help="fly the valid shots and list each invalid one instead of refusing"
    )
    parser.set_defaults(run=run)


def _number_or_text(text: str):
    try:
        return float(text)
    except ValueError:
        return text


REQUEST_TO_COLUMN = {
    **{f"air.{field}": column for column, field in AIR_COLUMNS.items()},
    **{f"wind.{field}": column for column, field in WIND_COLUMNS.items()},
    **{f"ground.{field}": column for column, field in GROUND_COLUMNS.items()},
}
"""Request field -> CSV column, to name the column of a refused value."""


def shots_from_csv(path: Path) -> tuple[list[dict], list[str | None], list[str], list[str]]:
    """Request dicts, shot ids (None where the file has none), where each shot is ("FILE line N") and the problems
    found while reading (extra cells, repeated shot ids) of a launches CSV."""
    with reading(path), open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        known = {"shot_id", "normalized", *LAUNCH_COLUMNS, *AIR_COLUMNS, *WIND_COLUMNS, *GROUND_COLUMNS, *PASSED_OVER}
        unknown = [c for c in reader.fieldnames or [] if c not in known]
        if not reader.fieldnames:
            raise ValueError(f"{path} line 1: no header row; launch columns are {', '.join(LAUNCH_COLUMNS)}")
        if unknown:
            raise ValueError(f"{path}: unknown columns {unknown}; launch columns are {', '.join(LAUNCH_COLUMNS)}")
        shots, ids, places, problems, seen = [], [], [], [], {}
        for line, row in enumerate(reader, start=2):
            place = f"{path} line {line}"
            if None in row:
                problems.append(f"{place}: {len(row[None])} cells beyond the header")
                continue
            shot_id = row.get("shot_id")
            if shot_id and shot_id in seen:
                problems.append(f"{place} column 'shot_id': {shot_id!r} duplicates the shot_id of line {seen[shot_id]}")
                continue
            if shot_id:
                seen[shot_id] = line
            cells = {k: _number_or_text(v.strip()) for k, v in row.items() if v is not None and v.strip() != ""}
            shot = {k: cells[k] for k in LAUNCH_COLUMNS if k in cells}
            air = {AIR_COLUMNS[k]: cells[k] for k in AIR_COLUMNS if k in cells}
            wind = {WIND_COLUMNS[k]: cells[k] for k in WIND_COLUMNS if k in cells}
            ground = {GROUND_COLUMNS[k]: cells[k] for k in GROUND_COLUMNS if k in cells}
            for name, part in (("air", air), ("wind", wind), ("ground", ground)):
                if part:
                    shot[name] = part
            if "normalized" in cells:
                shot["normalized"] = str(cells["normalized"]).lower() in ("1", "1.0", "true", "yes")
            shots.append(shot)
            ids.append(shot_id)
            places.append(place)
    return shots, ids, places, problems


def validate(raw: list, places: list[str], csv_columns: bool) -> tuple[list, list[int], list[str]]:
    """(valid ShotRequests, their indices in `raw`, one problem line per invalid value naming where and which field)."""
    from pydantic import ValidationError

    from service.api.models import ShotRequest, describe_errors

    shots, kept, problems = [], [], []
    for index, (item, place) in enumerate(zip(raw, places, strict=True)):
        try:
            shots.append(ShotRequest.model_validate(item))
            kept.append(index)
        except ValidationError as error:
            for detail in describe_errors(error.errors()):
                field = detail["field"]
                where = f"column '{REQUEST_TO_COLUMN.get(field, field)}'" if csv_columns else f"field '{field}'"
                problems.append(f"{place} {where}: {detail['message'].split(': ', 1)[-1]}")
    return shots, kept, problems


def shots_from_json(text: str, source: str) -> list[dict]:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{source}: not valid JSON ({error})") from None
    if isinstance(data, dict) and "shots" in data:
        data = data["shots"]
    return data if isinstance(data, list) else [data]


def flat_row(result: dict) -> dict:
    """One CSV row of a result: the flight's numbers, then normalized_* and flat_* ones, or the error."""
    row = {}
    for prefix, flight in (("", result), ("normalized_", result.get("normalized")), ("flat_", result.get("flat"))):
        if not flight:
            continue
        for key, value in flight.items():
            if key in ("landing", "rest"):
                row[f"{prefix}{key}_x_m"], row[f"{prefix}{key}_y_m"] = value["x_m"], value["y_m"]
            elif key not in ("trajectory", "normalized", "flat", "conditions"):
                row[prefix + key] = value
    return row


def run(args: argparse.Namespace) -> int:
    from service.api.shots import fly_shots
    from service.engine import FlightEngine
    from service.model_location import model_dir

    ids: list[str | None] = []
    problems: list[str] = []
    from_csv = False
    if args.input == "-":
        raw = shots_from_json(sys.stdin.read(), "standard input")
        places = [f"standard input shot {i}" for i in range(len(raw))]
    else:
        path = Path(args.input)
        if not path.is_file():
            raise FileNotFoundError(f"no such file: {path}")
        from_csv = path.suffix.lower() == ".csv"
        if from_csv:
            raw, ids, places, problems = shots_from_csv(path)
        else:
            with reading(path):
                raw = shots_from_json(path.read_text(), str(path))
            places = [f"{path} shot {i}" for i in range(len(raw))]
    if not raw and not problems:
        raise ValueError(f"{args.input}: no shots in it")
    shots, kept, invalid = validate(raw, places, from_csv)
    problems += invalid
    if problems and not args.skip_bad_rows:
        shown = "\n  ".join(problems[:20]) + (f"\n  ... and {len(problems) - 20} more" if len(problems) > 20 else "")
        raise ValueError(f"{args.input}: {len(problems)} invalid values (--skip-bad-rows flies the rest):\n  {shown}")
    for problem in problems:
        print(f"golfflight simulate: skipped: {problem}", file=sys.stderr)
    ids = [ids[i] for i in kept] if ids else []
    engine = FlightEngine(model_dir(args.model))
    results = [r.model_dump(exclude_none=True) for r in fly_shots(engine, shots)]
    if args.out and args.out.lower().endswith(".csv"):
        rows = [
            {**({"shot_id": i} if i is not None else {}), **flat_row(r)}
            for i, r in zip(ids or [None] * len(results), results)
        ]
        columns = list(dict.fromkeys(key for row in rows for key in row))
        with open(args.out, "w", newline="") as handle:
            writer = csv.DictWriter(handle, columns)
            writer.writeheader()
            writer.writerows(rows)
        return 0
    if ids:
        results = [{"shot_id": i, **r} for i, r in zip(ids, results)]
    text = json.dumps({"results": results}, indent=2)
    if args.out:
        Path(args.out).write_text(text + "\n")
    else:
        print(text)
    return 0
