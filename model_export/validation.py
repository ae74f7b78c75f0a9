"""The validation shots of a canonical file with their float64 tensors, for the torch rollout (`model_export.evaluate`);
the records, predictions and errors are torch-free in `evaluation.validation`."""

from __future__ import annotations

import os
from dataclasses import dataclass

import torch
from golfflight.evaluation.validation import ValidationShots, load_validation_shots
from golfflight.model_export.data import MIN_APEX_M, ShotTensors, to_tensors


@dataclass
class ValidationSet(ValidationShots):
    """`ValidationShots` and the same shots as float64 tensors."""

    tensors: ShotTensors


def load_validation(path: str | os.PathLike, min_apex_m: float = MIN_APEX_M) -> ValidationSet:
    """Read a canonical CSV and keep its validation shots, as records and as float64 tensors."""
    val = load_validation_shots(path, min_apex_m)
    return ValidationSet(val.path, val.shots, val.all_shots, to_tensors(val.shots, torch.float64))
