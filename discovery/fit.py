"""Fit effects through the full simulator and score them on held-out sessions.

Residuals are standardized (recorded - model) / expected sigma over every observed outcome, so carry, apex,
time and angle weigh by how well each is known. The optimiser is scipy's bounded least squares with a Jacobian
built from finite differences flown as ONE stacked batch. Held-out error: folds grouped by session; each fold's
parameters are one Gauss-Newton step from the all-data fit using only the other folds' residuals and Jacobian,
within the parameters' bounds (exact for a locally linear problem, and cheap), then the held-out shots are flown
with them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.discovery.effects import Effect, apply_all
from golfflight.discovery.model import FlightModel
from golfflight.discovery.recordings import OBSERVABLES, Recordings
from golfflight.discovery.simulator import Outcomes, Setup
from scipy.optimize import least_squares, lsq_linear

MISSED_LANDING_Z = 10.0
"""Standardized residual given to a shot the model does not land (it cannot be compared)."""

MAX_FIT_SHOTS = 600
"""Effects are fitted on at most this many shots (spread over sessions); held-out scoring uses every shot."""

SCORED_SHOTS = 5_000
"""Candidates are scored (Jacobian, covariance, held-out error) on at most this many shots, a stratified subsample of
larger sets (`stratified_rows`); the systematic test and the chosen explanation's held-out errors use every shot.
Each candidate costs about (2 + k) flights of its scored shots, so this bounds a 100,000-shot diagnosis; with every
session represented the session-clustered uncertainties grow by far less than sqrt(N / SCORED_SHOTS)
(docs/discovery.md, "Scale")."""

MAX_EVALUATIONS = 12


@dataclass
class Problem:
    """Recordings, the conditions the model assumes for them, expected sigmas, the entries that count and the
    model's known error on each shot (`offset` [N, 5], added to every prediction; zero without a control)."""

    model: FlightModel
    recordings: Recordings
    base: Setup
    sigma: np.ndarray
    use: np.ndarray
    offset: np.ndarray

    @property
    def observed(self) -> np.ndarray:
        return self.recordings.observed

    def outcomes(
        self,
        effects: tuple[Effect, ...],
        theta_rows: np.ndarray,
        rows: np.ndarray,
        keep_positions: bool = False,
        model: FlightModel | None = None,
    ) -> Outcomes:
        """Fly shots `rows` (may repeat) with per-row parameters theta_rows [M, k] through the diagnosed model (or
        `model`, e.g. its control); returns the Outcomes batch."""
        conditions = apply_all(effects, theta_rows, self.base.take(rows))
        correction = next((e.correction for e in effects if e.correction is not None), None)
        return (model or self.model).simulate(conditions, correction, keep_positions)

    def predict(self, effects: tuple[Effect, ...], thetas: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Outcomes [B, len(rows), 5] of B parameter sets [B, k], all flown in one batch."""
        thetas = np.atleast_2d(thetas)
        theta_rows = np.repeat(thetas, len(rows), axis=0)
        flown = self.outcomes(effects, theta_rows, np.tile(rows, len(thetas)))
        return flown.outcomes().reshape(len(thetas), len(rows), len(OBSERVABLES)) + self.offset[rows]

    def subset(self, rows: np.ndarray) -> Problem:
        """The same problem restricted to the shots at `rows`."""
        return Problem(
            self.model,
            self.recordings.subset(rows),
            self.base.take(rows),
            self.sigma[rows],
            self.use[rows],
            self.offset[rows],
        )

    def shared_information(self, z: np.ndarray, jacobian: np.ndarray) -> np.ndarray | None:
        """What the model's error shared between shots adds to J'J (`Discrepancy.shared_information`): only a model
        with a baseline's discrepancy says how its error is shared; None otherwise."""
        discrepancy = self.model.discrepancy
        if discrepancy is None or jacobian.shape[-1] == 0:
            return None
        weights = np.where(np.isfinite(z)[..., None], jacobian / self.sigma[..., None], 0.0)
        return discrepancy.shared_information(self.recordings.launch, weights, np.random.default_rng(5))

    def standardize(self, predicted: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(recorded - predicted) / sigma [..., len(rows), 5]; NaN where unused, a large value where not landed."""
        z = (self.observed[rows] - predicted) / self.sigma[rows]
        z = np.where(np.isnan(predicted), MISSED_LANDING_Z, z)
        return np.where(self.use[rows], z, np.nan)


@dataclass
class Fit:
    """Fitted internal parameters of a candidate with the residuals [N, 5] and Jacobian [N, 5, k] on all shots."""

    effects: tuple[Effect, ...]
    theta: np.ndarray
    z: np.ndarray
    jacobian: np.ndarray
    covariance: np.ndarray

    @property
    def name(self) -> str:
        return "+".join(e.name for e in self.effects) or "none"

    @property
    def k(self) -> int:
        return len(self.theta)


@dataclass
class Scored:
    """A fitted candidate with its held-out standardized residuals [N, 5], held-out error and penalty."""

    fit: Fit
    heldout_z: np.ndarray
    error: float
    penalty: float

    @property
    def score(self) -> float:
        return self.error + self.penalty


def per_shot(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sum of z^2, number of used entries) per shot."""
    used = np.isfinite(z)
    return np.where(used, z**2, 0.0).sum(axis=1), used.sum(axis=1).astype(float)


def blocks(result: Fit) -> list[tuple[Effect, slice]]:
    """Each effect of a fit with its parameters' place in the fit's parameter vector."""
    out, start = [], 0
    for effect in result.effects:
        out.append((effect, slice(start, start + effect.size)))
        start += effect.size
    return out


def _bounds(effects: tuple[Effect, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    params = [p for e in effects for p in e.parameters]
    return (
        np.array([p.low for p in params]),
        np.array([p.high for p in params]),
        np.array([p.typical for p in params]),
        np.array([p.step for p in params]),
    )


def residuals_and_jacobian(
    problem: Problem, effects: tuple[Effect, ...], theta: np.ndarray, rows: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """z [n, 5] at theta and its Jacobian dz/dtheta [n, 5, k] by forward differences, flown as one batch."""
    _, high, _, step = _bounds(effects)
    k = len(theta)
    h = np.where(theta + step <= high, step, -step)
    thetas = np.vstack([theta, theta + np.diag(h)]) if k else theta[None]
    z = problem.standardize(problem.predict(effects, thetas, rows), rows)
    jacobian = np.moveaxis((z[1:] - z[:1]) / h[:, None, None], 0, -1) if k else np.zeros(z.shape[1:] + (0,))
    return z[0], jacobian


def covariance(
    z: np.ndarray, jacobian: np.ndarray, groups: np.ndarray, shared: np.ndarray | None = None
) -> np.ndarray:
    """Parameter covariance from the Jacobian: s^2 (J'J)^-1, or s^2 (J'J)^-1 (J'J + shared) (J'J)^-1 where the model's
    error is shared between shots (`shared`, `Problem.shared_information`), or the session-clustered sandwich (5+
    sessions) when that is larger on average (shots of a session share conditions, so they may not be
    independent)."""
    used = np.isfinite(z)
    k = jacobian.shape[-1]
    if k == 0:
        return np.zeros((0, 0))
    J = np.where(used[..., None], jacobian, 0.0)
    r = np.where(used, z, 0.0)
    flat_j = J.reshape(-1, k)
    bread = np.linalg.pinv(flat_j.T @ flat_j)
    m = used.sum()
    codes = np.unique(groups, return_inverse=True)[1]
    g = codes.max() + 1
    classical = bread * float(np.sum(r**2) / max(m - k, 1))
    if shared is not None:
        classical = classical @ (flat_j.T @ flat_j + shared) @ bread
    if g < 5:
        return classical
    scores = np.zeros((g, k))
    np.add.at(scores, codes, np.einsum("nok,no->nk", J, r))
    sandwich = bread @ (scores.T @ scores * g / (g - 1)) @ bread
    inflation = np.mean(np.diag(sandwich) / np.maximum(np.diag(classical), 1e-300))
    return sandwich if inflation >= 1.0 else classical


def held_nuisance_covariance(
    z: np.ndarray, jacobian: np.ndarray, nuisance_jacobian: np.ndarray, nuisance_covariance: np.ndarray
) -> np.ndarray:
    """What a nuisance estimated first, on other data, and then held adds to a least-squares fit's covariance: the
    fit moves with the nuisance's error as G = -(J'J)^-1 J'J_n (J, J_n: dz/dtheta [N,5,k], dz/dnuisance [N,5,m]), so
    it adds G Cov_n G' (Murphy & Topel 1985; no cross term, the two data sets being independent)."""
    used = np.isfinite(z)
    k, m = jacobian.shape[-1], nuisance_jacobian.shape[-1]
    J = np.where(used[..., None], jacobian, 0.0).reshape(-1, k)
    J_n = np.where(used[..., None], nuisance_jacobian, 0.0).reshape(-1, m)
    moves = -np.linalg.pinv(J.T @ J) @ (J.T @ J_n)
    return moves @ nuisance_covariance @ moves.T


def linear_starts(
    problem: Problem, base: Fit | None, additions: tuple[Effect, ...], rows: np.ndarray
) -> list[tuple[np.ndarray, float]]:
    """For each effect added to `base`: a Gauss-Newton start for base + effect and its linearised cost, all from
    one Jacobian of base plus every addition at their current values (one stacked batch)."""
    base_effects = base.effects if base is not None else ()
    base_theta = base.theta if base is not None else np.zeros(0)
    effects = base_effects + additions
    theta = np.concatenate([base_theta] + [e.null for e in additions])
    z, jacobian = residuals_and_jacobian(problem, effects, theta, rows)
    used = np.isfinite(z)
    r, J = z[used], jacobian[used]
    low, high, _, _ = _bounds(effects)
    k_base = len(base_theta)
    out, start = [], k_base
    for effect in additions:
        columns = np.r_[np.arange(k_base), np.arange(start, start + effect.size)]
        step = np.linalg.lstsq(J[:, columns], -r, rcond=None)[0]
        cost = float(np.sum((r + J[:, columns] @ step) ** 2))
        guess = np.clip(theta[columns] + step, low[columns], high[columns])
        out.append((guess, cost))
        start += effect.size
    return out


def fit_rows(recordings: Recordings, rng: np.random.Generator, limit: int = MAX_FIT_SHOTS) -> np.ndarray:
    """At most `limit` shots for fitting, the same share of every session."""
    n = len(recordings)
    if n <= limit:
        return np.arange(n)
    return np.sort(rng.choice(n, size=limit, replace=False))


def stratified_rows(recordings: Recordings, size: int, rng: np.random.Generator) -> np.ndarray:
    """`size` shots (all of them if there are no more) spread over every session and club in proportion: a systematic
    sample, from a random start, through the shots ordered by session, club and a random key, so each session-club
    stratum of n shots gets n x size / N of them (rounded one way or the other) and no session is left out whose
    shots number at least N / size. Sorted indices."""
    n = len(recordings)
    if n <= size:
        return np.arange(n)
    order = np.lexsort((rng.random(n), recordings.club, recordings.session))
    picks = np.floor(rng.random() * n / size + np.arange(size) * n / size).astype(int)
    return np.sort(order[np.minimum(picks, n - 1)])


def fitted_parameters(
    problem: Problem, effects: tuple[Effect, ...], start: np.ndarray, rows: np.ndarray
) -> tuple[np.ndarray, dict[bytes, tuple[np.ndarray, np.ndarray]]]:
    """Least-squares parameters of the effects on `rows` from `start`, within their bounds, and the (z, Jacobian) on
    `rows` at each parameter set tried."""
    low, high, typical, _ = _bounds(effects)
    theta = np.clip(start, low, high)
    flown: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
    if not len(theta):
        return theta, flown

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = x.tobytes()
        if key not in flown:
            flown[key] = residuals_and_jacobian(problem, effects, x, rows)
        z, jac = flown[key]
        used = np.isfinite(z)
        return z[used], jac[used]

    result = least_squares(
        lambda x: evaluate(x)[0],
        theta,
        jac=lambda x: evaluate(x)[1],
        bounds=(low, high),
        x_scale=typical,
        method="trf",
        max_nfev=MAX_EVALUATIONS,
        xtol=1e-3,
        ftol=1e-4,
    )
    return result.x, flown


def fit(problem: Problem, effects: tuple[Effect, ...], start: np.ndarray, rows: np.ndarray) -> Fit:
    """Least-squares fit of the effects' parameters on `rows`, then residuals and Jacobian on every shot."""
    theta, flown = fitted_parameters(problem, effects, start, rows)
    if len(rows) == len(problem.recordings) and theta.tobytes() in flown:
        return fit_at(problem, effects, theta, flown[theta.tobytes()])
    return fit_at(problem, effects, theta)


def fit_at(
    problem: Problem,
    effects: tuple[Effect, ...],
    theta: np.ndarray,
    flown: tuple[np.ndarray, np.ndarray] | None = None,
) -> Fit:
    """The effects at `theta` as a Fit: residuals, Jacobian and covariance on every shot (`flown`: the residuals and
    Jacobian on every shot where already flown)."""
    everyone = np.arange(len(problem.recordings))
    z, jacobian = flown if flown is not None else residuals_and_jacobian(problem, effects, theta, everyone)
    shared = problem.shared_information(z, jacobian)
    return Fit(effects, theta, z, jacobian, covariance(z, jacobian, problem.recordings.session, shared))


def folds(groups: np.ndarray, n_folds: int = 5) -> tuple[np.ndarray, str]:
    """Fold index per shot: whole sessions per fold (balanced greedily) with 3+ sessions, else blocks of shots."""
    labels, codes, counts = np.unique(groups, return_inverse=True, return_counts=True)
    if labels.size >= 3:
        k = min(n_folds, labels.size)
        load = np.zeros(k)
        assignment = np.zeros(labels.size, dtype=int)
        for g in np.argsort(-counts, kind="stable"):
            assignment[g] = int(np.argmin(load))
            load[assignment[g]] += counts[g]
        return assignment[codes], f"session ({k} folds of whole sessions)"
    n = groups.size
    k = min(n_folds, n) if n > 20 else n
    return (np.arange(n) * k // n), ("shot blocks in recorded order" if k < n else "leave one shot out")


def fold_thetas(result: Fit, fold: np.ndarray) -> dict[int, np.ndarray]:
    """Each fold's parameters: one Gauss-Newton step from the fit using only the other folds' residuals and Jacobian,
    solved within the parameters' bounds (`fold` gives the fold of each shot the fit's residuals are on). An
    unbounded step clipped afterwards can land far from the fold's own best where parameters are nearly collinear
    and the fit sits at a bound."""
    low, high, _, _ = _bounds(result.effects)
    used = np.isfinite(result.z)
    thetas = {}
    for f in np.unique(fold):
        train = used & (fold != f)[:, None]
        J, r = result.jacobian[train], result.z[train]
        if len(r) <= result.k:
            thetas[int(f)] = result.theta
            continue
        step = lsq_linear(J, -r, bounds=(low - result.theta, high - result.theta)).x
        thetas[int(f)] = np.clip(result.theta + step, low, high)
    return thetas


def heldout(problem: Problem, result: Fit, fold: np.ndarray, thetas: dict[int, np.ndarray] | None = None) -> np.ndarray:
    """Held-out standardized residuals [N, 5]: each fold flown with parameters fitted without it (`thetas`, by
    default `fold_thetas` of the fit itself; a fold without any keeps the fit's parameters, which never saw it)."""
    if result.k == 0:
        return result.z
    thetas = fold_thetas(result, fold) if thetas is None else thetas
    theta_rows = np.repeat(result.theta[None], len(fold), axis=0)
    for f, theta in thetas.items():
        theta_rows[fold == f] = theta
    everyone = np.arange(len(fold))
    predicted = problem.outcomes(result.effects, theta_rows, everyone).outcomes() + problem.offset
    return problem.standardize(predicted, everyone)


def cluster_bootstrap(
    numerator: np.ndarray, denominator: np.ndarray, groups: np.ndarray, rng: np.random.Generator, draws: int = 2000
) -> np.ndarray:
    """Bootstrap draws of sum(numerator) / sum(denominator), resampling whole groups (shots if only one group)."""
    codes = np.unique(groups, return_inverse=True)[1]
    g = codes.max() + 1
    if g < 5:
        codes, g = np.arange(len(groups)), len(groups)
    num = np.bincount(codes, weights=numerator, minlength=g)
    den = np.bincount(codes, weights=denominator, minlength=g)
    pick = rng.integers(0, g, size=(draws, g))
    weights = np.zeros((draws, g))
    np.add.at(weights, (np.repeat(np.arange(draws), g), pick.ravel()), 1.0)
    return (weights @ num) / np.maximum(weights @ den, 1e-12)
