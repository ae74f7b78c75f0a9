"""Three-vectors as (x, y, z) tuples whose components are floats (one ball), NumPy [N] arrays (a batch) or torch [N]
tensors (the torch engine's batch on its device), and the few scalar functions the ground phase needs on each: one
formula serves the one-shot latency path, the batch and the device, as `flight.physics` does for the flight."""

from __future__ import annotations

import math
import sys

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


NUMBERS = (float, int, np.generic)
"""Plain numbers (NumPy's scalars among them): one ball's components, on the one-shot latency path (checked before
anything slower)."""


def _torch(name: str, *values):
    """torch's `name` on `values`, some of them torch tensors (the torch engine's ground phase on its device: this
    module never imports torch, a caller holding tensors has), the plain numbers made tensors like the first tensor."""
    torch = sys.modules["torch"]
    like = next(v for v in values if isinstance(v, torch.Tensor))
    return getattr(torch, name)(*(v if isinstance(v, torch.Tensor) else torch.as_tensor(v, dtype=like.dtype,
                                                                                       device=like.device)
                                  for v in values))


def minimum(a, b):
    if isinstance(a, NUMBERS) and isinstance(b, NUMBERS):
        return min(a, b)
    return np.minimum(a, b) if isinstance(a, np.ndarray) or isinstance(b, np.ndarray) else _torch("minimum", a, b)


def maximum(a, b):
    if isinstance(a, NUMBERS) and isinstance(b, NUMBERS):
        return max(a, b)
    return np.maximum(a, b) if isinstance(a, np.ndarray) or isinstance(b, np.ndarray) else _torch("maximum", a, b)


def atan2(y, x):
    if isinstance(y, NUMBERS) and isinstance(x, NUMBERS):
        return math.atan2(y, x)
    return np.arctan2(y, x) if isinstance(y, np.ndarray) or isinstance(x, np.ndarray) else _torch("atan2", y, x)


def cos(a):
    if isinstance(a, NUMBERS):
        return math.cos(a)
    return np.cos(a) if isinstance(a, np.ndarray) else a.cos()


def sin(a):
    if isinstance(a, NUMBERS):
        return math.sin(a)
    return np.sin(a) if isinstance(a, np.ndarray) else a.sin()


def log1p(a):
    if isinstance(a, NUMBERS):
        return math.log1p(a)
    return np.log1p(a) if isinstance(a, np.ndarray) else a.log1p()


def expm1(a):
    if isinstance(a, NUMBERS):
        return math.expm1(a)
    return np.expm1(a) if isinstance(a, np.ndarray) else a.expm1()


def where(condition, a, b):
    """a where `condition` holds, else b (both evaluated)."""
    if isinstance(condition, (bool, np.bool_)):
        return a if condition else b
    if isinstance(condition, np.ndarray):
        return np.where(condition, a, b)
    torch = sys.modules["torch"]
    dtype = next((v.dtype for v in (a, b) if isinstance(v, torch.Tensor)), torch.float64)
    return torch.where(condition, *(v if isinstance(v, torch.Tensor) else torch.as_tensor(v, dtype=dtype,
                                                                                        device=condition.device)
                                    for v in (a, b)))
