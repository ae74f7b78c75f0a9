"""Subcommands of the `golfflight` command; each module has `register(subparsers)` and sets `run`."""

from golfflight.commands import (
    accuracy,
    calibrate,
    convert,
    discover,
    evaluate,
    export,
    finetune,
    fly,
    ground_fit,
    physics_check,
    serve,
    simulate,
    sweep,
    synth,
    train,
    train_real,
)

COMMANDS = [
    fly, synth, convert, calibrate, train, train_real, export, evaluate, finetune, accuracy, ground_fit, physics_check,
    serve, simulate, sweep, discover,
]
