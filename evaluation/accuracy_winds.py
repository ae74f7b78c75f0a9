"""Latent winds: each measured tour flight's own uniform wind, fitted with a model held fixed, and whether the fits
agree between players on the same hole and round (they would, if what they absorb were the weather).

A shot's wind (x right, y down the target line, m/s) is the least-squares fit of the model's positions to the
radar's, at the integrator's own step times up to the radar-tracked time (beyond it the polynomial is TrackMan's
extrapolation). Every shot is fitted at once: one batched flight per evaluation, the Jacobian block-diagonal (a
shot's wind moves only its own positions), so scipy's finite differences need two extra flights per Jacobian.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.flight.flyer import Flyer
from golfflight.flight.wind import Wind
from scipy import sparse
from scipy.optimize import least_squares
from scipy.stats import f as f_distribution

TRAINING_CONDITIONS_FILE = "training_conditions.json"
"""Written beside a bundle by the real-data training pipeline: the per-group winds (and air, ball) it learned."""

WIND_BOUND_MPS = 25.0
"""A fitted wind component stays within +-25 m/s (a gale); real tee-shot winds are a few m/s."""

NEVER_LANDS_M = -1.0e4
"""Ground height for the fit's flights: every ball flies to the last fitted time, so every shot has its positions."""

SHOT_ID = re.compile(r"^(?P<tournament>[^-]+)-R(?P<round>\d+)-H(?P<hole>\d+)-P")


def group_of(shot_id: str) -> str | None:
    """'016-R1-H3' for a TOURCAST shot id '016-R1-H3-P12345-S1' (the shots that shared one hole in one round)."""
    match = SHOT_ID.match(shot_id)
    return None if match is None else f"{match['tournament']}-R{match['round']}-H{match['hole']}"


def round_of(group: str) -> str:
    return group.rsplit("-H", 1)[0]


@dataclass
class MeasuredPaths:
    """Measured positions (relative to the start) at the integrator's step times k dt, k = 1..K: [K, N, 3], NaN after
    a shot's radar-tracked time; with each shot's launch."""

    shot_ids: list[str]
    launch: dict[str, np.ndarray]
    dt_s: float
    positions: np.ndarray

    @property
    def times_s(self) -> np.ndarray:
        return self.dt_s * np.arange(1, self.positions.shape[0] + 1)

    @property
    def counts(self) -> np.ndarray:
        """Measured steps per shot."""
        return np.isfinite(self.positions[..., 0]).sum(axis=0)


def measured_paths(
    shot_ids: Sequence[str],
    launch: dict[str, np.ndarray],
    trajectories: Mapping[str, np.ndarray],
    tracked_s: Mapping[str, float],
    dt_s: float,
) -> MeasuredPaths:
    """Sample each trajectory [T, 4] (t, x, y, z relative to the start) at k dt up to its tracked time (and landing)."""
    ends = np.array([min(tracked_s[s], trajectories[s][-1, 0]) for s in shot_ids])
    steps = int(np.floor(ends.max() / dt_s + 1e-9)) if len(ends) else 0
    times = dt_s * np.arange(1, steps + 1)
    positions = np.full((steps, len(shot_ids), 3), np.nan)
    for j, shot_id in enumerate(shot_ids):
        path = trajectories[shot_id]
        inside = times <= ends[j] + 1e-9
        for axis in range(3):
            positions[inside, j, axis] = np.interp(times[inside], path[:, 0], path[:, axis + 1])
    return MeasuredPaths(list(shot_ids), launch, dt_s, positions)


