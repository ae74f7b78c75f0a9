"""The model discrepancy a baseline session teaches beyond its learned form (Kennedy & O'Hagan 2001): per observable,
a Gaussian process over the recorded launch, fitted to the residuals the form leaves, its mean added to every
prediction and its variance to every shot's expected error.

Near the baseline's launches the mean carries what the form's coefficients could not (a forward-Euler model's own
step error, say) and the variance is small; far from them the mean fades to zero and the variance grows to the whole
discrepancy the baseline showed: a new session's shots outside the baseline are expected to miss by that much
(`discovery.reach` says which they are).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from golfflight.discovery.recordings import OBSERVABLES
from golfflight.discovery.simulator import Outcomes
from scipy.linalg import cho_solve, solve_triangular

INPUTS: tuple[str, ...] = ("ball_speed_mps", "launch_angle_deg", "spin_rpm", "spin_axis_deg")
"""The launch values the discrepancy depends on (the launch direction only turns a flight about the vertical)."""
LENGTHSCALES = (0.5, 1.0, 2.0)
"""Candidate length scales, in standard deviations of the baseline's launch values."""
AMPLITUDES = (0.1, 0.3, 1.0, 2.0)
"""Candidate amplitudes, as shares of the residuals' standard deviation."""
MAX_POINTS = 1000
"""At most this many baseline shots condition each process's mean (a random share): its cost grows as their cube."""
SEARCH_POINTS = 300
"""The length scale and amplitude are chosen on this many of them (twelve candidates, each a Cholesky factor)."""
MAX_SD_POINTS = 300
"""The SD is read from the process conditioned on the first this many of them: a triangular solve per shot costs
their square, and fewer points only widen the SD (a new session's 100,000 shots in seconds)."""
CHUNK = 10_000
"""Shots whose kernel rows are built at once (a chunk of 10,000 against 1,000 points is 80 MB)."""
CACHED = 4
"""Launch sets whose discrepancy means are kept: a fit's shots, its held-out shots and the whole set."""
SHARED_POINTS = 1000
"""At most this many shots (a random share) estimate how the discrepancy's error is shared between shots
(`Discrepancy.shared_information`), about 70 times a diagnosis: the pairs cost their square, and a random 1,000 of
a larger set's shots estimate them without bias (tests/test_shared_error.py)."""


def _kernel(a: np.ndarray, b: np.ndarray, lengthscale: float) -> np.ndarray:
    squared = (a**2).sum(1)[:, None] + (b**2).sum(1)[None, :] - 2.0 * a @ b.T
    return np.exp(-0.5 * np.maximum(squared, 0.0) / lengthscale**2)


