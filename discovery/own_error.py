"""The model's own error where the truth is known, for its card (`weights_schema.model_card.OwnError`).

A bundle trained on the reference world's flights is measured against that teacher: clean, calm launches from the
synthetic generator (several clubs, players and robots) flown through the bundle as the service flies it and
through the reference world, without measurement noise; the RMS difference per observable is the error
`golfflight diagnose` expects of the model itself. A bundle trained on real flights needs its held-out real sets
instead, with the launch monitor's noise taken out; this module does not guess that.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from golfflight.discovery.conceal import conceal
from golfflight.discovery.model import from_bundle
from golfflight.discovery.recordings import OBSERVABLES, from_shot_set
from golfflight.shots.files import write_text_atomic
from golfflight.shots.synth import MeasurementNoise
from golfflight.weights_schema.bundle import CARD_FILE
from golfflight.weights_schema.model_card import ModelCard, OwnError

NO_NOISE = MeasurementNoise(**{name: 0.0 for name in MeasurementNoise.__dataclass_fields__})

AGAINST = (
    "the reference world (its teacher; calibrated, RK4 at 0.1 s): clean calm launches of the synthetic generator in "
    "ICAO standard air, flown by the bundle as the service flies it, no measurement noise"
)


def measure_own_error(bundle_dir: str | os.PathLike, n_shots: int = 2000, seed: int = 0) -> OwnError:
    """RMS difference per observable between the bundle's flights and the reference world's on the same launches."""
    mine = from_shot_set(conceal({}, n_shots, seed, noise=NO_NOISE, model=from_bundle(bundle_dir)).shots)
    truth = from_shot_set(conceal({}, n_shots, seed, noise=NO_NOISE).shots)
    common, i, j = np.intersect1d(mine.shot_id, truth.shot_id, return_indices=True)
    difference = mine.observed[i] - truth.observed[j]
    sigma = {name: float(np.sqrt(np.nanmean(difference[:, k] ** 2))) for k, name in enumerate(OBSERVABLES)}
    return OwnError(sigma=sigma, measured_against=AGAINST, n_shots=len(common))


def write_own_error(bundle_dir: str | os.PathLike, own: OwnError) -> Path:
    """The bundle's card with `own` in it (schema 1.3); every other field as it was."""
    path = Path(bundle_dir) / CARD_FILE
    card = ModelCard.model_validate_json(path.read_text())
    updated = ModelCard.model_validate({**card.model_dump(mode="json"), "schema_version": "1.3", "own_error": own})
    write_text_atomic(path, json.dumps(updated.model_dump(mode="json"), indent=2) + "\n")
    return path
