"""The `golfflight` console command: one subcommand per module in `golfflight.commands`, each a thin layer
over plain functions of the packages that do the work."""

from __future__ import annotations

import argparse
import csv
import importlib
import os
import select
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
from golfflight.errors import GolfflightError, InputError


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The command line: every command with its options, or with `only` (a command's name, or "" for none) that
    command's alone, the others by name and one-line help, so that their modules (and what they import) are not
    loaded for a command that does not need them."""
    parser = argparse.ArgumentParser(prog="golfflight", description="Golf ball flight engine (Phys-NN+).")
    parser.add_argument("--version", action="version", version=f"golfflight {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True)
    full = {c.module for name, c in COMMANDS.items() if only is None or name == only}
    for name, command in COMMANDS.items():
        if command.module in full:
            importlib.import_module(f"golfflight.commands.{command.module}").register(subparsers)
            full.discard(command.module)  # a module registers all of its commands at once
        elif name not in subparsers.choices:
            subparsers.add_parser(name, help=command.summary)
    return parser


def command_named(argv: list[str]) -> str:
    """The command an argument list runs ("" when it names none: `golfflight --help`, a typo), read as argparse
    reads it: the first argument that is not an option."""
    first = next((arg for arg in argv if not arg.startswith("-")), "")
    return first if first in COMMANDS else ""


USER_ERRORS = (InputError, FileNotFoundError, IsADirectoryError, NotADirectoryError, PermissionError, csv.Error)
"""What the user can fix, printed as one line with exit status 2: our input errors (a bad option, file, record or
bundle), a path that is missing, unreadable or a folder, and a file that is not CSV (NUL bytes, runaway fields).
Our other failures (an output that cannot be written, a shot that cannot land) are one line with exit status 1;
anything else is a bug and keeps its traceback."""


def stdout_reader_gone() -> bool:
    """Whether standard output is a pipe whose reader has closed it (`golfflight simulate s.csv | head` once `head`
    has its lines): the poll of its write end reports an error."""
    try:
        poll = select.poll()
        poll.register(sys.stdout.fileno(), select.POLLOUT)
        return any(events & select.POLLERR for _, events in poll.poll(0))
    except (AttributeError, OSError, ValueError):  # no poll on this platform, or no file behind standard output
        return False


def _dispatch(argv: list[str] | None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    args = build_parser(command_named(argv)).parse_args(argv)
    try:
        return args.run(args) or 0
    except USER_ERRORS as error:
        print(f"golfflight {args.command}: error: {error}", file=sys.stderr)
        return 2
    except GolfflightError as error:
        print(f"golfflight {args.command}: error: {error}", file=sys.stderr)
        return 1


def main(argv: list[str] | None = None) -> int:
    """Run one command (its help included) and flush what it printed. A reader that closes standard output early
    ends the command quietly with status 0, as `head` expects of what it reads, instead of a BrokenPipeError
    traceback; any other broken pipe keeps its traceback."""
    try:
        try:
            return _dispatch(argv)
        finally:
            sys.stdout.flush()
    except BrokenPipeError:
        if not stdout_reader_gone():
            raise
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # the interpreter's last flush goes nowhere
        return 0


if __name__ == "__main__":
    sys.exit(main())
