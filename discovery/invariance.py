"""One value for every shot: a venue condition or a launch-monitor bias must not change with the launch.

A venue's air, its wind, its ground's height and a launch monitor's bias are each one value for every shot of a set.
Where the model's form differs from the recordings' physics, a fit of such an effect also takes up that form
difference, seen in the effect's direction, and the form difference changes with the launch: a ball model whose drag
falls off faster with speed than the recordings' reads as denser air on the slower shots and thinner air on the
faster ones. So the chosen explanation is fitted again on the slower and on the faster half of the shots (split at
the median ball speed, the launch value the clubs differ most in), and a venue condition or monitor bias whose two
values differ beyond doubt (chi-square of their difference on the two fits' covariances, at SPLIT_LEVEL shared
among the choice's conditions) and materially (further apart than SPLIT_SHARE of the effect's fitted size, its
distance from no effect) is the model's form, not a condition of the recordings: `Diagnoser.select` does not claim
it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.discovery.fit import Fit, Problem, blocks, fit
from scipy.stats import chi2

SPLIT_LEVEL = 0.003
"""The chance (about three standard deviations) below which the two halves' values are told apart, shared among the
conditions of one choice (Bonferroni: each of k is tested at SPLIT_LEVEL / k), so that a choice of three conditions
is no likelier to lose one to chance than a choice of one."""

SPLIT_SHARE = 0.3
"""How far apart (a share of the effect's fitted size) the halves' values must lie to be a material difference:
each half then lies 15 % or more from the value fitted on every shot, beyond the 10 % a named parameter is held to."""

MIN_HALF_SHOTS = 20
"""Fewer shots than this in a half: the halves are not fitted (their values would say little)."""


@dataclass(frozen=True)
class Halves:
    """An effect's values fitted on the slower and on the faster half of the shots, the chance of a difference that
    large from the halves' scatter alone, and how far apart they lie as a share of the effect's fitted size."""

    effect: str
    slower: tuple[float, ...]
    faster: tuple[float, ...]
    p_value: float
    share: float
    level: float = SPLIT_LEVEL

    @property
    def varies(self) -> bool:
        """Whether the halves differ beyond doubt (at `level`) and materially: the model's form, not one condition."""
        return self.p_value < self.level and self.share > SPLIT_SHARE

    def describe(self) -> str:
        def values(theta: tuple[float, ...]) -> str:
            return ", ".join(f"{v:.4g}" for v in theta)

        return (f"{self.effect}: slower half {values(self.slower)}, faster half {values(self.faster)} "
                f"({self.share:.0%} of its size apart, p {self.p_value:.2g})")


def speed_halves(problem: Problem) -> np.ndarray:
    """Which shots are in the slower half (ball speed at or below the median)."""
    speed = problem.recordings.launch["ball_speed_mps"]
    return speed <= np.median(speed)


def halves(problem: Problem, chosen: Fit, rows: np.ndarray) -> list[Halves]:
    """The venue conditions and monitor biases of `chosen`, each fitted on either half of the shots (the fit rows
    `rows` of that half, from the values fitted on every shot); none where a half has fewer than MIN_HALF_SHOTS."""
    conditions = [(effect, block) for effect, block in blocks(chosen) if effect.kind != "form"]
    slower = speed_halves(problem)
    if not conditions or min(slower[rows].sum(), (~slower[rows]).sum()) < MIN_HALF_SHOTS:
        return []
    fitted = []
    for half in (slower, ~slower):
        members = np.flatnonzero(half)
        part = problem.subset(members)  # residuals and Jacobian of this half's shots only
        refit = fit(part, chosen.effects, chosen.theta, np.searchsorted(members, rows[half[rows]]))
        fitted.append((refit.theta, refit.covariance))
    (low_theta, low_cov), (high_theta, high_cov) = fitted
    found = []
    for effect, block in conditions:
        apart = low_theta[block] - high_theta[block]
        spread = low_cov[block, block] + high_cov[block, block]
        statistic = float(apart @ np.linalg.lstsq(spread, apart, rcond=None)[0])
        size = float(np.linalg.norm(chosen.theta[block] - effect.null))
        found.append(Halves(
            effect.name, tuple(low_theta[block].tolist()), tuple(high_theta[block].tolist()),
            float(chi2.sf(statistic, len(apart))), float(np.linalg.norm(apart)) / max(size, 1e-12),
            SPLIT_LEVEL / len(conditions),
        ))
    return found


def set_aside_sentence(entry: str) -> str:
    """The statement's sentence for the conditions set aside as the model's form (`Halves.describe`, joined)."""
    return (" Set aside as the model's form, each a value that changes with the launch where a venue condition or a "
            f"monitor bias is one value for every shot: {entry}.")
