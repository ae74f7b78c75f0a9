"""`golfflight accuracy --variant LABEL=RUN[,RUN...]`: the trained variants (a bundle, or an NN run folder, a run
per seed) beside Ferguson 2022 published and the synthetic model on every held-out set and the validation split,
written into a docs page's own generated section (`variant_comparison`)."""

from __future__ import annotations

import os
from pathlib import Path

from golfflight.errors import InputError
from golfflight.evaluation.accuracy_flyers import ferguson_flyer, model_flyer
from golfflight.evaluation.landing_network import LandingNetwork
from golfflight.evaluation.variant_comparison import (
    BOOTSTRAP_DRAWS,
    Comparand,
    Predictor,
    comparison_lines,
    flown,
    predicted_landing,
)
from golfflight.evaluation.variant_sets import all_sets
from golfflight.shots.markdown import write_generated_section

COMMAND = "accuracy --variant"


def parse_variant(text: str) -> tuple[str, list[str]]:
    """'LABEL=RUN[,RUN...]' -> (label, runs); InputError naming the option for anything else."""
    label, _, runs = text.partition("=")
    paths = [p for p in runs.split(",") if p]
    if not label or not paths:
        raise InputError(f"--variant must be LABEL=RUN[,RUN...] (a bundle or an NN run folder a seed), got {text!r}")
    return label, paths


def _run(path: str) -> Predictor:
    """A bundle flies its shots; a folder of `train-real --variant nn` predicts their landing points."""
    if (Path(path) / "model_card.json").is_file():
        return flown(model_flyer(path))
    return predicted_landing(LandingNetwork(path))


def comparands(variants: list[str], synthetic: str | os.PathLike) -> list[Comparand]:
    """The given variants in order, then Ferguson 2022 published and the synthetic model (at the first bundle's
    Euler step, as `golfflight accuracy` flies Ferguson)."""
    parsed = [parse_variant(text) for text in variants]
    compared = [Comparand(label, [_run(path) for path in paths]) for label, paths in parsed]
    synthetic_model = model_flyer(synthetic, "synthetic model")
    ferguson = ferguson_flyer(synthetic_model.dt_s, synthetic_model.max_flight_time_s)
    return [*compared, Comparand("Ferguson 2022 published", [flown(ferguson)]),
            Comparand("synthetic model", [flown(synthetic_model)])]


def run_variant_comparison(variants: list[str], synthetic: str | os.PathLike, data_dir: str | os.PathLike,
                           validation_file: str | os.PathLike | None, out: str | os.PathLike) -> str:
    """Compare, write OUT's `accuracy --variant` section, and return its markdown."""
    lines = [
        "Each cell: the statistic of the model's first run (the one exported, or chosen on validation), its 95 % "
        f"interval from {BOOTSTRAP_DRAWS:,} bootstrap draws of whole blocks (range blocks, tour holes, validation "
        "groups: shots of one block share their weather and player, so single shots are not resampled), and the "
        "range over the runs where a variant has several seeds. NN predicts no height. Errors in yards, model "
        "minus recorded.",
        "",
        *comparison_lines(comparands(variants, synthetic), all_sets(data_dir, validation_file)),
    ]
    markdown = "\n".join(lines) + "\n"
    write_generated_section(out, markdown, COMMAND)
    return markdown
