"""report.html, written for a reader: the headline first (`discovery.headline`: what differs, the most likely cause,
the runner-up, read in ten seconds), then the verdict in plain words (`discovery.verdict`: what differs, which
physics explains it, the rivals, how sure, what to record next), then numbered sections of evidence, each table
with its units in the headers, and the interactive figures (`discovery.figures`: residuals against the launch
values that matter and along the flight, per-session means, held-out residuals and trajectories before and after the
correction, the candidates' scores); report.json itself only in a folded "raw" section at the end.

One self-contained file: the stylesheet (`discovery.style`) and plotly.js are embedded once in the page, nothing is
fetched, so the report opens offline and prints as a report.
The figures need plotly, the optional extra `report`; without it the page keeps every table and the statement and
says which extra to install (`PLOTS_MISSING`): diagnose works without it.
"""

from __future__ import annotations

from html import escape

from golfflight.discovery import tables
from golfflight.discovery.headline import headline
from golfflight.discovery.reach import baseline_sentence
from golfflight.discovery.schema import Report
from golfflight.discovery.style import STYLE
from golfflight.discovery.verdict import Verdict, verdict
from golfflight.discovery.words import OBSERVABLE_WORDS

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


VERDICT_ROWS = (
    ("differs", "What differs"),
    ("physics", "Which physics"),
    ("rivals", "Rivals"),
    ("sure", "How sure"),
    ("record_next", "Record next"),
)
"""The verdict's questions in the order a reader asks them: its fields and their titles."""

KNOWN_FIELDS = {
    "schema_version",
    "baseline",
    "recordings",
    "n_shots",
    "n_sessions",
    "fit_shots",
    "scored_shots",
    "observables",
    "trajectories",
    "model",
    "systematic",
    "systematic_test",
    "located",
    "effects",
    "unlisted",
    "candidates",
    "ambiguities",
    "air_rival",
    "heldout",
    "statement",
    "headline",
    "service_settings",
    "seconds",
}
"""report.json's fields this page has a place for; any other (added since) is shown in words under "Further
findings", so a new finding is never lost between the JSON and the page."""


def _items(lines: list[str]) -> str:
    return "<ul>" + "".join(f"<li>{escape(line[0].upper() + line[1:])}</li>" for line in lines) + "</ul>"


def headline_block(report: Report) -> str:
    """The headline, one paragraph per sentence: what differs, the most likely cause, the runner-up (a value and its
    ± kept on one line)."""
    sentences = "".join(f"<p>{escape(s).replace(' ± ', '&nbsp;±&nbsp;')}</p>" for s in headline(report))
    return f"<div class=headline>{sentences}</div>"


def verdict_section(report: Report, found: Verdict) -> str:
    """The verdict: the headline, one list per question, and the report's own paragraph."""
    rows = "".join(
        f"<dt>{title}</dt><dd>{_items(getattr(found, field))}</dd>"
        for field, title in VERDICT_ROWS
        if getattr(found, field)
    )
    return (
        f"<section class=verdict id=verdict aria-labelledby=verdict-title><h2 id=verdict-title>Verdict</h2>"
        f"{headline_block(report)}<dl>{rows}</dl>"
        f"<p class=paragraph>In one paragraph (report.json's statement): {escape(report.statement)}</p></section>"
    )


def title_block(report: Report) -> str:
    """What was diagnosed against what: the recordings, their size and outcomes, the model, the run time."""
    fields = report.model_dump()
    subsample = ", ".join(
        f"{what} {fields[key]:,}"
        for key, what in (("fit_shots", "fitted on"), ("scored_shots", "scored on"))
        if isinstance(fields.get(key), int) and fields[key] < report.n_shots
    )
    facts = {
        "Shots": f"{report.n_shots:,} in {report.n_sessions:,} sessions"
        + (f" (candidates {subsample})" if subsample else ""),
        "Recorded": ", ".join(OBSERVABLE_WORDS.get(n, n) for n in report.observables)
        + (f"; {report.trajectories:,} trajectories" if report.trajectories else ""),
        "Model": f"{report.model.name}, assumed air {report.model.density_kg_m3:.3f} kg/m³",
        "Run": f"{report.seconds:.1f} s",
    }
    items = "".join(f"<div><dt>{k}</dt><dd>{escape(v)}</dd></div>" for k, v in facts.items())
    return (
        "<header class=title><p class=kicker>golfflight diagnose · recordings against the model</p>"
        f"<h1>{escape(report.recordings or 'Recordings')}</h1><dl class=meta>{items}</dl></header>"
    )


