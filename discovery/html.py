"""report.html: the statement, the tables and the plots an engineer looks at first (residuals against the
covariates that matter, before/after held-out histograms, trajectory overlays, the candidates' scores)."""

from __future__ import annotations

import json
from html import escape

import numpy as np

from discovery import svg
from discovery.recordings import LABELS, OBSERVABLES
from discovery.schema import Report

STYLE = """body{font-family:sans-serif;max-width:1280px;margin:1em auto;color:#222}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}
th{background:#f2f2f2}td:first-child{text-align:left}.plots svg{margin:4px;border:1px solid #eee}
.statement{font-size:1.1em;background:#f7f7f0;padding:.6em;border-left:4px solid #1f77b4}"""


def _table(header: list[str], rows: list[list[object]]) -> str:
    def cell(v: object) -> str:
        return f"{v:.4g}" if isinstance(v, float) else escape(str(v))

    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _covariate_plots(diagnosis) -> list[str]:
    report, rec = diagnosis.report, diagnosis.recordings
    ranked = sorted(report.located.covariates, key=lambda c: (not c.significant, -abs(c.t)))
    plots = []
    for item in ranked[:4]:
        j = OBSERVABLES.index(item.observable)
        x = rec.covariate(item.covariate)
        before = rec.observed[:, j] - diagnosis.before[:, j]
        series = [(x, before, "model as is")]
        if diagnosis.chosen is not None:
            series.append((x, rec.observed[:, j] - diagnosis.after[:, j], "corrected"))
        plots.append(
            svg.scatter(
                f"{item.observable} residual vs {item.covariate} (t = {item.t:.1f})",
                item.covariate,
                f"recorded - model, {LABELS[item.observable]}",
                series,
            )
        )
    return plots


def _histograms(diagnosis) -> list[str]:
    plots = []
    for j, name in enumerate(OBSERVABLES):
        before = diagnosis.heldout_before[:, j]
        if not np.isfinite(before).any():
            continue
        series = [(before, "held out, model as is")]
        if diagnosis.chosen is not None:
            series.append((diagnosis.heldout_after[:, j], "held out, corrected"))
        plots.append(svg.histogram(f"held-out residual: {name}", LABELS[name], series))
    return plots


def _trajectories(diagnosis, count: int = 6) -> list[str]:
    rec = diagnosis.recordings
    if not rec.trajectories or diagnosis.positions_before is None:
        return []
    index = {shot: i for i, shot in enumerate(rec.shot_id)}
    shots = [s for s in rec.trajectories if s in index][:count]
    side, height = [], []
    for k, shot in enumerate(shots):
        samples = rec.trajectories[shot]
        i = index[shot]
        before = diagnosis.positions_before[:, i]
        label = k == 0
        height.append((samples[:, 2], samples[:, 3], "recorded" if label else None, 0, False))
        height.append((before[:, 1], before[:, 2], "model as is" if label else None, 2, True))
        side.append((samples[:, 2], samples[:, 1], "recorded" if label else None, 0, False))
        side.append((before[:, 1], before[:, 0], "model as is" if label else None, 2, True))
        if diagnosis.positions_after is not None:
            after = diagnosis.positions_after[:, i]
            height.append((after[:, 1], after[:, 2], "corrected" if label else None, 1, False))
            side.append((after[:, 1], after[:, 0], "corrected" if label else None, 1, False))
    return [
        svg.lines("trajectories: height", "down the line (m)", "height (m)", height),
        svg.lines("trajectories: side", "down the line (m)", "right of the line (m)", side),
    ]


