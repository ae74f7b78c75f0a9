"""The validation split of a canonical file as records, model predictions on it and their errors (the paper's L_p and
L_h).

The shots are exactly those `model_export.data.load_training_data` validates on; `model_export.validation` adds
their float64 tensors for the torch rollout. Torch-free: the reference world and the runtime path need only these.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from golfflight.errors import InputError
from golfflight.shots.records import ShotSet, read_shots
from golfflight.shots.synth import MIN_APEX_M


@dataclass
class ValidationShots:
    """The validation shots (the file's 'val' rows after the training filters) as records, and all the file's rows."""

    path: Path
    shots: ShotSet
    all_shots: ShotSet

    def __len__(self) -> int:
        return len(self.shots)

    @property
    def landing_m(self) -> np.ndarray:
        """Recorded landing points [N,2] (x, y), NaN where not recorded."""
        return np.stack([self.shots.column("carry_x_m"), self.shots.column("carry_y_m")], axis=-1)

    @property
    def apex_m(self) -> np.ndarray:
        return self.shots.column("apex_m")


def validation_mask(shots: ShotSet, min_apex_m: float = MIN_APEX_M) -> np.ndarray:
    """The rows `model_export.data.load_training_data` validates on: marked 'val', with a landing point or an
    apex, and no recorded apex under `min_apex_m`."""
    landing_known = ~np.isnan(shots.column("carry_x_m")) & ~np.isnan(shots.column("carry_y_m"))
    apex = shots.column("apex_m")
    with np.errstate(invalid="ignore"):
        return (shots.column("split") == "val") & (landing_known | ~np.isnan(apex)) & ~(apex < min_apex_m)


def load_validation_shots(path: str | os.PathLike, min_apex_m: float = MIN_APEX_M) -> ValidationShots:
    """Read a canonical CSV and keep its validation shots."""
    path = Path(path)
    shots = read_shots(path)
    val = shots.subset(validation_mask(shots, min_apex_m))
    if not len(val):
        raise InputError(f"{path}: no validation shots (rows marked 'val' that pass the training filters)")
    return ValidationShots(path, val, shots)


@dataclass
class Prediction:
    """A model's landing points [N,2] and max heights [N] (None for the NN baseline) for the validation shots."""

    landing_m: np.ndarray
    apex_m: np.ndarray | None


@dataclass
class Errors:
    """Per-shot errors (prediction - recorded), NaN where the shot has no such target."""

    landing_m: np.ndarray
    length_m: np.ndarray
    side_m: np.ndarray
    apex_m: np.ndarray | None

    @property
    def mean_landing_m(self) -> float:
        """Mean landing-point distance: the paper's L_p."""
        return float(np.nanmean(self.landing_m))

    @property
    def mean_abs_apex_m(self) -> float | None:
        """Mean absolute max-height error: the paper's L_h."""
        return None if self.apex_m is None else float(np.nanmean(np.abs(self.apex_m)))


def errors_of(prediction: Prediction, val: ValidationShots) -> Errors:
    """Landing distance, length (y) and side (x) errors, and max-height error against the recorded outcomes."""
    difference = prediction.landing_m - val.landing_m
    apex = None if prediction.apex_m is None else prediction.apex_m - val.apex_m
    return Errors(np.linalg.norm(difference, axis=-1), difference[:, 1], difference[:, 0], apex)


def gap(prediction: Prediction, world: Prediction) -> tuple[float, float | None]:
    """Mean landing distance and mean absolute max-height difference between a model and the nominal reference
    world on the same launches: the model-form error, free of weather and outcome noise."""
    landing = float(np.nanmean(np.linalg.norm(prediction.landing_m - world.landing_m, axis=-1)))
    if prediction.apex_m is None or world.apex_m is None:
        return landing, None
    return landing, float(np.nanmean(np.abs(prediction.apex_m - world.apex_m)))
