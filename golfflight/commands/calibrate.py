"""`golfflight calibrate-reference`: the reference world's table against TrackMan's tour averages, or a new fit."""

from __future__ import annotations

import argparse

from flight.reference_aero import CALIBRATED
from shots.calibrate_reference import (
    evaluate,
    evaluate_ferguson,
    fit_reference,
    parameters_literal,
    render_markdown,
)
from shots.markdown import write_generated_section
from shots.reference_world import default_tour_averages_path, read_tour_averages

COMMAND = "calibrate-reference"


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        COMMAND,
        help="render the reference world's calibration table (or refit it with --fit)",
        description="Fly the PGA 2023 tour-average launches through the reference world and compare with TrackMan. "
        "Without --fit the committed CALIBRATED parameters are used; with --fit they are refitted and the new "
        "literal is printed for pasting into flight/reference_aero.py.",
    )
    parser.add_argument("--fit", action="store_true", help="run the least-squares fit first (about a minute)")
    parser.add_argument("--data", default=None, help="tour-averages CSV (default: the shared data's PGA 2023 table)")
    parser.add_argument("--out", default=None, help="markdown file whose generated section to replace (default: print)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    clubs = read_tour_averages(args.data or default_tour_averages_path())
    params = CALIBRATED
    if args.fit:
        params = fit_reference(clubs)
        print("# Paste into flight/reference_aero.py:")
        print(parameters_literal(params))
        print()
    text = render_markdown(evaluate(clubs, params), params, baseline=evaluate_ferguson(clubs))
    if args.out:
        write_generated_section(args.out, text, COMMAND)
        print(f"wrote {args.out}")
    else:
        print(text, end="")
    return 0
