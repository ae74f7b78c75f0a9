"""Subcommands of the `golfflight` command; each module has `register(subparsers)` and sets `run`."""

from golfflight.commands import calibrate, convert, discover, export, fly, serve, simulate, synth, train

COMMANDS = [fly, synth, convert, calibrate, train, export, serve, simulate, discover]
