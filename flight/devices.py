"""Where torch runs: the `--device` of `train`, `train-real`, `finetune` and `sweep --engine torch`, refused in one
line where this machine lacks it (a GPU asked for where torch sees none)."""

from __future__ import annotations

import ctypes
import ctypes.util

import torch
from golfflight.errors import InputError

DEFAULT_DEVICE = "cpu"
"""Every command's device unless told otherwise: the CPU results are the ones the repository's numbers come from."""


class DeviceError(InputError):
    """A device this machine cannot run torch on (no GPU for cuda, an unknown name)."""


def resolve_device(name: str) -> torch.device:
    """The torch device called `name` ("cpu", "cuda", "cuda:1"), or DeviceError where it is not present."""
    try:
        device = torch.device(name)
    except RuntimeError:
        raise DeviceError(f"--device {name!r}: not a device name (cpu, cuda or cuda:N)") from None
    if device.type == "cpu":
        return device
    if device.type != "cuda":
        raise DeviceError(f"--device {name!r}: only cpu and cuda are supported")
    if not torch.cuda.is_available():
        raise DeviceError(f"--device {name}: this machine has no CUDA GPU that torch {torch.__version__} can use "
                          f"(torch.cuda.is_available() is False); use --device cpu")
    if device.index is not None and device.index >= torch.cuda.device_count():
        raise DeviceError(f"--device {name}: this machine has {torch.cuda.device_count()} CUDA GPUs")
    return device


M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
"""glibc's mallopt parameters (malloc.h)."""

KEPT_FREE_BYTES = 256 * 2**20
"""Freed memory glibc keeps for the process's next allocations, at most, once `keep_freed_memory` has run."""


def keep_freed_memory() -> bool:
    """Have glibc keep the CPU memory torch frees for its next allocations instead of handing it back to the system.

    Each Euler step of a part of 4,096 shots allocates and frees about 12 MB of the network's activations. glibc's
    default hands freed memory back once more than twice the largest block freed lies free at the heap's top, so the
    next step takes it back page by page from the kernel, zeroed: the torch engine on a CPU flew about 0.72 of its
    speed beside another process (an interleaved A/B during issue 44, docs/benchmarks.md). Process-wide: it keeps at
    most KEPT_FREE_BYTES free. False where the C library has no mallopt (not glibc)."""
    try:
        mallopt = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(M_TRIM_THRESHOLD, KEPT_FREE_BYTES)) and bool(mallopt(M_MMAP_THRESHOLD, 32 * 2**20))