def render(diagnosis) -> str:
    """The whole HTML page of a diagnosis."""
    report: Report = diagnosis.report
    held = report.heldout
    observed = [n for n in OBSERVABLES if n in held.before]
    stats = {o.name: o for o in report.located.observables}
    mismatch_rows = [
        [
            n,
            stats[n].bias,
            stats[n].bias_se,
            stats[n].rms,
            stats[n].expected,
            stats[n].rms_ratio,
            "yes" if stats[n].significant else "",
            held.before[n],
            held.after[n],
            "{:.3g} [{:.3g}, {:.3g}]".format(*held.improvement_by_observable[n]),
        ]
        for n in observed
        if n in stats
    ]
    candidates = [
        [
            c.name,
            "; ".join(
                f"{e.name}: "
                + ", ".join(f"{k} {v:.4g} ± {e.uncertainty.get(k, float('nan')):.2g}" for k, v in e.parameters.items())
                for e in c.effects
            ),
            c.n_parameters,
            c.heldout_error,
            c.penalty,
            c.score,
        ]
        for c in report.candidates
    ]
    group_rows = [
        [
            g.observable,
            g.grouping,
            g.n_groups,
            g.f,
            g.p,
            "yes" if g.significant else "",
            ", ".join(f"{k} {v:+.2f}" for k, v in g.extremes.items()),
        ]
        for g in report.located.groups
    ]
    trajectory_rows = [
        [t.phase, t.height_band, t.n_samples, t.n_shots, t.across_m, t.along_m, t.height_m, t.rms_m]
        for t in report.located.trajectory
    ]
    fraction = (
        ""
        if held.explained_fraction is None
        else f"; explained share of the excess error {100 * held.explained_fraction:.0f} % "
        f"(95 % interval {100 * held.explained_fraction_ci[0]:.0f}–{100 * held.explained_fraction_ci[1]:.0f} %)"
    )
    scored = sorted(report.candidates, key=lambda c: c.score)[:15]
    sections = [
        (
            f"<h1>Mismatch diagnosis</h1><p>{escape(report.recordings)}: {report.n_shots} shots, {report.n_sessions} "
            f"sessions, observed {', '.join(report.observables)}, {report.trajectories} trajectories. Model: "
            f"{escape(report.model.name)}. {report.seconds:.1f} s.</p>"
        ),
        f"<p class='statement'>{escape(report.statement)}</p>",
        f"<p><b>Systematic:</b> {report.systematic}. Test: {escape(json.dumps(report.systematic_test, default=str))}</p>",
        "<h2>Where the mismatch is</h2><ul>"
        + "".join(f"<li>{escape(s)}</li>" for s in report.located.summary)
        + "</ul>",
        _table(
            [
                "observable",
                "bias",
                "bias SE",
                "RMS",
                "expected",
                "RMS/expected",
                "significant",
                "held-out RMS before",
                "held-out RMS after",
                "improvement of mean z² [95 %]",
            ],
            mismatch_rows,
        ),
        (
            f"<p>Held-out ({escape(held.grouping)}): mean squared standardized error {held.before_error:.3g} → "
            f"{held.after_error:.3g}, improvement {held.improvement:.3g} (95 % interval {held.improvement_ci[0]:.3g} to "
            f"{held.improvement_ci[1]:.3g}){fraction}.</p>"
        ),
        "<div class='plots'>" + "".join(_covariate_plots(diagnosis)) + "</div>",
        "<h2>Before and after, held-out shots</h2><div class='plots'>" + "".join(_histograms(diagnosis)) + "</div>",
    ]
    trajectory_plots = _trajectories(diagnosis)
    if trajectory_plots or trajectory_rows:
        sections.append(
            "<h2>Along the flight</h2>"
            + _table(
                ["phase", "height band", "samples", "shots", "across (m)", "along (m)", "height (m)", "RMS (m)"],
                trajectory_rows,
            )
            + "<div class='plots'>"
            + "".join(trajectory_plots)
            + "</div>"
        )
    sections += [
        "<h2>Candidates</h2><div class='plots'>"
        + svg.bars("held-out score (lower is better)", "score", [c.name for c in scored], [c.score for c in scored])
        + "</div>",
        _table(["candidate", "fitted parameters", "k", "held-out error", "penalty", "score"], candidates),
    ]
    if report.ambiguities:
        sections.append(
            "<h2>What the data cannot separate</h2><ul>"
            + "".join(
                f"<li>{escape(a.effects[0])} vs {escape(a.effects[1])}: {escape(a.note)}</li>"
                for a in report.ambiguities
            )
            + "</ul>"
        )
    if report.unlisted is not None:
        sections.append(
            f"<h2>Unlisted effect</h2><p>{escape(report.unlisted.expression)}</p><ul>"
            + "".join(f"<li>{escape(k)}: {escape(v)}</li>" for k, v in report.unlisted.meaning.items())
            + "</ul>"
        )
    sections += [
        "<h2>Differences between groups</h2>"
        + _table(
            ["observable", "grouping", "groups", "F", "p", "significant", "extreme groups (mean residual)"], group_rows
        ),
        "<h2>Service settings</h2><pre>"
        + escape(report.service_settings.model_dump_json(indent=2, exclude_none=True))
        + "</pre>",
        "<h2>Expected error</h2>"
        + _table(
            [
                "observable",
                "model error",
                "source",
                "outcome noise",
                "launch noise",
                "recordings' scatter (x expected)",
                "scatter used",
            ],
            [
                [
                    n,
                    report.model.model_error[n],
                    report.model.model_error_source.get(n, ""),
                    report.model.outcome_noise[n],
                    report.model.launch_noise[n],
                    report.model.scatter[n].ratio if n in report.model.scatter else "",
                    report.model.scatter[n].applied if n in report.model.scatter else "",
                ]
                for n in OBSERVABLES
            ],
        ),
    ]
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>golfflight diagnose</title><style>{STYLE}</style>"
        f"</head><body>{''.join(sections)}</body></html>"
    )
