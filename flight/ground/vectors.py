"""Three-vectors as (x, y, z) tuples whose components are floats (one ball) or NumPy [N] arrays (a batch), and the
few scalar functions the ground phase needs on either: one formula serves the one-shot latency path and the batch,
as `flight.physics` does for the flight."""

from __future__ import annotations

import math

import numpy as np

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


def minimum(a, b):
    return np.minimum(a, b) if isinstance(a, np.ndarray) or isinstance(b, np.ndarray) else min(a, b)


def maximum(a, b):
    return np.maximum(a, b) if isinstance(a, np.ndarray) or isinstance(b, np.ndarray) else max(a, b)


def atan2(y, x):
    return np.arctan2(y, x) if isinstance(y, np.ndarray) or isinstance(x, np.ndarray) else math.atan2(y, x)


def cos(a):
    return np.cos(a) if isinstance(a, np.ndarray) else math.cos(a)


def sin(a):
    return np.sin(a) if isinstance(a, np.ndarray) else math.sin(a)


def log1p(a):
    return np.log1p(a) if isinstance(a, np.ndarray) else math.log1p(a)


def expm1(a):
    return np.expm1(a) if isinstance(a, np.ndarray) else math.expm1(a)


def where(condition, a, b):
    """a where `condition` holds, else b (both evaluated)."""
    return np.where(condition, a, b) if isinstance(condition, np.ndarray) else (a if condition else b)
