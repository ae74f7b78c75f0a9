"""The `golfflight` console command: one subcommand per module in `golfflight.commands`, each a thin layer
over plain functions of the packages that do the work."""

from __future__ import annotations

import argparse
import csv
import sys

import golfflight

if getattr(golfflight, "__file__", None) is None:  # a namespace package: a folder hides ours (golfflight/__init__.py)
    raise SystemExit(
        f"golfflight: Python imported the folder {next(iter(golfflight.__path__))} instead of the installed golfflight "
        "(a folder called golfflight in the current folder comes first): run `python3 -m golfflight` from any other "
        "folder, such as the checkout itself, or run the `golfflight` command"
    )

from golfflight import __version__
from golfflight.commands import COMMANDS


class UserError(Exception):
    """An error the user can fix (a bad file, a bad option): printed as one line, no traceback."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="golfflight", description="Golf ball flight engine (Phys-NN+).")
    parser.add_argument("--version", action="version", version=f"golfflight {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.register(subparsers)
    return parser


USER_ERRORS = (UserError, ValueError, OSError, csv.Error)
"""What a bad input can raise: ValueError covers RecordError, BundleError, pydantic's and JSON's errors; OSError a
missing, unreadable or directory path; csv.Error a file that is not CSV (NUL bytes, runaway fields)."""


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.run(args) or 0
    except USER_ERRORS as error:
        print(f"golfflight {args.command}: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
