"""Locate a mismatch: bias and spread per observable against the expected error, dependence on launch values,
clubs, sessions and shot order, and where along the flight when trajectories are recorded.

Standard errors are clustered by session when there are at least five (a session shares its weather, so its
shots are not independent); every p-value joins one Holm family, so "significant" means family-wise.
"""

from __future__ import annotations

import numpy as np
from golfflight.discovery.recordings import COVARIATES, OBSERVABLES, Recordings
from golfflight.discovery.schema import CovariateStat, GroupStat, Located, ObservableStat, TrajectoryStat
from scipy import stats

ALPHA = 0.01
MIN_CLUSTERS = 5
HEIGHT_BANDS = ((0.0, 10.0), (10.0, 20.0), (20.0, 30.0), (30.0, np.inf))


def _clusters(groups: np.ndarray) -> tuple[np.ndarray, int]:
    codes = np.unique(groups, return_inverse=True)[1]
    return codes, int(codes.max()) + 1 if codes.size else 0


def mean_test(values: np.ndarray, groups: np.ndarray, null: float = 0.0) -> tuple[float, float, float]:
    """(mean, standard error, two-sided p) of `values` against `null`, clustered when there are enough groups."""
    n = values.size
    mean = float(values.mean())
    codes, g = _clusters(groups)
    if g >= MIN_CLUSTERS:
        sums = np.bincount(codes, weights=values - mean, minlength=g)
        se = float(np.sqrt(np.sum(sums**2) * g / (g - 1)) / n)
        dof = g - 1
    else:
        se = float(values.std(ddof=1) / np.sqrt(n)) if n > 1 else np.inf
        dof = max(n - 1, 1)
    t = (mean - null) / se if se > 0 else 0.0
    return mean, se, float(2 * stats.t.sf(abs(t), dof))


def slope_test(y: np.ndarray, x: np.ndarray, groups: np.ndarray) -> tuple[float, float, float]:
    """(slope per SD of x, t, two-sided p) of the least-squares line y ~ x, cluster-robust sandwich errors."""
    sd = x.std()
    n = y.size
    if sd == 0 or n < 4:
        return 0.0, 0.0, 1.0
    u = (x - x.mean()) / sd
    slope = float(np.sum(u * y) / np.sum(u * u))
    e = y - y.mean() - slope * u
    codes, g = _clusters(groups)
    if g >= MIN_CLUSTERS:
        scores = np.bincount(codes, weights=u * e, minlength=g)
        var = np.sum(scores**2) * g / (g - 1) / np.sum(u * u) ** 2
        dof = g - 1
    else:
        var = np.sum(e**2) / (n - 2) / np.sum(u * u)
        dof = n - 2
    t = slope / np.sqrt(var) if var > 0 else 0.0
    return slope, float(t), float(2 * stats.t.sf(abs(t), dof))


def group_test(z: np.ndarray, groups: np.ndarray) -> tuple[float, float, int]:
    """(F, p, number of groups) of a one-way ANOVA: do the group means of z differ?"""
    labels, codes = np.unique(groups, return_inverse=True)
    k = labels.size
    if k < 2 or z.size - k < 2:
        return 0.0, 1.0, k
    counts = np.bincount(codes, minlength=k)
    means = np.bincount(codes, weights=z, minlength=k) / counts
    between = np.sum(counts * (means - z.mean()) ** 2) / (k - 1)
    within = np.sum((z - means[codes]) ** 2) / (z.size - k)
    f = between / within if within > 0 else 0.0
    return float(f), float(stats.f.sf(f, k - 1, z.size - k)), int(k)


def holm(pvalues: list[float], alpha: float = ALPHA) -> list[bool]:
    """Holm's step-down rejections at family-wise level alpha."""
    order = np.argsort(pvalues)
    reject = [False] * len(pvalues)
    m = len(pvalues)
    for rank, index in enumerate(order):
        if pvalues[index] > alpha / (m - rank):
            break
        reject[index] = True
    return reject


