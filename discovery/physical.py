"""Explanations in physical terms: a combination of coefficient scales that agree is restated as the one physical
cause they make together, air density (`effects.ALIASES`), with one parameter instead of several.

Air `ratio` x as dense scales drag, lift and the spin torque by `ratio` at once, so an explanation such as "drag x
0.83, lift x 0.83" is thin air in other words, and the simpler physical statement stands unless the richer one beats
it on held-out sessions beyond doubt and by a material share (the rule a pair must pass over a single).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from golfflight.discovery.effects import ALIASES, AIR_VARIANTS, EFFECTS, Effect
from golfflight.discovery.fit import Fit, Problem, Scored, blocks, fit

Score = Callable[[Fit], Scored]

BALL_AGREEMENT = 0.03
"""Another ball whose drag and lift scales lie within this share of each other, and its spin decay within
DECAY_AGREEMENT of them, is air in other words: density alone scales drag, lift and the spin torque by one ratio, so
a ball that differs from the baseline's by one share in all three is a change of air, not of ball. The shares allow
for what the baseline cannot teach (how the flight responds to air it never flew in tilts the three apart: a 1,900 m
venue flown as density alone in Ferguson 2022's world, 0.776, read as a ball of 0.844, 0.865 and 0.911)."""
DECAY_AGREEMENT = 0.15
"""The spin decay is measured far less well than drag and lift (its campaign sizes are 10-30 %)."""


def ball_agrees(result: Fit) -> bool:
    """Whether the fit holds another ball whose three scales agree (BALL_AGREEMENT, DECAY_AGREEMENT)."""
    for effect, block in blocks(result):
        if effect.kind == "ball":
            drag, lift, decay = np.log(result.theta[block])
            return bool(abs(drag - lift) < BALL_AGREEMENT and abs(decay - (drag + lift) / 2) < DECAY_AGREEMENT)
    return False


def aliased(result: Fit) -> list[tuple[Effect, slice]]:
    """The coefficient scales of a fit that air density is made of."""
    return [(e, block) for e, block in blocks(result) if e.name in ALIASES]


def air_in_place(
    problem: Problem,
    result: Fit,
    replaced: list[str],
    variant: str,
    ratio: float,
    rows: np.ndarray,
    score: Score,
    known: dict[frozenset, Scored],
) -> Scored:
    """`result`'s library effects with air density (`variant`, started at `ratio`) in place of the effects named in
    `replaced` (the rest kept beside it), fitted and scored, or taken from `known` where already fitted."""
    kept = [(e, block) for e, block in blocks(result) if e.correction is None and e.name not in replaced]
    kept = [(e, block) for e, block in kept if e.name not in AIR_VARIANTS]
    effects = tuple(e for e, _ in kept) + (EFFECTS[variant],)
    key = frozenset(e.name for e in effects)
    if key not in known:
        start = np.concatenate([result.theta[block] for _, block in kept] + [np.array([ratio])])
        known[key] = score(fit(problem, effects, start, rows))
    return known[key]


def common_ratio(result: Fit) -> float:
    """The density ratio the fit's aliased coefficient scales agree on: their geometric mean (1 where it has none)."""
    scales = [result.theta[block][0] for _, block in aliased(result)]
    return float(np.exp(np.mean(np.log(scales)))) if scales else 1.0


def restatements(
    problem: Problem, chosen: Scored, rows: np.ndarray, score: Score, known: dict[frozenset, Scored]
) -> list[Scored]:
    """The chosen explanation with air density (each variant) in place of its two or more coefficient scales, best
    held-out error first; empty where it has fewer than two."""
    scales = [e.name for e, _ in aliased(chosen.fit)]
    if len(scales) < 2:
        return []
    ratio = float(np.clip(common_ratio(chosen.fit), 0.61, 1.29))
    tried = [air_in_place(problem, chosen.fit, scales, v, ratio, rows, score, known) for v in AIR_VARIANTS]
    return sorted(tried, key=lambda s: s.error)
