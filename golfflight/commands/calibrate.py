"""`golfflight calibrate-reference`: the reference world's fit to the recordings it is calibrated on (every trainable
source in its own air, the PGA TOUR 2023 table's training clubs among them), or a new fit, with the table per club
and the altitude and wind checks nothing is fitted to."""

from __future__ import annotations

import argparse
from pathlib import Path

from golfflight.commands import COMMANDS

COMMAND = "calibrate-reference"


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        COMMAND,
        help=COMMANDS[COMMAND].summary,
        description="Fly the calibration cells (the training split of every trainable real source in its own air, "
        "TrackMan's normalized 7-iron set and the PGA 2023 table's training clubs) through the reference world and "
        "compare with the recordings. Without --fit the committed CALIBRATED parameters and air factors are used; "
        "with --fit they are refitted and the new literals are printed for pasting into flight/reference_aero.py "
        "and model_export/reference_targets.py.",
    )
    parser.add_argument("--fit", action="store_true", help="run the least-squares fit first (several minutes)")
    parser.add_argument("--data", type=Path, default=None, help="shared data folder (default: ../shared/data)")
    parser.add_argument("--out", default=None, help="markdown file whose generated section to replace (default: print)")
    parser.add_argument("--quiet", action="store_true", help="no progress on standard error")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.flight.reference_aero import CALIBRATED
    from golfflight.model_export.reference_targets import FITTED_AIR_FACTORS, calibration_cells
    from golfflight.shots.calibrate_reference import (
        evaluate,
        evaluate_clubs,
        evaluate_clubs_ferguson,
        fit_reference,
        parameters_literal,
        render_markdown,
        with_air_factors,
    )
    from golfflight.shots.markdown import write_generated_section
    from golfflight.shots.paths import shared_data_dir
    from golfflight.shots.progress import progress_step
    from golfflight.shots.reference_checks import render_checks_markdown
    from golfflight.shots.reference_world import TOUR_AVERAGES_FILE, read_tour_averages
    from golfflight.shots.source_air import PGA_2023_TABLE, UNKNOWN_AIR_SOURCES

    root = args.data or shared_data_dir()
    shown = not args.quiet
    progress_step(f"reading the calibration cells under {root}...", shown)
    cells = calibration_cells(root)
    params, factors = CALIBRATED, FITTED_AIR_FACTORS
    if args.fit:
        calibration = fit_reference(cells, unknown_air=UNKNOWN_AIR_SOURCES, progress=shown)
        params, factors = calibration.params, calibration.air_factors
        print("# Paste into flight/reference_aero.py:")
        print(parameters_literal(params))
        print(f"# and into model_export/reference_targets.py:\nFITTED_AIR_FACTORS = "
              f"{ {k: round(v, 4) for k, v in factors.items()} }")
        print(f"# cost {calibration.cost:.2f}\n")
    averages = root / TOUR_AVERAGES_FILE
    check = ferguson = None
    progress_step("flying the calibration cells, the tour averages and the altitude and wind checks...", shown)
    if averages.exists():
        clubs = read_tour_averages(averages)
        air = PGA_2023_TABLE.air()
        check, ferguson = evaluate_clubs(clubs, params, air), evaluate_clubs_ferguson(clubs, air)
    text = render_markdown(evaluate(with_air_factors(cells, factors), params), params, check, ferguson, factors)
    text += "\n".join(render_checks_markdown(params)) + "\n"
    if args.out:
        write_generated_section(args.out, text, COMMAND)
        print(f"wrote {args.out}")
    else:
        print(text, end="")
    return 0
