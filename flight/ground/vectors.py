"""Three-vectors as (x, y, z) tuples whose components are floats (one ball), NumPy [N] arrays (a batch) or torch [N]
tensors (the torch engine's batch on its device): one formula serves the one-shot latency path, the batch and the
device, as `flight.physics` does for the flight; the scalar functions beside them are `flight.xp`'s."""

from __future__ import annotations

from golfflight.flight.xp import is_flag, where

TINY = 1e-12
"""Guards the direction of a zero vector."""


def dot(a: tuple, b: tuple):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: tuple, b: tuple) -> tuple:
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def add(a: tuple, b: tuple, scale=1.0) -> tuple:
    """a + scale b."""
    return a[0] + scale * b[0], a[1] + scale * b[1], a[2] + scale * b[2]


def times(scale, a: tuple) -> tuple:
    return scale * a[0], scale * a[1], scale * a[2]


def norm(a: tuple):
    return dot(a, a) ** 0.5


def choose(flags, a: tuple, b: tuple) -> tuple:
    """a where `flags` hold, else b, component by component (`flight.xp.where`; one ball's flag picks at once)."""
    if is_flag(flags):
        return a if flags else b
    return where(flags, a[0], b[0]), where(flags, a[1], b[1]), where(flags, a[2], b[2])
