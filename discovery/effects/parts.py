"""Pieces several effects share: one reported parameter, draws of a plausible size, sizes in words."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from golfflight.discovery.effects.base import Context, Draw, Reported


def single(key: str) -> Callable[[np.ndarray, np.ndarray, Context], Reported]:
    """Reports the one internal parameter as `key`, with its standard deviation."""

    def describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
        return {key: float(theta[0])}, {key: float(np.sqrt(max(covariance[0, 0], 0.0)))}

    return describe


def sign(rng: np.random.Generator) -> float:
    """+1 or -1, evenly."""
    return 1.0 if rng.random() < 0.5 else -1.0


def signed(**ranges: tuple[float, float, float]) -> Draw:
    """Draws each key as centre ± uniform(low, high), given (centre, low, high), a sign each, in the order given."""

    def draw(rng: np.random.Generator) -> dict[str, float]:
        return {key: float(centre + sign(rng) * rng.uniform(low, high)) for key, (centre, low, high) in ranges.items()}

    return draw


def uniform(**ranges: tuple[float, float]) -> Draw:
    """Draws each key uniformly in (low, high), in the order given."""

    def draw(rng: np.random.Generator) -> dict[str, float]:
        return {key: float(rng.uniform(low, high)) for key, (low, high) in ranges.items()}

    return draw


def plus_minus(value: float, sd: float, unit: str = "") -> str:
    """'4.03 ± 0.02 unit' with as many decimals as the uncertainty's second significant digit needs."""
    decimals = int(np.clip(1 - np.floor(np.log10(sd)), 0, 6)) if sd > 0 and np.isfinite(sd) else 2
    return f"{value:.{decimals}f} ± {sd:.{decimals}f}{unit}"


def scaled(words: str, key: str = "scale") -> Callable[[dict[str, float], dict[str, float]], str]:
    """'drag scaled by 1.05 ± 0.01': `words` then the reported `key` ± 1 sigma."""

    def phrase(p: dict[str, float], u: dict[str, float]) -> str:
        return f"{words} {plus_minus(p[key], u[key])}"

    return phrase
