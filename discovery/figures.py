"""The interactive figures of report.html (plotly, the optional extra `report`): residuals against the launch values
that matter and along the flight, per-session means with their standard errors, held-out residuals and trajectories
before and after the suggested correction, and the candidates' scores.

Every point that is one shot carries its shot id, session and club in `customdata` (`SHOT_FIELDS`), shown on
hover, so a reader goes from an odd point straight to the shot in the recordings. Plain SVG scatter traces (not
WebGL): they render in any browser, headless ones included, and a few thousand points stay quick. Above
PLOTTED_SHOTS shots the scatter plots show a subsample stratified by session and club (their titles say so) and
every statistic drawn over them (binned means, histograms, session means) uses every shot, so a season's report
stays a few megabytes.
"""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go
from golfflight.discovery.fit import stratified_rows
from golfflight.discovery.locate import binned_means, trajectory_residuals
from golfflight.discovery.recordings import LABELS, OBSERVABLES, Recordings
from golfflight.discovery.words import OBSERVABLE_WORDS, UNITS, covariate_label, effect_words
from plotly.subplots import make_subplots

SHOT_FIELDS = ("shot", "session", "club")
"""What each shot-level point's `customdata` row holds, in this order."""

BEFORE, AFTER = "#888888", "#1f77b4"
"""Colours of the model as is and of the corrected model, in every figure."""

SIZE = {"width": 570, "height": 400}
"""A figure's size in pixels: two side by side in the page's 76rem column."""

PLOTTED_SHOTS = 5_000
"""Shots drawn as points in a scatter plot at most (a stratified subsample above it)."""

HISTOGRAM_BINS = 40
"""Bins of the held-out histograms, counted here so the page holds counts, not every shot's value."""


def plotted_shots(recordings: Recordings) -> np.ndarray:
    """The shots a scatter plot draws: all up to PLOTTED_SHOTS, above it that many spread over every session and club
    in proportion (the same shots in every figure and every run)."""
    return stratified_rows(recordings, PLOTTED_SHOTS, np.random.default_rng(0))


def _shown(recordings: Recordings, shown: np.ndarray) -> str:
    """A title's note of how many shots its points are (empty where every shot is drawn)."""
    n = len(recordings)
    return "" if len(shown) == n else f" ({len(shown):,} of {n:,} shots shown)"


def _shots(recordings: Recordings, index: np.ndarray | None = None) -> np.ndarray:
    """customdata rows (shot id, session, club) [N, 3] of the shots at `index` (all by default)."""
    rows = np.column_stack([recordings.shot_id, recordings.session, recordings.club]).astype(str)
    return rows if index is None else rows[index]


def _hover(x_label: str, y_label: str) -> str:
    lines = [f"{name} %{{customdata[{k}]}}" for k, name in enumerate(SHOT_FIELDS)]
    return "<br>".join(lines + [f"{x_label}: %{{x:.4g}}", f"{y_label}: %{{y:.4g}}"]) + "<extra>%{fullData.name}</extra>"


def _points(x: np.ndarray, y: np.ndarray, shots: np.ndarray, name: str, color: str, hover: str) -> go.Scatter:
    keep = np.isfinite(x) & np.isfinite(y)
    return go.Scatter(
        x=x[keep],
        y=y[keep],
        customdata=shots[keep],
        mode="markers",
        name=name,
        marker={"color": color, "size": 5, "opacity": 0.5},
        hovertemplate=hover,
    )


def _layout(figure: go.Figure, title: str, x_label: str, y_label: str) -> go.Figure:
    figure.update_layout(
        title={"text": title}, hovermode="closest", margin={"l": 60, "r": 10, "t": 50, "b": 50}, **SIZE
    )
    figure.update_xaxes(title_text=x_label)
    figure.update_yaxes(title_text=y_label)
    return figure


def covariate_figures(diagnosis, count: int = 4) -> list[go.Figure]:
    """Residual (recorded - model) against the `count` launch values with the strongest trends, as is and corrected,
    each with its binned means."""
    report, rec = diagnosis.report, diagnosis.recordings
    ranked = sorted(report.located.covariates, key=lambda c: (not c.significant, -abs(c.t)))
    shown = plotted_shots(rec)
    shots = _shots(rec, shown)
    out = []
    for item in ranked[:count]:
        j = OBSERVABLES.index(item.observable)
        x = rec.covariate(item.covariate)
        y_label = f"recorded − model, {LABELS[item.observable]}"
        series = [("model as is", diagnosis.before, BEFORE)]
        if diagnosis.chosen is not None:
            series.append(("corrected", diagnosis.after, AFTER))
        figure = go.Figure()
        for name, predicted, color in series:
            residual = rec.observed[:, j] - predicted[:, j]
            hover = _hover(item.covariate, "residual")
            figure.add_trace(_points(x[shown], residual[shown], shots, name, color, hover))
            centres, means = binned_means(x, residual)
            figure.add_trace(
                go.Scatter(
                    x=centres,
                    y=means,
                    mode="lines",
                    name=f"{name}, binned mean",
                    line={"color": color, "width": 3},
                    hovertemplate="binned mean %{y:.4g}<extra></extra>",
                )
            )
        title = (
            f"{OBSERVABLE_WORDS[item.observable]} difference vs {covariate_label(item.covariate)} (t = {item.t:.1f})"
            + _shown(rec, shown)
        )
        out.append(_layout(figure, title, covariate_label(item.covariate), y_label))
    return out