def group_codes(recordings: Recordings) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(sorted names, each shot's index among them) of the clubs and of the sessions: the same groups as the names,
    without comparing strings shot by shot on a large set."""
    return {grouping: np.unique(getattr(recordings, grouping), return_inverse=True) for grouping in ("club", "session")}


def group_means(values: np.ndarray, codes: np.ndarray, names: np.ndarray) -> dict[str, float]:
    """The mean of `values` in each group present (`codes` index `names`), keyed by name in code order; each mean is
    taken over its members in their order, as `values[codes == g].mean()` would, in one sort instead of a pass per
    group."""
    order = np.argsort(codes, kind="stable")
    present, starts = np.unique(codes[order], return_index=True)
    return {str(names[g]): float(part.mean()) for g, part in zip(present, np.split(values[order], starts[1:]))}


def binned_means(x: np.ndarray, y: np.ndarray, bins: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Means of y in quantile bins of x (the trend line drawn over a scatter)."""
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if x.size < 2 * bins:
        return np.zeros(0), np.zeros(0)
    edges = np.unique(np.quantile(x, np.linspace(0, 1, bins + 1)))
    which = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, len(edges) - 2)
    centres = np.array([x[which == b].mean() for b in range(len(edges) - 1) if (which == b).any()])
    means = np.array([y[which == b].mean() for b in range(len(edges) - 1) if (which == b).any()])
    return centres, means


def trajectory_residuals(recordings: Recordings, positions: np.ndarray, dt_s: float) -> dict[str, np.ndarray]:
    """Per shot id with a recorded trajectory: rows of (t, recorded x, y, z, residual x, y, z), recorded - model."""
    rows = {}
    index = {shot: i for i, shot in enumerate(recordings.shot_id)}
    for shot, samples in recordings.trajectories.items():
        if shot not in index:
            continue
        path = positions[:, index[shot]]
        valid = np.isfinite(path[:, 2])
        times = dt_s * np.arange(path.shape[0])[valid]
        t = samples[:, 0]
        inside = t <= times[-1]
        if inside.sum() < 2:
            continue
        t, recorded = t[inside], samples[inside, 1:4]
        model = np.stack([np.interp(t, times, path[valid, k]) for k in range(3)], axis=1)
        rows[shot] = np.column_stack([t, recorded, recorded - model])
    return rows


def trajectory_stats(rows: list[np.ndarray]) -> list[TrajectoryStat]:
    """Mean residual by flight phase (before/after the recorded apex) and height band."""
    out = []
    tagged = []
    for shot, r in enumerate(rows):
        descent = np.arange(len(r)) > np.argmax(r[:, 3])
        tagged.append(np.column_stack([r, descent, np.full(len(r), shot)]))
    if not tagged:
        return out
    data = np.concatenate(tagged)
    for phase, flag in (("ascent", 0.0), ("descent", 1.0)):
        for low, high in HEIGHT_BANDS:
            cell = data[(data[:, 7] == flag) & (data[:, 3] >= low) & (data[:, 3] < high)]
            if len(cell) == 0:
                continue
            band = f"{low:g}-{high:g} m" if np.isfinite(high) else f"above {low:g} m"
            out.append(
                TrajectoryStat(
                    phase=phase,
                    height_band=band,
                    n_samples=len(cell),
                    n_shots=len(np.unique(cell[:, 8])),
                    across_m=float(cell[:, 4].mean()),
                    along_m=float(cell[:, 5].mean()),
                    height_m=float(cell[:, 6].mean()),
                    rms_m=float(np.sqrt(np.mean(np.sum(cell[:, 4:7] ** 2, axis=1)))),
                )
            )
    return out


