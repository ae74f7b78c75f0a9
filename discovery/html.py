"""report.html: the statement, the tables and the interactive figures an engineer looks at first (`discovery.figures`:
residuals against the covariates that matter and along the flight, per-session means, held-out residuals and
trajectories before and after the correction, the candidates' scores).

One self-contained file: plotly.js is embedded once in the page, nothing is fetched, so the report opens offline.
The figures need plotly, the optional extra `report`; without it the page keeps every table and the statement and
says which extra to install (`PLOTS_MISSING`): diagnose works without it.
"""

from __future__ import annotations

import json
from html import escape

from golfflight.discovery.recordings import OBSERVABLES
from golfflight.discovery.schema import Report

STYLE = """body{font-family:sans-serif;max-width:1280px;margin:1em auto;color:#222}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}
th{background:#f2f2f2}td:first-child{text-align:left}.plots{display:flex;flex-wrap:wrap;gap:6px}
.plots>div{border:1px solid #eee}.missing{background:#fff4e5;padding:.6em;border-left:4px solid #ff7f0e}
.statement{font-size:1.1em;background:#f7f7f0;padding:.6em;border-left:4px solid #1f77b4}"""

PLOTS_MISSING = (
    "The interactive figures need plotly, which is not installed: pip install 'golfflight[report]' (the tables and "
    "the statement are complete without it)."
)


def plots_available() -> bool:
    """Whether plotly (the extra `report`) can be imported, so report.html gets its figures."""
    try:
        import plotly  # noqa: F401
    except ModuleNotFoundError:
        return False
    return True


class Plots:
    """The report's figures as HTML fragments by section (each a plotly div and its script, no plotly.js) plus the
    plotly.js bundle the page embeds once; empty, with `PLOTS_MISSING`, where plotly is not installed."""

    def __init__(self, diagnosis) -> None:
        self.sections: dict[str, list[str]] = {}
        self.bundle = ""
        if not plots_available():
            return
        from golfflight.discovery.figures import report_figures
        from plotly.offline import get_plotlyjs

        self.bundle = get_plotlyjs()
        count = 0
        for section, figures in report_figures(diagnosis).items():
            self.sections[section] = []
            for figure in figures:
                config = {"displaylogo": False}
                html = figure.to_html(full_html=False, include_plotlyjs=False, div_id=f"figure-{count}", config=config)
                self.sections[section].append(html)
                count += 1

    def div(self, section: str) -> str:
        """The section's figures in one flex row ("" without plotly or figures)."""
        figures = self.sections.get(section, [])
        return f"<div class='plots'>{''.join(figures)}</div>" if figures else ""

    def head(self) -> str:
        """The page head's script: the plotly.js bundle, inline (never a CDN link)."""
        return f"<script type='text/javascript'>{self.bundle}</script>" if self.bundle else ""

    def notice(self) -> str:
        """The line that names the extra to install, where the figures are missing ("" otherwise)."""
        return "" if self.bundle else f"<p class='missing'>{escape(PLOTS_MISSING)}</p>"


def _table(header: list[str], rows: list[list[object]]) -> str:
    def cell(v: object) -> str:
        return f"{v:.4g}" if isinstance(v, float) else escape(str(v))

    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _mismatch_table(report: Report) -> str:
    """Per observable: the located bias and scatter against the expected, and the held-out RMS before and after."""
    held = report.heldout
    stats = {o.name: o for o in report.located.observables}
    rows = [
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
        for n in OBSERVABLES
        if n in held.before and n in stats
    ]
    header = ["observable", "bias", "bias SE", "RMS", "expected", "RMS/expected", "significant"]
    return _table(header + ["held-out RMS before", "held-out RMS after", "improvement of mean z² [95 %]"], rows)


def _heldout_line(report: Report) -> str:
    """The held-out errors before and after in one sentence, with the explained share where there is one."""
    held = report.heldout
    fraction = (
        ""
        if held.explained_fraction is None
        else f"; explained share of the excess error {100 * held.explained_fraction:.0f} % "
        f"(95 % interval {100 * held.explained_fraction_ci[0]:.0f}–{100 * held.explained_fraction_ci[1]:.0f} %)"
    )
    return (
        f"<p>Held-out ({escape(held.grouping)}): mean squared standardized error {held.before_error:.3g} → "
        f"{held.after_error:.3g}, improvement {held.improvement:.3g} (95 % interval {held.improvement_ci[0]:.3g} to "
        f"{held.improvement_ci[1]:.3g}){fraction}.</p>"
    )