def session_figure(diagnosis) -> go.Figure:
    """Mean residual of every session with its standard error, per observed observable, as is and corrected: a
    shift shared by a session (its weather) stands out from the rest."""
    rec = diagnosis.recordings
    names = [(j, n) for j, n in enumerate(OBSERVABLES) if n in rec.observed_names]
    sessions, codes = np.unique(rec.session, return_inverse=True)
    # each session's shots in recorded order, found once (a season has a thousand sessions and 100,000 shots)
    members = np.split(np.argsort(codes, kind="stable"), np.cumsum(np.bincount(codes))[:-1])
    clubs = [", ".join(np.unique(rec.club[rows]).astype(str)) for rows in members]
    figure = make_subplots(rows=len(names), cols=1, shared_xaxes=True, subplot_titles=[LABELS[n] for _, n in names])
    series = [("model as is", diagnosis.before, BEFORE)]
    if diagnosis.chosen is not None:
        series.append(("corrected", diagnosis.after, AFTER))
    for row, (j, name) in enumerate(names, start=1):
        for label, predicted, color in series:
            means, errors, details = [], [], []
            for session, rows, played in zip(sessions, members, clubs):
                residual = rec.observed[rows, j] - predicted[rows, j]
                residual = residual[np.isfinite(residual)]
                means.append(residual.mean() if residual.size else np.nan)
                errors.append(residual.std(ddof=1) / np.sqrt(residual.size) if residual.size > 1 else np.nan)
                details.append([str(session), residual.size, played, errors[-1]])
            figure.add_trace(
                go.Scatter(
                    x=sessions.astype(str),
                    y=means,
                    error_y={"type": "data", "array": errors, "visible": True},
                    customdata=details,
                    mode="markers",
                    name=label,
                    legendgroup=label,
                    showlegend=row == 1,
                    marker={"color": color, "size": 8},
                    hovertemplate="session %{customdata[0]}<br>%{customdata[1]} shots<br>clubs %{customdata[2]}"
                    "<br>mean %{y:.4g} ± %{customdata[3]:.2g}<extra>%{fullData.name}</extra>",
                ),
                row=row,
                col=1,
            )
        figure.update_yaxes(title_text=f"mean residual ({UNITS[name]})", row=row, col=1)
    figure.update_layout(
        title={"text": "mean residual per session (± 1 standard error)"},
        hovermode="closest",
        width=SIZE["width"],
        height=170 * len(names) + 100,
        margin={"l": 60, "r": 10, "t": 70, "b": 50},
    )
    return figure


def phase_figure(diagnosis) -> go.Figure | None:
    """Position residuals (recorded - model) of the recorded trajectories against the share of the flight, as is and
    corrected: where along the flight a left-out effect acts (None without trajectories)."""
    rec = diagnosis.recordings
    if not rec.trajectories or diagnosis.positions_before is None:
        return None
    shown = plotted_shots(rec)
    index = {rec.shot_id[i]: i for i in shown}
    shots = _shots(rec)
    series = [("model as is", diagnosis.positions_before, BEFORE)]
    if diagnosis.positions_after is not None:
        series.append(("corrected", diagnosis.positions_after, AFTER))
    figure = make_subplots(rows=2, cols=1, shared_xaxes=True, subplot_titles=["height", "across the line (+ right)"])
    dt_s = diagnosis.report.model.dt_s
    for label, positions, color in series:
        residuals = {shot: r for shot, r in trajectory_residuals(rec, positions, dt_s).items() if shot in index}
        if not residuals:
            continue
        share = np.concatenate([r[:, 0] / r[-1, 0] for r in residuals.values()])
        data = np.concatenate(list(residuals.values()))
        who = np.concatenate([np.repeat(shots[[index[s]]], len(r), axis=0) for s, r in residuals.items()])
        for row, column, name in ((1, 6, "height residual (m)"), (2, 4, "across residual (m)")):
            trace = _points(share, data[:, column], who, label, color, _hover("share of the flight", name))
            trace.update(legendgroup=label, showlegend=row == 1)
            figure.add_trace(trace, row=row, col=1)
    figure.update_xaxes(title_text="share of the recorded flight (0 = launch, 1 = last sample)", row=2, col=1)
    figure.update_yaxes(title_text="recorded − model (m)")
    figure.update_layout(
        title={"text": "trajectory residuals along the flight" + _shown(rec, shown)},
        hovermode="closest",
        width=SIZE["width"],
        height=560,
        margin={"l": 60, "r": 10, "t": 70, "b": 50},
    )
    return figure


