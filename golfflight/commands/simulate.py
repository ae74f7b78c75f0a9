"""`golfflight simulate`: fly shots through a model bundle from the command line, as POST /v1/shots/batch does.

Input: JSON (one shot, a list of shots, or {"shots": [...]}, in the HTTP request format) or a CSV of launches
(one row per shot, the request's launch fields as columns plus optional flat conditions: temperature_c,
altitude_m, pressure_hpa, humidity_pct, density_kg_m3, wind_speed_mps or wind_speed_mph, wind_from_deg, wind_profile,
wind_reference_height_m, normalized, and the ground: ground_surface, stimp_ft, ground_elevation_m or
ground_elevation_ft, slope_deg, slope_dir_deg). A canonical shot file works as is: its identity and outcome columns are
passed over, its shot_id echoed. Output: {"results": [...]} as JSON, or a flat CSV when --out ends in .csv: the
result's fields as columns (`contract.columns.result_columns`), its points flattened (rest_x_m, rest_x_yd, ...), every
length in metres and yards, the landing speed in m/s and mph.

A bad shot (a value out of range or not a number, an extra cell, a shot_id seen before) refuses the file with its
line (CSV) or index (JSON) and field; --skip-bad-rows flies the rest and lists each one left out on stderr.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

from golfflight.contract.columns import cell_value, check, columns_message, flat_row, request_of_cells
from golfflight.shots.records import reading


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("simulate", help="fly shots from a JSON or CSV file through the model (no server)")
    parser.add_argument("input", help="JSON or CSV file of shots; - reads JSON from standard input")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.add_argument("--out", help="write here instead of standard output (.csv: a flat CSV, else JSON)")
    parser.add_argument(
        "--skip-bad-rows", action="store_true", help="fly the valid shots and list each invalid one instead of refusing"
    )
    parser.set_defaults(run=run)


def shots_from_csv(path: Path) -> tuple[list[dict], list[str | None], list[str], list[str]]:
    """Request dicts, shot ids (None where the file has none), where each shot is ("FILE line N") and the problems
    found while reading (extra cells, repeated shot ids) of a launches CSV."""
    with reading(path), open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        refused = columns_message(str(path), list(reader.fieldnames or []))
        if refused:
            raise ValueError(refused)
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
            shots.append(request_of_cells({k: cell_value(v) for k, v in row.items()}))
            ids.append(shot_id)
            places.append(place)
    return shots, ids, places, problems


def validate(raw: list, places: list[str], csv_columns: bool) -> tuple[list, list[int], list[str]]:
    """(valid ShotRequests, their indices in `raw`, one problem line per invalid value naming where and which field)."""
    shots, kept, problems = [], [], []
    for index, (item, place) in enumerate(zip(raw, places, strict=True)):
        checked = check(item, csv_columns)
        if isinstance(checked, list):
            problems += [f"{place} {problem}" for problem in checked]
        else:
            shots.append(checked)
            kept.append(index)
    return shots, kept, problems


def shots_from_json(text: str, source: str) -> list[dict]:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{source}: not valid JSON ({error})") from None
    if isinstance(data, dict) and "shots" in data:
        data = data["shots"]
    return data if isinstance(data, list) else [data]


def run(args: argparse.Namespace) -> int:
    from golfflight.contract.flying import fly_shots
    from golfflight.flight.bundle_location import model_dir
    from golfflight.flight.engine import FlightEngine

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
