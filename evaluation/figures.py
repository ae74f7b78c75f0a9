"""PNG figures of the evaluation (matplotlib, Agg backend): the paper's Figures 6 and 7 and the real-data path error.

Each function takes plain arrays, writes one file and returns its path; nothing here computes a metric.
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from golfflight.flight.constants import YARD_M
from PIL import Image

DPI = 110
MAX_SCATTER_POINTS = 50_000
"""Scatter plots draw a random subset of this many points at most (the PNG stays small, the cloud's shape stays)."""


def _save(figure: plt.Figure, path: str | os.PathLike) -> Path:
    """Write a PNG with a 256-colour palette: a third of the size for these plots, no visible change."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, dpi=DPI, format="png")
    plt.close(figure)
    Image.open(buffer).convert("RGB").quantize(256).save(path, optimize=True)
    return path


def error_histograms(series: dict[str, dict[str, np.ndarray]], path: str | os.PathLike) -> Path:
    """Figure 6: normalised histograms, in yards, of landing-point error, length error, side error and max-height
    error over the central 99 % of the pooled values (the legend's means use all of them). `series` maps a label to
    {"landing", "length", "side", "apex"} per-shot errors in metres (NaN skipped)."""
    panels = (
        ("landing", "landing position error (yd)", True),
        ("length", "length error (yd)", False),
        ("side", "side error (yd)", False),
        ("apex", "max height error (yd)", False),
    )
    colours = {name: f"C{i}" for i, name in enumerate(series)}
    figure, axes = plt.subplots(2, 2, figsize=(10, 7))
    for axis, (key, label, from_zero) in zip(axes.ravel(), panels):
        values = {name: v[key][np.isfinite(v[key])] / YARD_M for name, v in series.items() if v.get(key) is not None}
        if not values:
            axis.set_visible(False)
            continue
        pooled = np.concatenate(list(values.values()))
        low, high = np.percentile(pooled, [0.5, 99.5])
        bins = np.linspace(0.0 if from_zero else low, high, 60)
        for name, v in values.items():
            axis.hist(
                v,
                bins=bins,
                density=True,
                histtype="step",
                linewidth=1.5,
                color=colours[name],
                label=f"{name} (mean |e| {np.mean(np.abs(v)):.2f})",
            )
        axis.set_xlabel(label)
        axis.set_ylabel("density")
        axis.legend(fontsize=8)
    return _save(figure, path)


def _subset(n: int, seed: int = 0) -> np.ndarray:
    if n <= MAX_SCATTER_POINTS:
        return np.arange(n)
    return np.random.default_rng(seed).choice(n, MAX_SCATTER_POINTS, replace=False)


def coefficient_clouds(
    spin_ratio: np.ndarray,
    model: dict[str, np.ndarray],
    effective: dict[str, np.ndarray],
    reference: dict[str, np.ndarray],
    curves: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
    path: str | os.PathLike,
    model_label: str = "Phys-NN+",
) -> Path:
    """Figure 7: C_L and C_D against the spin ratio at every in-flight step. Top row: the network's raw heads (the
    paper's figure); bottom row: `effective` coefficients (what the force sees, see the caller) with the reference
    world's values at the same states. `curves` maps a label to (S, C_L(S), C_D(S)) lines."""
    index = _subset(len(spin_ratio))
    s = spin_ratio[index]
    figure, axes = plt.subplots(2, 2, figsize=(11, 8), sharex=True)
    rows = ((model, f"{model_label} raw head"), (effective, f"{model_label} effective"))
    for row, (values, label) in enumerate(rows):
        for column, key in enumerate(("C_L", "C_D")):
            axis = axes[row, column]
            if row == 1:
                axis.scatter(
                    s,
                    reference[key][index],
                    s=0.3,
                    alpha=0.08,
                    color="tab:green",
                    rasterized=True,
                    label="reference world (same states)",
                )
            axis.scatter(s, values[key][index], s=0.3, alpha=0.08, color="tab:blue", rasterized=True, label=label)
            for (name, (grid, c_lift, c_drag)), style in zip(curves.items(), ("-", ":", "--")):
                axis.plot(grid, c_lift if key == "C_L" else c_drag, style, color="tab:red", linewidth=1.8, label=name)
            axis.set_ylabel(key if row == 0 else f"effective {key}")
            axis.set_xlim(0.0, float(np.percentile(spin_ratio, 99.9)))
            shown = [float(np.percentile(values[key], 99.9))] + (
                [float(np.percentile(reference[key], 99.9))] if row == 1 else []
            )
            shown += [float(np.max(line[1 if key == "C_L" else 2])) for line in curves.values()]
            axis.set_ylim(0.0, 1.1 * max(shown))
            legend = axis.legend(fontsize=7, markerscale=15, loc="best")
            for handle in legend.legend_handles:
                handle.set_alpha(1.0)
    for axis in axes[1]:
        axis.set_xlabel("spin ratio S = R|ω|/|v|")
    return _save(figure, path)


def path_error(times_s: np.ndarray, errors_m: Sequence[np.ndarray], path: str | os.PathLike, title: str) -> Path:
    """Median and 10-90 % band of the 3-D position error against time; errors_m[i] holds the shots in flight at
    times_s[i]. Drawn while at least a quarter of the shots are in flight (later, a few long flights are noise)."""
    figure, axis = plt.subplots(figsize=(7, 4.2))
    most = max((len(e) for e in errors_m), default=0)
    keep = [i for i, e in enumerate(errors_m) if len(e) and len(e) >= 0.25 * most]
    t = times_s[keep]
    quantiles = np.array([np.percentile(errors_m[i], [10, 50, 90]) for i in keep]).reshape(-1, 3)
    axis.fill_between(t, quantiles[:, 0], quantiles[:, 2], alpha=0.25, label="10-90 %")
    axis.plot(t, quantiles[:, 1], linewidth=2, label="median")
    axis.set_xlabel("time since launch (s)")
    axis.set_ylabel("3-D position error (m)")
    axis.set_title(f"{title}\n(drawn while at least 25 % of the shots are in flight)", fontsize=10)
    axis.grid(alpha=0.3)
    axis.legend()
    return _save(figure, path)


def learning_curve(shots: dict[str, np.ndarray], errors: dict[str, np.ndarray], spans: dict[str, np.ndarray],
                   path: str | os.PathLike, ylabel: str) -> Path:
    """Error against training shots, a line per model: `errors[label]` at `shots[label]` (log axis), with the range
    over seeds `spans[label]` [n, 2] as bars."""
    return learning_curves([(ylabel, shots, errors, spans)], path)


LearningPanel = tuple[str, dict[str, np.ndarray], dict[str, np.ndarray], dict[str, np.ndarray]]
"""One panel of `learning_curves`: (y label, shots, errors, spans) as `learning_curve` takes them."""


def learning_curves(panels: Sequence[LearningPanel], path: str | os.PathLike,
                    floors: dict[int, tuple[str, float]] | None = None) -> Path:
    """`learning_curve`'s plot for each panel, side by side; `floors[i]` = (label, value) draws a dashed horizontal
    line on panel i (a reference level, such as a noise floor)."""
    figure, axes = plt.subplots(1, len(panels), figsize=(6.5 * len(panels), 4.2), squeeze=False)
    for index, (axis, (ylabel, shots, errors, spans)) in enumerate(zip(axes[0], panels)):
        for label, n in shots.items():
            low, high = spans[label][:, 0], spans[label][:, 1]
            axis.errorbar(n, errors[label], yerr=[errors[label] - low, high - errors[label]], marker="o",
                          capsize=3, label=label)
        if floors and index in floors:
            axis.axhline(floors[index][1], color="grey", linestyle="--", label=floors[index][0])
        axis.set_xscale("log")
        axis.set_xlabel("training shots")
        axis.set_ylabel(ylabel)
        axis.grid(alpha=0.3)
        axis.legend()
    return _save(figure, path)
