"""`golfflight ground-fit`: fit the fairway's ground parameters on THE PLAYERS 2020 rest positions, check them on the
TOUR Championship 2020 against a constant roll, print the table and write docs/ground.md's generated section and a
results file."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from golfflight.commands import COMMANDS


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "ground-fit",
        help=COMMANDS["ground-fit"].summary,
        description="Fly every radar tee shot that came to rest on the fairway (THE PLAYERS 2020, TOUR Championship "
        "2020 pbp files of the shared data, read in place) through the model to its rest elevation, bounce and roll "
        "it on the fairway; fit the fairway on THE PLAYERS, check on the TOUR Championship against carry plus a "
        "constant roll.",
    )
    parser.add_argument("--model", help="model bundle (default: the served default, `golfflight serve`'s lookup)")
    parser.add_argument("--data-dir", help="shared data folder (default: $GOLFFLIGHT_SHARED_DATA or ../shared/data)")
    parser.add_argument("--out", default="docs/ground.md", help="markdown file whose generated section is replaced")
    parser.add_argument("--results", default="docs/ground_fit.json", help="JSON results file")
    parser.add_argument("--quiet", action="store_true", help="no progress on standard error")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.flight.flyer import load_flyer
    from golfflight.shots.files import write_text_atomic
    from golfflight.shots.ground_fit import markdown, run_fit
    from golfflight.shots.markdown import write_generated_section
    from golfflight.shots.paths import shared_data_dir

    data_dir = Path(args.data_dir) if args.data_dir else shared_data_dir()
    flyer = load_flyer(args.model)
    model = args.model or str(flyer.bundle_dir)
    fit = run_fit(flyer, data_dir, progress=not args.quiet)
    section = markdown(fit, model)
    print(section, end="")
    write_generated_section(args.out, section, "ground-fit")
    write_text_atomic(args.results, json.dumps({"model": model, **fit.as_dict()}, indent=2) + "\n")
    print(f"wrote {args.out}, {args.results}")
    return 0
