"""Subcommands of the `golfflight` command; each module has `register(subparsers)` and sets `run`."""

from golfflight.commands import calibrate, convert, fly, synth

COMMANDS = [fly, synth, convert, calibrate]