def _chunked(z: np.ndarray, read: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    return np.concatenate([read(z[start : start + CHUNK]) for start in range(0, len(z), CHUNK)]) if len(z) else z[:, 0]


@dataclass(frozen=True)
class Process:
    """One observable's Gaussian process: its conditioning points, weights, Cholesky factor and hyperparameters."""

    points: np.ndarray
    weights: np.ndarray
    sd_cholesky: np.ndarray
    """The Cholesky factor of the first MAX_SD_POINTS points' covariance (with their noise)."""
    lengthscale: float
    amplitude: float

    def mean(self, z: np.ndarray) -> np.ndarray:
        """Mean [N] at standardized launches z [N, len(INPUTS)]."""
        if not len(self.points):
            return np.zeros(len(z))
        return _chunked(z, lambda part: self.amplitude**2 * _kernel(part, self.points, self.lengthscale) @ self.weights)

    def sd(self, z: np.ndarray) -> np.ndarray:
        """SD [N] at standardized launches z (a triangular solve per shot: what the mean alone does not need)."""
        if not len(self.points):
            return np.zeros(len(z))
        points = self.points[: len(self.sd_cholesky)]

        def read(part: np.ndarray) -> np.ndarray:
            cross = self.amplitude**2 * _kernel(part, points, self.lengthscale)
            solved = solve_triangular(self.sd_cholesky, cross.T, lower=True)
            return np.sqrt(np.maximum(self.amplitude**2 - (solved**2).sum(axis=0), 0.0))

        return _chunked(z, read)

    def shared(self, z: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """sum over pairs i != j of weights_i' C_ij weights_j [k, k], C the process's posterior covariance between
        the shots at standardized launches z [n, 4] (weights [n, k]): what the error the shots share adds."""
        if not len(self.points):
            return np.zeros((weights.shape[1],) * 2)
        cross = self.amplitude**2 * _kernel(z, self.points[: len(self.sd_cholesky)], self.lengthscale)
        solved = solve_triangular(self.sd_cholesky, cross.T, lower=True)
        projected = solved @ weights
        every = self.amplitude**2 * weights.T @ _kernel(z, z, self.lengthscale) @ weights - projected.T @ projected
        own_sd2 = np.maximum(self.amplitude**2 - (solved**2).sum(axis=0), 0.0)
        return every - (weights * own_sd2[:, None]).T @ weights


def _likelihood(points: np.ndarray, y: np.ndarray, noise: np.ndarray, lengthscale: float, amplitude: float) -> float:
    cholesky = np.linalg.cholesky(amplitude**2 * _kernel(points, points, lengthscale) + np.diag(noise**2))
    return float(-0.5 * y @ cho_solve((cholesky, True), y) - np.log(np.diag(cholesky)).sum())


def fit_process(
    z: np.ndarray,
    residual: np.ndarray,
    noise_sd: np.ndarray,
    rng: np.random.Generator,
    hyper: tuple[float, float] | None = None,
) -> Process:
    """The process conditioned on the shots with a residual (at most MAX_POINTS of them, in random order), its length
    scale and amplitude those of highest marginal likelihood among the candidates on the first SEARCH_POINTS of them
    (or `hyper`, another process's); none where fewer than 10 shots have a residual."""
    used = np.flatnonzero(np.isfinite(residual) & np.isfinite(noise_sd))
    if len(used) < 10:
        return Process(np.zeros((0, z.shape[1])), np.zeros(0), np.zeros((0, 0)), 1.0, 0.0)
    used = rng.permutation(used)[:MAX_POINTS]
    points, y, noise = z[used], residual[used], noise_sd[used]
    if hyper is None:
        spread = float(np.std(y)) or 1.0
        search = slice(0, SEARCH_POINTS)
        hyper = max(
            ((lengthscale, share * spread) for lengthscale in LENGTHSCALES for share in AMPLITUDES),
            key=lambda h: _likelihood(points[search], y[search], noise[search], *h),
        )
    lengthscale, amplitude = hyper
    covariance = amplitude**2 * _kernel(points, points, lengthscale) + np.diag(noise**2)
    weights = cho_solve((np.linalg.cholesky(covariance), True), y)
    sd_cholesky = np.linalg.cholesky(covariance[:MAX_SD_POINTS, :MAX_SD_POINTS])
    return Process(points, weights, sd_cholesky, lengthscale, amplitude)


@dataclass(frozen=True)
class Discrepancy:
    """The baseline's discrepancy per observable over its standardized launches."""

    centre: np.ndarray
    scale: np.ndarray
    processes: tuple[Process, ...]
    """One per observable, in OBSERVABLES order."""
    recent: dict[bytes, np.ndarray] = field(default_factory=dict, compare=False, repr=False)
    """The means of the last CACHED launch sets read, by their standardized values."""

    def standardized(self, launch: dict[str, np.ndarray]) -> np.ndarray:
        return (np.stack([launch[k] for k in INPUTS], axis=1) - self.centre) / self.scale

    def mean(self, launch: dict[str, np.ndarray]) -> np.ndarray:
        """Mean [N,5] of the discrepancy at launches, read once for each distinct launch and kept for the last
        CACHED launch sets (a fit flies the same shots under many parameter sets, most of which leave the launch)."""
        z = self.standardized(launch)
        key = z.tobytes()
        if key not in self.recent:
            distinct, inverse = np.unique(z, axis=0, return_inverse=True)
            means = np.stack([process.mean(distinct) for process in self.processes], axis=1)
            self.recent[key] = means[inverse.reshape(-1)]
            self.recent[key].flags.writeable = False
            while len(self.recent) > CACHED:
                self.recent.pop(next(iter(self.recent)))
        return self.recent[key]

    def predict(self, launch: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Mean and SD [N,5] of the discrepancy at launches."""
        z = self.standardized(launch)
        return self.mean(launch), np.stack([process.sd(z) for process in self.processes], axis=1)

    def shared_information(
        self, launch: dict[str, np.ndarray], weights: np.ndarray, rng: np.random.Generator
    ) -> np.ndarray:
        """What the discrepancy's error, shared by shots at nearby launches, adds to J'J [k, k] beyond independent
        errors: sum over observables and pairs of shots of weights_i' C_ij weights_j, weights [N, 5, k] the Jacobian
        over each shot's expected error (zero where unused), C the posterior covariance between the two shots'
        discrepancies. A shot's own error is already in its expected error; counting it once per shot, as if shots
        erred independently, made the baseline's parameters 2-4 times too sure (docs/discovery.md). Above
        SHARED_POINTS shots, the pairs of a random share, scaled to all pairs."""
        n = len(weights)
        rows = np.arange(n) if n <= SHARED_POINTS else np.sort(rng.choice(n, SHARED_POINTS, replace=False))
        m = len(rows)
        z = self.standardized({k: v[rows] for k, v in launch.items()})
        total = sum(process.shared(z, weights[rows, j]) for j, process in enumerate(self.processes))
        return total * (n * (n - 1)) / max(m * (m - 1), 1)

    def shifted(self, flown: Outcomes, launch: dict[str, np.ndarray]) -> Outcomes:
        """A batch's outcomes with the discrepancy's mean at its flown launches added (positions left as flown)."""
        mean = self.mean(launch)
        landing = flown.landing_xy + mean[:, [1, 0]]
        return Outcomes(landing, flown.apex_m + mean[:, 2], flown.flight_time_s + mean[:, 3],
                        flown.landing_angle_deg + mean[:, 4], flown.positions, flown.dt_s)


def fit_discrepancy(
    launch: dict[str, np.ndarray],
    residual: np.ndarray,
    noise_sd: np.ndarray,
    seed: int = 0,
    like: Discrepancy | None = None,
) -> Discrepancy:
    """The discrepancy of residuals [N,5] with each shot's expected noise SD [N,5], over the recorded launches (with
    the length scales and amplitudes of `like`, where given: a held-out fold's)."""
    values = np.stack([launch[k] for k in INPUTS], axis=1)
    centre, scale = values.mean(axis=0), values.std(axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    z = (values - centre) / scale
    rng = np.random.default_rng([seed, 4])
    hypers = [None] * len(OBSERVABLES) if like is None else [(p.lengthscale, p.amplitude) for p in like.processes]
    processes = tuple(
        fit_process(z, residual[:, j], noise_sd[:, j], rng, hypers[j]) for j in range(len(OBSERVABLES))
    )
    return Discrepancy(centre, scale, processes)
