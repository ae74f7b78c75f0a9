"""Phys-NN+, refitted Phys-Q, NN, Ferguson 2022 published and the synthetic model on every held-out set and on the
real training file's validation split (issue 57): landing error, carry, side and height, each with its bias, a 95 %
bootstrap interval that resamples blocks (range blocks, tour holes, validation groups), never single shots, and the
spread over the seeds each trained variant was run with.

Shots of one block share their weather, session and player, so they are not independent: resampling shots would
draw intervals too narrow. Every model flies the same shots in the same air (`variant_sets`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.evaluation.accuracy_sets import outcome_errors
from golfflight.evaluation.landing_network import LandingNetwork
from golfflight.flight.air import Air
from golfflight.flight.constants import YARD_M
from golfflight.flight.flyer import Flyer
from golfflight.shots.markdown import table
from golfflight.shots.records import ShotSet

BOOTSTRAP_DRAWS = 2000
"""Resamples per interval: over 20 resampling seeds the interval's ends scatter by 1 % of its width (sd) at 2,000
draws, 1-3 % at 1,000 (the validation range blocks and THE PLAYERS' holes, docs/accuracy.md); Efron & Tibshirani
1993 advise 1,000 or more for percentile intervals."""
BOOTSTRAP_SEED = 57


@dataclass(frozen=True)
class Statistic:
    """One row of the comparison: the mean (`bias`) or mean absolute value (`mae`) of a per-shot error, in yd."""

    name: str
    key: str
    kind: str

    def per_shot(self, errors: dict[str, np.ndarray]) -> np.ndarray:
        values = errors[self.key]
        return np.abs(values) if self.kind == "mae" else values


STATISTICS = (
    Statistic("landing error, yd", "landing_m", "mae"),
    Statistic("carry MAE, yd", "carry_m", "mae"),
    Statistic("carry bias, yd", "carry_m", "bias"),
    Statistic("side MAE, yd", "side_m", "mae"),
    Statistic("side bias, yd", "side_m", "bias"),
    Statistic("height MAE, yd", "apex_m", "mae"),
    Statistic("height bias, yd", "apex_m", "bias"),
)


class Predictor(Protocol):
    """What flies (or predicts) a set's shots: per-shot model - recorded errors (`accuracy_sets.outcome_errors`)."""

    def __call__(self, shots: ShotSet, air: Air | None) -> dict[str, np.ndarray]: ...


def _carry_where_only_distance(errors: dict[str, np.ndarray], carry_m: np.ndarray, shots: ShotSet
                               ) -> dict[str, np.ndarray]:
    """The carry error of shots that record their carry distance but no landing point (THE PLAYERS' apexRange,
    `docs/real_data.md`), which `outcome_errors` leaves NaN: the model's carry against that distance."""
    x, y = shots.column("carry_x_m"), shots.column("carry_y_m")
    only_distance = np.isnan(x) & np.isfinite(y)
    return errors | {"carry_m": np.where(only_distance, carry_m - y, errors["carry_m"])}


def flown(model: Flyer) -> Predictor:
    """A physics model's errors: each shot flown calm in `air` (None: the model's own)."""

    def errors(shots: ShotSet, air: Air | None) -> dict[str, np.ndarray]:
        flight = model.flight(launch_problem(shots.launch(), air))
        return _carry_where_only_distance(outcome_errors(flight, shots), flight.carry_m, shots)
    return errors


def predicted_landing(network: LandingNetwork) -> Predictor:
    """NN's errors: its landing point against the recorded one; no height (it predicts none), whatever the air."""

    def errors(shots: ShotSet, air: Air | None) -> dict[str, np.ndarray]:
        landing = network.landing(shots.launch())
        x, y = shots.column("carry_x_m"), shots.column("carry_y_m")
        carry = np.hypot(landing[:, 0], landing[:, 1])
        return _carry_where_only_distance(
            {"carry_m": carry - np.hypot(x, y), "side_m": landing[:, 0] - x,
             "landing_m": np.hypot(landing[:, 0] - x, landing[:, 1] - y), "apex_m": np.full(len(x), np.nan)},
            carry, shots)
    return errors


@dataclass
class Comparand:
    """A model in the comparison: its runs (seeds), the first the one exported or chosen on validation."""

    label: str
    runs: Sequence[Predictor]


@dataclass
class ComparisonSet:
    """Shots every model flies, the block of each shot (what the bootstrap resamples) and the air (None: each
    model's own)."""

    name: str
    shots: ShotSet
    blocks: np.ndarray
    air: Air | None
    note: str


@dataclass(frozen=True)
class Estimate:
    """A statistic of one model on one set: its value (the first run), the 95 % block-bootstrap interval, the range
    over the runs (None with one run), the shots and blocks behind it."""

    value: float
    low: float
    high: float
    seeds: tuple[float, float] | None
    shots: int
    blocks: int

    def cell(self) -> str:
        if not math.isfinite(self.value):
            return "—"
        text = f"{self.value:.2f} [{self.low:.2f}, {self.high:.2f}]"
        return text + (f" (seeds {self.seeds[0]:.2f}–{self.seeds[1]:.2f})" if self.seeds else "")


def block_bootstrap(values: np.ndarray, blocks: np.ndarray, draws: int = BOOTSTRAP_DRAWS,
                    seed: int = BOOTSTRAP_SEED) -> tuple[float, float]:
    """The 95 % percentile interval of the mean of `values` (NaN left out) when whole blocks are drawn with
    replacement: each draw takes as many blocks as there are, each with all its shots."""
    keep = np.isfinite(values)
    names, index = np.unique(blocks[keep], return_inverse=True)
    if not len(names):
        return float("nan"), float("nan")
    sums = np.bincount(index, weights=values[keep], minlength=len(names))
    counts = np.bincount(index, minlength=len(names)).astype(float)
    drawn = np.random.default_rng(seed).integers(0, len(names), size=(draws, len(names)))
    means = sums[drawn].sum(axis=1) / counts[drawn].sum(axis=1)
    low, high = np.quantile(means, [0.025, 0.975])
    return float(low), float(high)


def _mean(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if len(finite) else float("nan")


def estimate(statistic: Statistic, runs_errors: list[dict[str, np.ndarray]], blocks: np.ndarray) -> Estimate:
    """`statistic` of the first run with its block interval, and its range over all the runs, in yd."""
    values = [statistic.per_shot(errors) / YARD_M for errors in runs_errors]
    low, high = block_bootstrap(values[0], blocks)
    per_run = [_mean(v) for v in values]
    finite = np.isfinite(values[0])
    return Estimate(per_run[0], low, high, (min(per_run), max(per_run)) if len(per_run) > 1 else None,
                    int(finite.sum()), len(np.unique(blocks[finite])))


def compare(comparands: Sequence[Comparand], comparison_set: ComparisonSet) -> dict[str, dict[str, Estimate]]:
    """Every statistic of every model on one set: {statistic name: {model label: Estimate}}."""
    errors = {c.label: [run(comparison_set.shots, comparison_set.air) for run in c.runs] for c in comparands}
    return {s.name: {label: estimate(s, runs, comparison_set.blocks) for label, runs in errors.items()}
            for s in STATISTICS}


def comparison_lines(comparands: Sequence[Comparand], sets: Sequence[ComparisonSet]) -> list[str]:
    """A markdown table per set: a row per statistic with a shot count, a column per model."""
    labels = [c.label for c in comparands]
    lines: list[str] = []
    for comparison_set in sets:
        results = compare(comparands, comparison_set)
        rows = [(name, *(by_model[label].cell() for label in labels)) for name, by_model in results.items()
                if any(math.isfinite(e.value) for e in by_model.values())]
        n_blocks = len(np.unique(comparison_set.blocks))
        lines += [f"**{comparison_set.name}** ({len(comparison_set.shots)} shots in {n_blocks} blocks; "
                  f"{comparison_set.note}):", "", *table(("", *labels), rows), ""]
    return lines
