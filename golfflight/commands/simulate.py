"""`golfflight simulate`: fly shots through a model bundle from the command line, as POST /v1/shots/batch does.

Input: JSON (one shot, a list of shots, or {"shots": [...]}, in the HTTP request format) or a CSV of launches
(one row per shot, the request's launch fields as columns plus optional flat conditions: temperature_c,
altitude_m, pressure_hpa, humidity_pct, density_kg_m3, wind_speed_mps or wind_speed_mph, wind_from_deg, wind_profile,
wind_reference_height_m, normalized, and the ground: ground_surface, stimp_ft, ground_elevation_m or
ground_elevation_ft, slope_deg, slope_dir_deg), and `putt` (1, true or yes: the ball rolls on the shot's ground from
the start, as a bay's shot with the putter does). A canonical shot file works as is: its identity and outcome columns
are passed over, its shot_id and identity columns (session, player, source, club, timestamp, shot_number, split,
group, ball) echoed. So does a file with results in it, simulate's own output or the bay's session
(GET /v1/session.csv): its result columns are passed over, not echoed, and it flies to the same carries. A CSV's
header is checked before any row is read: a missing launch column (a ball speed, the launch angle, a spin) or an
unknown one refuses the file in one line (`contract.columns.columns_message`, as `golfflight sweep` does).

Output: {"results": [...]} as JSON, or a flat CSV when --out ends in .csv: the result's fields as columns
(`contract.columns.result_columns`), its points flattened (rest_x_m, rest_x_yd, ...), every length in metres and
yards, the landing speed in m/s and mph. Each result starts with what matches it to its input: `row`, the input's
row number from 0 as in `golfflight sweep`'s results (a CSV's data row: its line number less 2, the header being
line 1; a JSON shot's index), the shot_id and identity columns where the CSV has them, the shot's launch columns as
read, `putt` where the CSV has it, its wind and ground columns, and the air it was flown in: its air columns as given,
then `air_density_kg_m3`, the density flown (ICAO standard air, 1.225 kg/m³, where the shot gives none).

A bad shot (a value out of range or not a number, an extra cell, a shot_id seen before) refuses the file with its
line (CSV) or index (JSON) and field; --skip-bad-rows flies the rest and lists each one left out on stderr, and
refuses the file still when no shot is left to fly.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from golfflight.commands import COMMANDS
from golfflight.errors import InputError


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("simulate", help=COMMANDS["simulate"].summary)
    parser.add_argument("input", help="JSON or CSV file of shots; - reads JSON from standard input")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.add_argument("--out", help="write here instead of standard output (.csv: a flat CSV, else JSON)")
    parser.add_argument(
        "--skip-bad-rows", action="store_true", help="fly the valid shots and list each invalid one instead of refusing"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.commands.simulate_io import fly_all, matching, read_input, refuse_or_skip, validate, write_csv
    from golfflight.flight.bundle_location import model_dir
    from golfflight.flight.engine import FlightEngine

    read, from_csv = read_input(args.input)
    if not read.shots and not read.problems:
        raise InputError(f"{args.input}: no shots in it")
    shots, kept, invalid = validate(read.shots, read.places, from_csv)
    refuse_or_skip(args.input, read.problems + invalid, len(shots), read.rows_read, args.skip_bad_rows)
    engine = FlightEngine(model_dir(args.model))
    putts = [read.putts[i] if read.putts else False for i in kept]
    results = fly_all(engine, shots, putts)
    fronts = matching(read, kept, shots)
    if args.out and args.out.lower().endswith(".csv"):
        write_csv(args.out, fronts, results)
        return 0
    text = json.dumps({"results": [{**f, **r} for f, r in zip(fronts, results, strict=True)]}, indent=2)
    if args.out:
        Path(args.out).write_text(text + "\n")
    else:
        print(text)
    return 0