def _model_positions(flyer: Flyer, paths: MeasuredPaths, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    steps = paths.positions.shape[0]
    wind = Wind.from_components(x, y)
    flight = flyer.flight(launch_problem(paths.launch, wind=wind, keep_states=True, max_time_s=steps * paths.dt_s,
                                         ground_height_m=NEVER_LANDS_M))
    start = flight.states[0].position
    return np.stack([s.position for s in flight.states[1 : steps + 1]]) - start[None]


@dataclass
class WindFit:
    """Per-shot fitted uniform wind (m/s) and the RMS position error (m) calm and with the fitted wind."""

    shot_ids: list[str]
    x_mps: np.ndarray
    y_mps: np.ndarray
    rms_calm_m: np.ndarray
    rms_fit_m: np.ndarray
    evaluations: int

    @property
    def groups(self) -> np.ndarray:
        return np.array([group_of(s) or "" for s in self.shot_ids], dtype=object)


def _rms(residual: np.ndarray, counts: np.ndarray) -> np.ndarray:
    return np.sqrt(np.nansum(residual**2, axis=(0, 2)) / np.maximum(3 * counts, 1))


def fit_winds(flyer: Flyer, paths: MeasuredPaths, max_evaluations: int = 60, step_mps: float = 0.01) -> WindFit:
    """Each shot's uniform wind minimising its squared position errors over its measured steps, the model fixed.

    The Jacobian is taken by forward differences of `step_mps` (all shots' x components at once, then all y): a
    step near scipy's default (1e-8 of the value, or of 1 at zero) is lost in the float32 inputs of an ONNX graph."""
    n, steps = len(paths.shot_ids), paths.positions.shape[0]
    measured = paths.positions
    valid = np.isfinite(measured)
    rows = np.arange(n * 3 * steps)
    pattern_rows = np.repeat(rows, 2)
    pattern_cols = (2 * (pattern_rows // (3 * steps)) + np.tile([0, 1], len(rows))) if n else pattern_rows

    def residual(theta: np.ndarray) -> np.ndarray:
        wind = theta.reshape(n, 2)
        difference = _model_positions(flyer, paths, wind[:, 0], wind[:, 1]) - measured
        return np.where(valid, difference, 0.0).transpose(1, 0, 2).reshape(-1)

    def jacobian(theta: np.ndarray) -> sparse.csr_matrix:
        base = residual(theta)
        columns = []
        for axis in (0, 1):
            moved = theta.reshape(n, 2).copy()
            moved[:, axis] += step_mps
            columns.append((residual(moved.reshape(-1)) - base) / step_mps)
        data = np.stack(columns, axis=1).reshape(-1)
        return sparse.csr_matrix((data, (pattern_rows, pattern_cols)), shape=(len(rows), 2 * n))

    calm = _model_positions(flyer, paths, np.zeros(n), np.zeros(n)) - measured
    solution = least_squares(
        residual,
        np.zeros(2 * n),
        jac=jacobian,
        bounds=(-WIND_BOUND_MPS, WIND_BOUND_MPS),
        x_scale=1.0,
        tr_solver="lsmr",
        max_nfev=max_evaluations,
    )
    wind = solution.x.reshape(n, 2)
    fitted = solution.fun.reshape(n, steps, 3).transpose(1, 0, 2)
    return WindFit(
        list(paths.shot_ids),
        wind[:, 0],
        wind[:, 1],
        _rms(np.where(valid, calm, np.nan), paths.counts),
        _rms(np.where(valid, fitted, np.nan), paths.counts),
        int(solution.nfev) + 3 * int(solution.njev or 0),
    )


@dataclass
class Anova:
    """One-way analysis of variance of one wind component across groups (groups of at least 2 shots)."""

    n_shots: int
    n_groups: int
    within_sd: float
    between_sd: float
    f: float
    p: float
    between_fraction: float


def anova(values: np.ndarray, groups: np.ndarray) -> Anova:
    """Within-group SD (pooled), SD of the group means, F = MS_between / MS_within and its p, SS_between / SS_total."""
    names = [g for g in dict.fromkeys(groups) if np.sum(groups == g) >= 2]
    keep = np.isin(groups, names)
    values, groups = values[keep], groups[keep]
    n, k = len(values), len(names)
    if k == 0:
        return Anova(0, 0, float("nan"), float("nan"), float("nan"), float("nan"), float("nan"))
    means = np.array([values[groups == g].mean() for g in names])
    sizes = np.array([np.sum(groups == g) for g in names])
    within = float(sum(np.sum((values[groups == g] - m) ** 2) for g, m in zip(names, means)))
    between = float(np.sum(sizes * (means - values.mean()) ** 2))
    within_sd = float(np.sqrt(within / (n - k))) if n > k else float("nan")
    if k < 2:
        return Anova(n, k, within_sd, float("nan"), float("nan"), float("nan"), float("nan"))
    f = (between / (k - 1)) / (within / (n - k)) if within > 0 else float("inf")
    return Anova(n, k, within_sd, float(np.std(means, ddof=1)), float(f), float(f_distribution.sf(f, k - 1, n - k)),
                 between / (between + within) if between + within > 0 else float("nan"))


@dataclass
class GroupWind:
    """The fitted winds of one hole in one round: mean components, speed and from-direction of the mean, within SDs."""

    group: str
    n: int
    x_mps: float
    y_mps: float
    sd_x_mps: float
    sd_y_mps: float

    @property
    def speed_mps(self) -> float:
        return float(Wind.from_components(self.x_mps, self.y_mps).speed_mps)

    @property
    def from_deg(self) -> float:
        return float(Wind.from_components(self.x_mps, self.y_mps).from_deg)


def group_winds(fit: WindFit) -> list[GroupWind]:
    """Per (round, hole): the shots' mean wind and their spread (SD, ddof 1; NaN for one shot)."""
    groups = fit.groups
    found = []
    for name in sorted(set(groups) - {""}, key=lambda g: (round_of(g), int(g.rsplit("-H", 1)[1]))):
        mask = groups == name
        x, y = fit.x_mps[mask], fit.y_mps[mask]
        sd = (float(np.std(x, ddof=1)), float(np.std(y, ddof=1))) if len(x) > 1 else (float("nan"), float("nan"))
        found.append(GroupWind(name, int(mask.sum()), float(x.mean()), float(y.mean()), *sd))
    return found


@dataclass
class Consistency:
    """Per round (and over the whole event) the ANOVA of each component across its holes."""

    rounds: dict[str, tuple[Anova, Anova]] = field(default_factory=dict)
    event: tuple[Anova, Anova] | None = None


def consistency(fit: WindFit) -> Consistency:
    groups = fit.groups
    result = Consistency()
    for name in sorted({round_of(g) for g in groups if g}):
        mask = np.array([bool(g) and round_of(g) == name for g in groups])
        result.rounds[name] = (anova(fit.x_mps[mask], groups[mask]), anova(fit.y_mps[mask], groups[mask]))
    has_group = groups != ""
    result.event = (anova(fit.x_mps[has_group], groups[has_group]), anova(fit.y_mps[has_group], groups[has_group]))
    return result


@dataclass
class TrainingWindComparison:
    """The training pipeline's per-group winds against the fitted group means: matched groups and the correlation of
    each component (NaN with fewer than 3 groups)."""

    n_groups: int
    n_training_groups: int
    correlation_x: float
    correlation_y: float
    mean_difference_x: float
    mean_difference_y: float


def training_winds(bundle: Path) -> list[dict] | None:
    """The "wind" entries of the bundle's training_conditions.json, or None when the bundle has none."""
    path = Path(bundle) / TRAINING_CONDITIONS_FILE
    if not path.is_file():
        return None
    return list(json.loads(path.read_text()).get("wind", []))


def compare_training_winds(entries: Sequence[dict], fitted: Sequence[GroupWind]) -> TrainingWindComparison:
    by_group = {g.group: g for g in fitted}
    pairs = [(e, by_group[e["group"]]) for e in entries if e.get("group") in by_group]
    if not pairs:
        nan = float("nan")
        return TrainingWindComparison(0, len(entries), nan, nan, nan, nan)
    trained = np.array([[float(e["x_mps"]), float(e["y_mps"])] for e, _ in pairs])
    ours = np.array([[g.x_mps, g.y_mps] for _, g in pairs])

    def correlation(axis: int) -> float:
        if len(pairs) < 3 or np.std(trained[:, axis]) == 0 or np.std(ours[:, axis]) == 0:
            return float("nan")
        return float(np.corrcoef(trained[:, axis], ours[:, axis])[0, 1])

    difference = np.mean(trained - ours, axis=0)
    return TrainingWindComparison(len(pairs), len(entries), correlation(0), correlation(1), float(difference[0]),
                                  float(difference[1]))
