"""Where torch runs: the `--device` of `train`, `train-real`, `finetune` and `sweep --engine torch`, refused in one
line where this machine lacks it (a GPU asked for where torch sees none)."""

from __future__ import annotations

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
