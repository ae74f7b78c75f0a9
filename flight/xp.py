"""The array namespace the physics is written over: plain floats (one ball, on the single shot's latency path), NumPy
arrays (a batch) and torch tensors (training and the torch engine, on a CPU or a GPU). The equations, the wind's
profile, the apex and the ground phase use `+ - * /`, `** 0.5` and these functions only, so each is written once and
runs on all three. The one place an array's kind is told apart: this module never imports torch (a caller holding
tensors has), so the serving install stays torch-free.

Array-API style, written out rather than taken from `array_api_compat`: that library has no namespace for plain
floats, the latency path's, and these few functions are all the physics needs."""

from __future__ import annotations

import math
import sys

import numpy as np

NUMBERS = (float, int, np.generic)
"""Plain numbers (NumPy's scalars among them): one ball's components, checked before anything slower."""


FLAGS = (bool, np.bool_)
"""One ball's flag (a comparison of plain numbers)."""


def is_flag(value) -> bool:
    """Whether a value is one ball's flag rather than an array of flags."""
    return isinstance(value, FLAGS)


def is_number(value) -> bool:
    """Whether a value is one plain number rather than an array (one ball's, or one air's: hashable, cacheable)."""
    return isinstance(value, NUMBERS)


def is_array(value) -> bool:
    """Whether a value is an array of numbers, NumPy's or torch's (torch's told by its type's module: this module
    never imports torch), rather than one number or an object such as a coefficient model."""
    return isinstance(value, np.ndarray) or type(value).__module__.startswith("torch")


def rows(value, index):
    """Some balls' share of a per-ball value: an array's rows at `index`; one number, or a 0-d array, is every
    ball's."""
    return value[index] if is_array(value) and value.ndim > 0 else value


def _tensor_call(name: str, *values):
    """torch's `name` on `values`, some of them tensors; the plain numbers among them made tensors like the first."""
    torch = sys.modules["torch"]
    like = next(v for v in values if isinstance(v, torch.Tensor))
    return getattr(torch, name)(*(v if isinstance(v, torch.Tensor) else torch.as_tensor(v, dtype=like.dtype,
                                                                                       device=like.device)
                                  for v in values))


CLAMPS = {"maximum": "clamp_min", "minimum": "clamp_max"}
"""A tensor's bound by a plain number without making the number a tensor (no copy to a device every call)."""


def _binary(name: str, numbers, arrays):
    def function(a, b):
        if isinstance(a, NUMBERS) and isinstance(b, NUMBERS):
            return numbers(a, b)
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            return arrays(a, b)
        if name in CLAMPS and isinstance(b, NUMBERS):
            return getattr(a, CLAMPS[name])(b)
        if name in CLAMPS and isinstance(a, NUMBERS):
            return getattr(b, CLAMPS[name])(a)
        return _tensor_call(name, a, b)

    function.__name__ = name
    return function


def _unary(name: str, numbers, arrays):
    def function(a):
        if isinstance(a, NUMBERS):
            return numbers(a)
        return arrays(a) if isinstance(a, np.ndarray) else getattr(a, name)()

    function.__name__ = name
    return function


maximum = _binary("maximum", max, np.maximum)
minimum = _binary("minimum", min, np.minimum)
atan2 = _binary("atan2", math.atan2, np.arctan2)
cos = _unary("cos", math.cos, np.cos)
sin = _unary("sin", math.sin, np.sin)
log = _unary("log", math.log, np.log)
log1p = _unary("log1p", math.log1p, np.log1p)
expm1 = _unary("expm1", math.expm1, np.expm1)


def where(condition, a, b):
    """a where `condition` holds, else b (both evaluated)."""
    if isinstance(condition, FLAGS):
        return a if condition else b
    if isinstance(condition, np.ndarray):
        return np.where(condition, a, b)
    torch = sys.modules["torch"]
    if isinstance(a, torch.Tensor) or isinstance(b, torch.Tensor):
        return torch.where(condition, a, b)  # a plain number takes the tensor's dtype
    return torch.where(condition, *(torch.as_tensor(v, dtype=torch.float64, device=condition.device) for v in (a, b)))