def _trajectory_section(report: Report, plots: Plots) -> list[str]:
    """The mismatch along the recorded flights (none without trajectories)."""
    rows = [
        [t.phase, t.height_band, t.n_samples, t.n_shots, t.across_m, t.along_m, t.height_m, t.rms_m]
        for t in report.located.trajectory
    ]
    if not rows and not plots.div("along"):
        return []
    header = ["phase", "height band", "samples", "shots", "across (m)", "along (m)", "height (m)", "RMS (m)"]
    return ["<h2>Along the flight</h2>" + _table(header, rows) + plots.div("along")]


def _candidates_table(report: Report) -> str:
    """Every candidate with its fitted parameters (± 1 sigma) and its held-out score."""
    rows = [
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
    return _table(["candidate", "fitted parameters", "k", "held-out error", "penalty", "score"], rows)


def _named_sections(report: Report) -> list[str]:
    """The ambiguities and the unlisted effect, where the report has them."""
    sections = []
    if report.ambiguities:
        items = "".join(
            f"<li>{escape(a.effects[0])} vs {escape(a.effects[1])}: {escape(a.note)}</li>" for a in report.ambiguities
        )
        sections.append(f"<h2>What the data cannot separate</h2><ul>{items}</ul>")
    if report.unlisted is not None:
        items = "".join(f"<li>{escape(k)}: {escape(v)}</li>" for k, v in report.unlisted.meaning.items())
        sections.append(f"<h2>Unlisted effect</h2><p>{escape(report.unlisted.expression)}</p><ul>{items}</ul>")
    return sections


def _groups_table(report: Report) -> str:
    """The differences between clubs and sessions the systematic test measured."""
    rows = [
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
    return _table(["observable", "grouping", "groups", "F", "p", "significant", "extreme groups (mean residual)"], rows)


def _expected_table(report: Report) -> str:
    """The error each observable was expected to have, by part, and where the recordings' own scatter replaced it."""
    model = report.model
    rows = [
        [
            n,
            model.model_error[n],
            model.model_error_source.get(n, ""),
            model.outcome_noise[n],
            model.launch_noise[n],
            model.scatter[n].ratio if n in model.scatter else "",
            model.scatter[n].applied if n in model.scatter else "",
        ]
        for n in OBSERVABLES
    ]
    header = ["observable", "model error", "source", "outcome noise", "launch noise"]
    return _table(header + ["recordings' scatter (x expected)", "scatter used"], rows)


def _opening(report: Report, plots: Plots) -> list[str]:
    """What was diagnosed against what, the statement, the systematic test and where the mismatch is."""
    return [
        (
            f"<h1>Mismatch diagnosis</h1><p>{escape(report.recordings)}: {report.n_shots} shots, {report.n_sessions} "
            f"sessions, observed {', '.join(report.observables)}, {report.trajectories} trajectories. Model: "
            f"{escape(report.model.name)}. {report.seconds:.1f} s.</p>"
        ),
        plots.notice(),
        f"<p class='statement'>{escape(report.statement)}</p>",
        f"<p><b>Systematic:</b> {report.systematic}. Test: "
        f"{escape(json.dumps(report.systematic_test, default=str))}</p>",
        "<h2>Where the mismatch is</h2><ul>"
        + "".join(f"<li>{escape(s)}</li>" for s in report.located.summary)
        + "</ul>",
    ]


def render(diagnosis) -> str:
    """The whole HTML page of a diagnosis."""
    report: Report = diagnosis.report
    plots = Plots(diagnosis)
    sections = [
        *_opening(report, plots),
        _mismatch_table(report),
        _heldout_line(report),
        plots.div("residuals"),
        "<h2>Before and after, held-out shots</h2>" + plots.div("heldout"),
        *_trajectory_section(report, plots),
        "<h2>Candidates</h2>" + plots.div("candidates"),
        _candidates_table(report),
        *_named_sections(report),
        "<h2>Differences between groups</h2>" + _groups_table(report),
        "<h2>Service settings</h2><pre>"
        + escape(report.service_settings.model_dump_json(indent=2, exclude_none=True))
        + "</pre>",
        "<h2>Expected error</h2>" + _expected_table(report),
    ]
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>golfflight diagnose</title><style>{STYLE}</style>"
        f"{plots.head()}</head><body>{''.join(sections)}</body></html>"
    )
