"""Subcommands of the `golfflight` command, by name: the module that registers each (`register(subparsers)` adds its
commands, their one-line help from here, and sets `run`) and that help. `golfflight.cli` imports only the module of
the command run, so `golfflight --help` imports none, and a command's help only its own module, whose work's
dependencies (numpy, ONNX Runtime, FastAPI, PyTorch) it imports when it runs."""

from typing import NamedTuple


class Command(NamedTuple):
    """A subcommand's module in `golfflight.commands` and its one-line help."""

    module: str
    summary: str


COMMANDS: dict[str, Command] = {
    "fly": Command(
        "fly", "fly one shot (a club's typical launch or your own) through the served model, or the reference world"
    ),
    "synth": Command("synth", "generate synthetic sessions flown through the reference world"),
    "convert": Command("convert", "convert a real export (TrackMan, TOURCAST, PGA TOUR pbp, Garmin) to canonical CSV"),
    "calibrate-reference": Command(
        "calibrate", "render the reference world's calibration tables (or refit it with --fit)"
    ),
    "train": Command("train", "train a Phys-NN variant or a baseline on shot records"),
    "train-real": Command(
        "train_real",
        "train on the real flights of the shared data (held-out sets never read), export the run with the lowest "
        "validation felt error (carry MAE + |bias| per source)",
    ),
    "export": Command("export", "export a trained physics variant as an ONNX model bundle"),
    "evaluate": Command(
        "evaluate", "Table 1 of trained runs on the validation split, with the noise floor and Figures 6-7"
    ),
    "finetune": Command(
        "finetune", "fine-tune a model bundle or training run on your own shots and export a new bundle"
    ),
    "accuracy": Command(
        "accuracy",
        "compare the real-data model, the synthetic model and Ferguson 2022 on the held-out real data and write "
        "docs/accuracy.md",
    ),
    "ground-fit": Command(
        "ground_fit", "fit the fairway's bounce and roll on PGA TOUR rest positions and write docs/ground.md"
    ),
    "physics-check": Command(
        "physics_check",
        "check a model's C_D, C_L and spin decay along each club's flight against the literature and write "
        "docs/physics_checks.md",
    ),
    "serve": Command(
        "serve", "serve flights over HTTP (OpenAPI docs at /docs) and, with --connect-port, GSPro Open Connect"
    ),
    "simulate": Command("simulate", "fly shots from a JSON or CSV file through the model (no server)"),
    "sweep": Command("sweep", "fly a file or grid of launches into a Parquet file (local, Ray or torch)"),
    "diagnose": Command("discover", "locate and explain a mismatch between recordings and the model"),
    "prove": Command("discover", "hide effects in synthetic recordings, diagnose them blind, score"),
    "own-error": Command(
        "discover", "measure a reference-trained bundle's own error against its teacher, for its card"
    ),
}
"""Every subcommand in the order `golfflight --help` lists them."""