def lerp(start, end, weight):
    """start + weight (end - start), one kernel for tensors (`torch.lerp`); weight [N] against [N,3] ends."""
    weight = weight[:, None] if weight.ndim < start.ndim else weight
    if isinstance(start, np.ndarray):
        return start + weight * (end - start)
    return sys.modules["torch"].lerp(start, end, weight)


def stack(components) -> object:
    """[..., k] from k arrays of one kind (NumPy or torch), along a new last axis."""
    first = components[0]
    if isinstance(first, np.ndarray):
        return np.stack(components, -1)
    return sys.modules["torch"].stack(tuple(components), -1)


def columns(a) -> tuple:
    """The three components of [..., 3] vectors (NumPy or torch): views, not copies."""
    return a[..., 0], a[..., 1], a[..., 2]


def anything(flags) -> bool:
    """Whether any of these flags holds: one ball's flag, or an array's (a device's answer waits for it)."""
    return bool(flags) if isinstance(flags, FLAGS) else bool(flags.any())


def negated(flags):
    """Not these flags: one ball's (a plain bool's `~` would be an integer), or an array's, element by element."""
    return not flags if isinstance(flags, FLAGS) else ~flags


def zeros_like(value, integer: bool = False):
    """Zeros of `value`'s kind: one plain number, or an array's shape, dtype (int64 where `integer`) and device."""
    if not is_array(value):
        return 0 if integer else 0.0
    if isinstance(value, np.ndarray):
        return np.zeros_like(value, dtype=np.int64 if integer else value.dtype)
    torch = sys.modules["torch"]
    return torch.zeros_like(value, dtype=torch.int64 if integer else value.dtype)


def full(shape, value, like):
    """An array of `shape` filled with `value`, of `like`'s kind (a float array; a tensor's dtype and device)."""
    if isinstance(like, np.ndarray):
        return np.full(shape, value, dtype=float)
    shape = (shape,) if isinstance(shape, int) else shape
    return sys.modules["torch"].full(shape, value, dtype=like.dtype, device=like.device)


def falses(n: int, like):
    """n False flags of `like`'s kind (a tensor's device)."""
    if isinstance(like, np.ndarray):
        return np.zeros(n, dtype=bool)
    torch = sys.modules["torch"]
    return torch.zeros(n, dtype=torch.bool, device=like.device)


def nonzero(flags):
    """The indices where a NumPy or torch array of flags holds (a tensor's answer waits for its device)."""
    if isinstance(flags, np.ndarray):
        return np.flatnonzero(flags)
    return flags.nonzero().squeeze(1)


def answers_now(flags) -> bool:
    """Whether asking about these flags is answered at once: NumPy's, or a tensor on the CPU; a GPU's tensor would
    first finish its queue of work (at every step, the step's own kernels)."""
    return isinstance(flags, np.ndarray) or flags.device.type == "cpu"


def rows_of(flags):
    """The rows a masked write touches (`put`): those where `flags` hold, when that is answered at once; else every
    row (a slice)."""
    return nonzero(flags) if answers_now(flags) else slice(None)


def put(flags, rows, current, values):
    """`current` with `values` (of `rows_of(flags)`) in the rows where `flags` hold: those rows written in place (a
    batch's landings are a few rows a step), or, on a GPU, every row merged by `where`, so that nothing waits for
    the device to say which rows hold."""
    if not isinstance(rows, slice):
        current[rows] = values
        return current
    return where(flags[:, None] if getattr(values, "ndim", 0) > flags.ndim else flags, values, current)


def may_hold(flags) -> bool:
    """Whether any of these flags may hold, answered without waiting for a device: the answer where it is answered
    at once (`answers_now`); True on a GPU."""
    return bool(flags.any()) if answers_now(flags) else True


def copy(a):
    """A copy of an array or a tensor."""
    return a.copy() if isinstance(a, np.ndarray) else a.clone()