def locate(
    recordings: Recordings,
    residual: np.ndarray,
    sigma: np.ndarray,
    use: np.ndarray,
    trajectory: list[TrajectoryStat],
    outliers: dict[str, int],
    dilution: dict[str, np.ndarray] | None = None,
) -> Located:
    """All locate statistics of residuals [N, 5] (recorded - model) with expected sigmas [N, 5]. A launch value's
    trend is tested after taking out the trend its own recording noise makes (`discovery.noise.dilution_slopes`)."""
    pending: list[tuple[type, dict, list[int]]] = []
    pvalues: list[float] = []
    codes = group_codes(recordings)

    def add(kind: type, item: dict, *p: float) -> None:
        pending.append((kind, item, list(range(len(pvalues), len(pvalues) + len(p)))))
        pvalues.extend(p)

    for j, name in enumerate(OBSERVABLES):
        rows = use[:, j]
        if rows.sum() < 3:
            continue
        r, s, sessions = residual[rows, j], sigma[rows, j], codes["session"][1][rows]
        z = r / s
        bias, se, p_bias = mean_test(r, sessions)
        _, _, p_excess = mean_test(z**2, sessions, null=1.0)
        p_excess = 1.0 if np.mean(z**2) < 1 else p_excess / 2
        add(
            ObservableStat,
            {
                "name": name,
                "n": int(rows.sum()),
                "bias": bias,
                "bias_se": se,
                "bias_p": p_bias,
                "spread": float(r.std(ddof=1)),
                "rms": float(np.sqrt(np.mean(r**2))),
                "expected": float(np.sqrt(np.mean(s**2))),
                "rms_ratio": float(np.sqrt(np.mean(z**2))),
                "excess_p": p_excess,
            },
            p_bias,
            p_excess,
        )
        for covariate in COVARIATES:
            x = recordings.covariate(covariate)[rows]
            expected = 0.0
            if dilution is not None and covariate in dilution:
                expected = -dilution[covariate][rows, j] * (x - recordings.covariate(covariate).mean())
            slope, t, p = slope_test(r - expected, x, sessions)
            add(CovariateStat, {"observable": name, "covariate": covariate, "slope_per_sd": slope, "t": t, "p": p}, p)
        for grouping in ("club", "session"):
            names, every = codes[grouping]
            labels = every[rows]
            f, p, k = group_test(z, labels)
            if k < 2:
                continue
            means = group_means(r, labels, names)
            extremes = dict(sorted(means.items(), key=lambda kv: -abs(kv[1] - bias))[:3])
            add(
                GroupStat,
                {"observable": name, "grouping": grouping, "n_groups": k, "f": f, "p": p, "extremes": extremes},
                p,
            )
    flags = holm(pvalues)
    built = {ObservableStat: [], CovariateStat: [], GroupStat: []}
    for kind, item, where in pending:
        built[kind].append(kind(**item, significant=any(flags[i] for i in where)))
    observables, covariates, groups = built[ObservableStat], built[CovariateStat], built[GroupStat]
    return Located(
        observables=observables,
        covariates=covariates,
        groups=groups,
        trajectory=trajectory,
        outliers=outliers,
        alpha=ALPHA,
        summary=summarise(observables, covariates, groups, trajectory),
    )


def has_structure(located: Located) -> bool:
    """Whether any test of the family found what noise and the model's own error do not make."""
    return any(stat.significant for stat in (*located.observables, *located.covariates, *located.groups))


def summarise(
    observables: list[ObservableStat],
    covariates: list[CovariateStat],
    groups: list[GroupStat],
    trajectory: list[TrajectoryStat],
) -> list[str]:
    """Plain lines, most telling first: significant biases, then the strongest covariate and group effects."""
    lines = []
    for o in sorted(observables, key=lambda o: -abs(o.bias / o.bias_se) if o.bias_se > 0 else 0):
        if o.significant:
            lines.append(
                f"{o.name}: bias {o.bias:+.2f} +/- {o.bias_se:.2f}, RMS {o.rms:.2f} vs {o.expected:.2f} "
                f"expected ({o.rms_ratio:.1f}x)"
            )
    for c in sorted((c for c in covariates if c.significant), key=lambda c: -abs(c.t))[:6]:
        lines.append(f"{c.observable} residual changes {c.slope_per_sd:+.2f} per SD of {c.covariate} (t = {c.t:.1f})")
    for g in sorted((g for g in groups if g.significant), key=lambda g: g.p)[:4]:
        worst = ", ".join(f"{k} {v:+.2f}" for k, v in g.extremes.items())
        lines.append(f"{g.observable} differs between {g.grouping}s (F = {g.f:.1f}; {worst})")
    if trajectory:
        worst = max(trajectory, key=lambda s: s.rms_m)
        lines.append(
            f"trajectories: largest mismatch in the {worst.phase} at {worst.height_band}: "
            f"{worst.rms_m:.2f} m RMS (height {worst.height_m:+.2f} m, along {worst.along_m:+.2f} m)"
        )
    if not lines:
        lines.append("no observable, covariate or group departs from the expected error at the family-wise level")
    return lines