def _further(report: Report) -> list[str]:
    """Fields of report.json this page has no section for (added since), in words."""
    extra = {k: v for k, v in report.model_dump().items() if k not in KNOWN_FIELDS and v not in (None, [], {})}
    if not extra:
        return []
    rows = []
    for key, value in extra.items():
        for item in value if isinstance(value, list) else [value]:
            rows += (
                tables.flat_rows(item, f"{key.replace('_', ' ')}: ")
                if isinstance(item, dict)
                else [[key.replace("_", " "), tables.flat_text(item), ""]]
            )
    columns = [
        tables.TableColumn("finding", "", False),
        tables.TableColumn("value", "in the unit beside it"),
        tables.TableColumn("unit", "", False),
    ]
    return ["<h2>Further findings</h2>" + tables.table(columns, rows)]


def _sections(report: Report, plots: Plots) -> list[str]:
    """The numbered evidence after the verdict."""
    trajectory = tables.trajectory_table(report) + plots.div("along")
    rivals = tables.rivals_table(report)
    return [
        *_baseline(report),
        "<h2>1. What differs</h2>"
        + tables.observables_table(report)
        + tables.trends_table(report)
        + plots.div("residuals"),
        *(["<h2>Along the flight</h2>" + trajectory] if trajectory else []),
        "<h2>2. Which physics: the candidates</h2>"
        "<p class=note>Each explanation fitted through the simulator and scored on shots held out of its fit.</p>"
        + tables.SCORE_NOTE
        + tables.candidates_table(report)
        + plots.div("candidates"),
        *(["<h2>3. Rivals and what would separate them</h2>" + rivals] if rivals else []),
        *_unlisted(report),
        "<h2>4. Held-out shots, before and after</h2>" + tables.heldout_table(report) + plots.div("heldout"),
        "<h2>5. How the tool decided</h2>" + tables.decision_table(report),
        "<h2>Differences between groups</h2>" + tables.groups_table(report),
        "<h2>Service settings</h2><p class=note>The correction as the service's request options "
        "(service_settings.json).</p>" + tables.settings_table(report),
        "<h2>Expected error</h2>" + tables.expected_table(report),
        *_further(report),
    ]


def _baseline(report: Report) -> list[str]:
    """The baseline session the shots were diagnosed against, where there is one."""
    if report.baseline is None:
        return []
    words = escape(baseline_sentence(report.baseline, report.n_shots))
    return [f"<h2>Against the baseline session</h2><p>{words}</p>" + tables.baseline_table(report.baseline)]


def _unlisted(report: Report) -> list[str]:
    """The learned extra acceleration, where the report has one."""
    if report.unlisted is None:
        return []
    items = "".join(f"<li>{escape(k)}: {escape(v)}</li>" for k, v in report.unlisted.meaning.items())
    return [f"<h2>Unlisted effect</h2><p>{escape(report.unlisted.expression)}</p><ul>{items}</ul>"]


def render(diagnosis) -> str:
    """The whole HTML page of a diagnosis."""
    report: Report = diagnosis.report
    plots = Plots(diagnosis)
    found = verdict(report, diagnosis.recordings.observed - diagnosis.before)
    raw = escape(report.model_dump_json(indent=2))
    main = [
        verdict_section(report, found),
        plots.notice(),
        *_sections(report, plots),
        f"<details class=raw><summary>Raw report.json</summary><pre>{raw}</pre></details>",
    ]
    return (
        "<!doctype html><html lang=en><head><meta charset=utf-8>"
        "<meta name=viewport content='width=device-width, initial-scale=1'>"
        f"<title>golfflight diagnose: {escape(report.recordings)}</title><style>{STYLE}</style>{plots.head()}</head>"
        f"<body>{title_block(report)}<main>{''.join(main)}</main>"
        f"<footer>golfflight diagnose · report.json schema {report.schema_version}</footer></body></html>"
    )
