"""The model as is on the recordings: its predictions (with a control's known error taken out), the residuals, the
wild readings left out of the fits, the error each shot is expected to miss by, and the recordings' own scatter.
What every diagnosis starts from, and what a baseline session's form is learned against (`discovery.form`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.discovery.model import FlightModel
from golfflight.discovery.noise import (
    ExpectedError,
    Scatter,
    base_conditions,
    expected_error,
    recording_scatter,
    with_discrepancy,
    with_scatter,
)
from golfflight.discovery.recordings import Recordings
from golfflight.discovery.simulator import Outcomes, Setup
from golfflight.shots.progress import progress_step
from golfflight.shots.synth import MeasurementNoise

OUTLIER_MAD = 8.0
"""A residual further than this many robust SDs from the median is a wild reading, left out of the fits."""


@dataclass(frozen=True)
class AsIs:
    """The model as is on the recordings: its predictions (the control's known error taken out), the residuals, the
    wild readings left out of the fits, the error each shot is expected to miss by and the recordings' own scatter."""

    base: Setup
    flown: Outcomes
    predicted: np.ndarray
    offset: np.ndarray
    residual: np.ndarray
    wild: np.ndarray
    use: np.ndarray
    expected: ExpectedError
    scatter: Scatter



def outlier_mask(residual: np.ndarray) -> np.ndarray:
    """True where a residual is a wild reading (far outside the bulk of its observable)."""
    out = np.zeros(residual.shape, dtype=bool)
    for j in range(residual.shape[1]):
        r = residual[:, j]
        finite = np.isfinite(r)
        if finite.sum() < 10:
            continue
        median = np.median(r[finite])
        mad = 1.4826 * np.median(np.abs(r[finite] - median))
        out[:, j] = finite & (np.abs(r - median) > OUTLIER_MAD * max(mad, 1e-9))
    return out


def as_is(
    recordings: Recordings,
    model: FlightModel,
    noise: MeasurementNoise,
    seed: int,
    estimate_scatter: bool,
    progress: bool = False,
) -> AsIs:
    """Fly the recorded launches through the model (and its control, or the discrepancy a baseline session taught),
    and measure how far off it is expected to be (with `progress`, the expected error's flights, five times the model's, are named as they start)."""
    base = base_conditions(recordings, model)
    flown = model.simulate(base, keep_positions=bool(recordings.trajectories))
    predicted = flown.outcomes()
    progress_step("the model's response to the launch monitor's noise (five more flights of every shot)...", progress)
    expected = expected_error(model, recordings, base, predicted, noise)
    offset = np.zeros_like(predicted)
    if model.control is not None:  # the model's known error on these launches, taken out of every prediction
        offset = np.nan_to_num(model.control.simulate(base).outcomes() - predicted)
    if model.discrepancy is not None:  # how sure the discrepancy a baseline session taught is at these launches
        expected = with_discrepancy(expected, model.discrepancy.predict(recordings.launch)[1])
    predicted = predicted + offset
    residual = recordings.observed - predicted
    wild = outlier_mask(residual)
    use = np.isfinite(residual) & np.isfinite(expected.sigma) & ~wild  # a shot the model does not land has none
    own_rng = np.random.default_rng([seed, 1])  # its own stream: the fits' draws stay as they were
    scatter = recording_scatter(recordings, np.where(use, residual / expected.sigma, np.nan), own_rng)
    if estimate_scatter:
        expected = with_scatter(expected, scatter)
    return AsIs(base, flown, predicted, offset, residual, wild, use, expected, scatter)