def heldout_figures(diagnosis) -> list[go.Figure]:
    """Histograms of the held-out residuals of each observed observable, as is and corrected."""
    out = []
    for j, name in enumerate(OBSERVABLES):
        before = diagnosis.heldout_before[:, j]
        if not np.isfinite(before).any():
            continue
        series = [("held out, model as is", before, BEFORE)]
        if diagnosis.chosen is not None:
            series.append(("held out, corrected", diagnosis.heldout_after[:, j], AFTER))
        finite = np.concatenate([values[np.isfinite(values)] for _, values, _ in series])
        edges = np.histogram_bin_edges(finite, bins=HISTOGRAM_BINS)
        centres, widths = (edges[1:] + edges[:-1]) / 2, np.diff(edges)
        figure = go.Figure()
        for label, values, color in series:
            counts = np.histogram(values[np.isfinite(values)], bins=edges)[0]
            figure.add_trace(
                go.Bar(
                    x=centres,
                    y=counts,
                    width=widths,
                    name=label,
                    marker_color=color,
                    opacity=0.6,
                    hovertemplate="%{x:.4g}: %{y} shots<extra>%{fullData.name}</extra>",
                )
            )
        figure.update_layout(barmode="overlay", bargap=0)
        title = f"held-out difference: {OBSERVABLE_WORDS[name]}"
        out.append(_layout(figure, title, f"recorded − model, {LABELS[name]}", "shots (count)"))
    return out


def trajectory_figures(diagnosis, count: int = 6) -> list[go.Figure]:
    """The first `count` recorded trajectories against the model's flights (as is and corrected): height and side
    against the distance down the line."""
    rec = diagnosis.recordings
    if not rec.trajectories or diagnosis.positions_before is None:
        return []
    index = {shot: i for i, shot in enumerate(rec.shot_id)}
    chosen = [s for s in rec.trajectories if s in index][:count]
    shots = _shots(rec)
    figures = {"height": go.Figure(), "side": go.Figure()}
    axes = {"height": (2, "height (m)"), "side": (0, "right of the line (m)")}
    for k, shot in enumerate(chosen):
        i = index[shot]
        lines = [("recorded", rec.trajectories[shot][:, 1:4], "#d62728", "solid")]
        lines.append(("model as is", diagnosis.positions_before[:, i], BEFORE, "dash"))
        if diagnosis.positions_after is not None:
            lines.append(("corrected", diagnosis.positions_after[:, i], AFTER, "solid"))
        for view, figure in figures.items():
            column, label = axes[view]
            for name, path, color, dash in lines:
                keep = np.isfinite(path).all(axis=1)
                figure.add_trace(
                    go.Scatter(
                        x=path[keep, 1],
                        y=path[keep, column],
                        customdata=np.repeat(shots[[i]], keep.sum(), axis=0),
                        mode="lines",
                        name=name,
                        legendgroup=name,
                        showlegend=k == 0,
                        line={"color": color, "dash": dash, "width": 1.5},
                        hovertemplate=_hover("down the line (m)", label),
                    )
                )
    return [
        _layout(figures[view], f"trajectories: {view}", "down the line (m)", axes[view][1])
        for view in ("height", "side")
    ]


def candidates_figure(diagnosis, count: int = 15) -> go.Figure:
    """The `count` best candidates' held-out scores (lower is better)."""
    scored = sorted(diagnosis.report.candidates, key=lambda c: c.score)[:count]
    figure = go.Figure(
        go.Bar(
            x=[c.score for c in scored],
            y=[effect_words(c.name) for c in scored],
            orientation="h",
            marker_color=AFTER,
            hovertemplate="%{y}: score %{x:.4g}<extra></extra>",
        )
    )
    figure.update_yaxes(autorange="reversed")
    _layout(figure, "held-out score (lower is better)", "score (mean z², 1 = as large as expected)", "")
    return figure.update_layout(height=120 + 22 * len(scored), margin={"l": 220})


def report_figures(diagnosis) -> dict[str, list[go.Figure]]:
    """Every figure of the report, by the section it goes in."""
    phase = phase_figure(diagnosis)
    return {
        "residuals": covariate_figures(diagnosis) + [session_figure(diagnosis)],
        "heldout": heldout_figures(diagnosis),
        "along": ([phase] if phase is not None else []) + trajectory_figures(diagnosis),
        "candidates": [candidates_figure(diagnosis)],
    }
