"""`golfflight convert`: turn a real launch-monitor export into the canonical shot CSV and print what was dropped."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from golfflight.commands import COMMANDS
from golfflight.errors import InputError

if TYPE_CHECKING:
    from golfflight.shots.trackman import Conversion

SKIP_HELP = "leave out malformed rows (each listed in the report) instead of refusing the file"


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "convert", help=COMMANDS["convert"].summary
    )
    formats = parser.add_subparsers(dest="format", required=True)

    trackman = formats.add_parser("trackman", help="a TrackMan CSV export (header row, then a units row)")
    trackman.add_argument("source", help="the TrackMan CSV export")
    trackman.add_argument("--out", required=True, help="canonical CSV to write")
    flights = trackman.add_mutually_exclusive_group()
    flights.add_argument("--min-tracked-fraction", type=float, default=0.9,
                         help="keep shots whose radar track covers this fraction of the flight (outdoor, measured)")
    flights.add_argument("--all-flights", action="store_true",
                         help="keep indoor shots too (their outcome is TrackMan's model)")
    trackman.add_argument("--ball", action="extend", nargs="+", help="keep only these ball types, e.g. Premium")
    trackman.add_argument("--session", help="session id when the file has no Date column (default: the file name)")
    trackman.add_argument("--skip-bad-rows", action="store_true", help=SKIP_HELP)
    trackman.set_defaults(run=run_trackman)

    tourcast = formats.add_parser("tourcast", help="PGA TOUR TOURCAST shot_trajectory CSV (+ pbp CSV for spin)")
    tourcast.add_argument("source", help="the shot_trajectory_*.csv file")
    tourcast.add_argument("--pbp", help="the event's pbp_*.csv file: spin joined on round/hole/player/shot")
    tourcast.add_argument("--estimate-spin", action="store_true",
                          help="estimate missing spin from the initial lift (Ferguson 2022 C_L) instead of dropping")
    tourcast.add_argument("--sample-interval", type=float, default=0.01, help="trajectory sample spacing, s")
    tourcast.add_argument("--out", required=True, help="canonical CSV to write (the trajectories go beside it)")
    tourcast.add_argument("--skip-bad-rows", action="store_true", help=SKIP_HELP)
    tourcast.set_defaults(run=run_tourcast)

    pbp = formats.add_parser("pbp", help="PGA TOUR play-by-play pbp_*.csv: the radar-measured tee shots' launch")
    pbp.add_argument("source", help="the pbp_*.csv file")
    pbp.add_argument("--out", required=True, help="canonical CSV to write")
    pbp.add_argument("--no-apex", dest="apex", action="store_false",
                     help="leave apex_m blank instead of reading radarData.apexHeight")
    pbp.add_argument("--skip-bad-rows", action="store_true", help=SKIP_HELP)
    pbp.set_defaults(run=run_pbp)

    garmin = formats.add_parser("garmin", help="a Garmin Golf app shot export (Approach R10, R50)")
    garmin.add_argument("source", help="the Garmin Golf CSV export")
    garmin.add_argument("--out", required=True, help="canonical CSV to write")
    garmin.add_argument("--no-air", dest="air", action="store_false",
                        help="leave the air blank (ICAO standard) instead of each shot's temperature and pressure")
    garmin.add_argument("--session", help="session id when the file has no Date column (default: the file name)")
    garmin.add_argument("--skip-bad-rows", action="store_true", help=SKIP_HELP)
    garmin.set_defaults(run=run_garmin)


def _write(conversion: Conversion, out: str) -> int:
    from golfflight.shots.records import trajectories_path, write_shots, write_trajectories

    print(conversion.report.summary())
    if not conversion.records:
        print(f"golfflight convert: no shot kept, {out} not written", file=sys.stderr)
        return 1
    write_shots(out, conversion.records)
    print(f"wrote {len(conversion.records)} shots to {out}")
    if conversion.trajectories:
        companion = trajectories_path(out)
        write_trajectories(companion, conversion.trajectories)
        print(f"wrote {len(conversion.trajectories)} sampled trajectories to {companion}")
    return 0


def run_trackman(args: argparse.Namespace) -> int:
    from golfflight.shots.trackman import load_trackman

    fraction = None if args.all_flights else args.min_tracked_fraction
    if fraction is not None and not 0 < fraction <= 1:
        raise InputError(f"--min-tracked-fraction must be in (0, 1], got {fraction}")
    conversion = load_trackman(args.source, min_tracked_fraction=fraction, balls=args.ball, session=args.session,
                               skip_bad_rows=args.skip_bad_rows)
    return _write(conversion, args.out)


def run_tourcast(args: argparse.Namespace) -> int:
    from golfflight.shots.tourcast import load_tourcast

    if args.sample_interval <= 0:
        raise InputError(f"--sample-interval must be positive, got {args.sample_interval}")
    conversion = load_tourcast(args.source, args.pbp, estimate_spin=args.estimate_spin,
                               sample_interval_s=args.sample_interval, skip_bad_rows=args.skip_bad_rows)
    return _write(conversion, args.out)


def run_pbp(args: argparse.Namespace) -> int:
    from golfflight.shots.pbp import load_pbp

    return _write(load_pbp(args.source, apex=args.apex, skip_bad_rows=args.skip_bad_rows), args.out)


def run_garmin(args: argparse.Namespace) -> int:
    from golfflight.shots.garmin import load_garmin

    conversion = load_garmin(args.source, air=args.air, session=args.session, skip_bad_rows=args.skip_bad_rows)
    return _write(conversion, args.out)
