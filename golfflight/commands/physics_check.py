"""`golfflight physics-check`: a model bundle's lift, drag and spin decay along each club's flight against the
published measurements, printed and written into a docs page's generated section."""

from __future__ import annotations

import argparse
from pathlib import Path

from golfflight.commands import COMMANDS


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "physics-check",
        help=COMMANDS["physics-check"].summary,
        description="Fly every club of shots.clubs.CLUBS through the bundle's runtime path in ICAO standard air, "
        "compare the C_D and C_L it meets with the band the measured literature points span near each (Re, S), "
        "and the spin it loses after 1, 3 and 5 s with TrackMan's measurements (the shared data's literature "
        "folder, read in place).",
    )
    parser.add_argument("--model", help="model bundle (default: the served default, `golfflight serve`'s lookup)")
    parser.add_argument("--data-dir", help="shared data folder (default: $GOLFFLIGHT_SHARED_DATA or ../shared/data)")
    parser.add_argument("--out", default="docs/physics_checks.md",
                        help="markdown file whose generated section is replaced (default docs/physics_checks.md)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.evaluation.physics_checks import COMMAND, markdown, run_physics_checks
    from golfflight.shots.markdown import write_generated_section
    from golfflight.shots.paths import shared_data_dir

    data_dir = Path(args.data_dir) if args.data_dir else shared_data_dir()
    section = markdown(run_physics_checks(args.model, data_dir))
    print(section, end="")
    write_generated_section(args.out, section, COMMAND)
    print(f"wrote {args.out}")
    return 0
