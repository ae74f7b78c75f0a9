"""Trajectories for a renderer: the integrator's states resampled at a fixed rate.

Between two integrator states the position is the cubic Hermite curve through both positions with both
velocities as its end tangents, so the path is smooth (C1) and the ball's speed along it is right, where
joining the 0.1 s states with straight lines would show kinks at every step.
"""

from __future__ import annotations

import numpy as np
from golfflight.flight.engine import EulerStates


def resample(
    states: EulerStates, rate_hz: float, keep_times_s: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Times [M] (0, 1/rate, ... then the last state's time) and positions [M,3] on the Hermite curve of the
    states; `keep_times_s` (state times: the landing, each impact, the rest) are sampled too, so the curve passes
    exactly through those states rather than cutting their corners."""
    times, positions, velocities = states.times_s, states.positions, states.velocities
    landing_time = float(times[-1])
    samples = np.arange(int(np.floor(landing_time * rate_hz + 1e-9)) + 1) / rate_hz
    if samples[-1] < landing_time - 1e-9:
        samples = np.append(samples, landing_time)
    if keep_times_s is not None:
        samples = np.union1d(samples, keep_times_s)
    segment = np.clip(np.searchsorted(times, samples, side="right") - 1, 0, len(times) - 2)
    t0, t1 = times[segment], times[segment + 1]
    h = (t1 - t0)[:, None]
    s = ((samples - t0) / (t1 - t0))[:, None]
    s2, s3 = s * s, s * s * s
    return samples, (
        (2 * s3 - 3 * s2 + 1) * positions[segment]
        + (s3 - 2 * s2 + s) * h * velocities[segment]
        + (-2 * s3 + 3 * s2) * positions[segment + 1]
        + (s3 - s2) * h * velocities[segment + 1]
    )
