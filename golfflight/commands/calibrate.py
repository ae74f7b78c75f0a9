"""`golfflight calibrate-reference`: the reference world's fit to the recordings it is calibrated on, or a new fit,
with the held-out PGA TOUR 2023 averages flown as a check and the altitude and wind checks nothing is fitted to."""

from __future__ import annotations

import argparse
from pathlib import Path

from flight.reference_aero import CALIBRATED
from model_export.reference_targets import calibration_cells
from shots.calibrate_reference import (
    evaluate,
    evaluate_clubs,
    evaluate_clubs_ferguson,
    fit_reference,
    parameters_literal,
    render_markdown,
)
from shots.markdown import write_generated_section
from shots.paths import shared_data_dir
from shots.reference_checks import render_checks_markdown
from shots.reference_world import TOUR_AVERAGES_FILE, read_tour_averages

COMMAND = "calibrate-reference"


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        COMMAND,
        help="render the reference world's calibration tables (or refit it with --fit)",
        description="Fly the calibration cells (the training split of the measured real sources and TrackMan's "
        "normalized 7-iron set) through the reference world and compare with the recordings; then fly the held-out "
        "PGA 2023 tour averages as a check, never a target. Without --fit the committed CALIBRATED parameters are "
        "used; with --fit they are refitted and the new literal is printed for pasting into flight/reference_aero.py.",
    )
    parser.add_argument("--fit", action="store_true", help="run the least-squares fit first (a few minutes)")
    parser.add_argument("--data", type=Path, default=None, help="shared data folder (default: ../shared/data)")
    parser.add_argument("--out", default=None, help="markdown file whose generated section to replace (default: print)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    root = args.data or shared_data_dir()
    cells = calibration_cells(root)
    params = CALIBRATED
    if args.fit:
        params = fit_reference(cells)
        print("# Paste into flight/reference_aero.py:")
        print(parameters_literal(params))
        print()
    averages = root / TOUR_AVERAGES_FILE
    check = ferguson = None
    if averages.exists():
        clubs = read_tour_averages(averages)
        check, ferguson = evaluate_clubs(clubs, params), evaluate_clubs_ferguson(clubs)
    text = render_markdown(evaluate(cells, params), params, check, ferguson)
    text += "\n".join(render_checks_markdown(params)) + "\n"
    if args.out:
        write_generated_section(args.out, text, COMMAND)
        print(f"wrote {args.out}")
    else:
        print(text, end="")
    return 0
