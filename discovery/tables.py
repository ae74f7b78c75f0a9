"""report.html's tables: every column headed with its unit (or "row unit" where each row is an observable with its
own), numbers right-aligned in tabular figures with a true minus sign, quantities in words, never a JSON object."""

from __future__ import annotations

from dataclasses import dataclass
from html import escape

import numpy as np
from golfflight.discovery.recordings import LABELS, OBSERVABLES
from golfflight.discovery.report import effect_phrase
from golfflight.discovery.schema import Ambiguity, BaselineInfo, Report
from golfflight.discovery.words import COVARIATE_WORDS, effect_words, key_words, unit_of

ROW_UNIT = "row's unit"
"""The unit line of a column whose rows are observables with different units (each row names its unit)."""

SCORE_UNIT = "mean z²"
"""The unit of a held-out error or score: the mean squared standardized difference z = (recorded − model) / expected
error, 1 where the differences are as large as expected (`SCORE_NOTE` says so above each such table)."""

SCORE_NOTE = (
    "<p class=note>Errors and scores are the mean of z², z = (recorded − model) / its expected error: 1 is as close "
    "as the model's own error and the launch monitor's noise allow on average; lower is better.</p>"
)


@dataclass(frozen=True)
class TableColumn:
    """A table column: its header, the unit line under it ("" for words) and whether it holds numbers."""

    header: str
    unit: str = ""
    numeric: bool = True
    wide: bool = False


def number(value: object, places: int | None = None) -> str:
    """A table cell's text: a float to `places` decimals (else 3 significant digits, no exponent below 10⁶) with a
    true minus sign; anything else as text."""
    if isinstance(value, bool) or not isinstance(value, float | int | np.floating | np.integer):
        return str(value)
    if not np.isfinite(value):
        return "–"
    if isinstance(value, int | np.integer):
        return f"{value:,}"
    if value == 0:
        return "0"
    if places is None:
        size = abs(value)
        places = 0 if size >= 100 else 1 if size >= 10 else 2 if size >= 1 else 3 if size >= 0.01 else 4
    return f"{value:,.{places}f}".replace("-", "−")


def table(columns: list[TableColumn], rows: list[list[object]], caption: str = "", chosen: int | None = None) -> str:
    """An HTML table; row `chosen` is highlighted."""
    head = "".join(
        f"<th{' class=num' if c.numeric else ''} scope=col>{escape(c.header)}"
        + (f"<span class=unit>{escape(c.unit)}</span>" if c.unit else "")
        + "</th>"
        for c in columns
    )
    body = []
    for i, row in enumerate(rows):
        cells = "".join(
            f"<td{' class=num' if c.numeric else ' class=wide' if c.wide else ''}>{escape(number(v))}</td>"
            for c, v in zip(columns, row)
        )
        body.append(f"<tr{' class=chosen' if i == chosen else ''}>{cells}</tr>")
    title = f"<caption>{escape(caption)}</caption>" if caption else ""
    return f"<div class=table-wrap><table>{title}<thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table></div>"


def _label(name: str) -> str:
    return LABELS.get(name, name)


def observables_table(report: Report) -> str:
    """Per observable: the mean difference and its standard error, the RMS against the expected, and the flag."""
    rows = [
        [_label(o.name), o.n, o.bias, o.bias_se, o.rms, o.expected, o.rms_ratio, "yes" if o.significant else ""]
        for o in report.located.observables
    ]
    columns = [
        TableColumn("observable", "with its unit", False),
        TableColumn("shots", "count"),
        TableColumn("mean difference, recorded − model", ROW_UNIT),
        TableColumn("standard error", ROW_UNIT),
        TableColumn("RMS difference", ROW_UNIT),
        TableColumn("expected RMS", ROW_UNIT),
        TableColumn("RMS / expected", "ratio"),
        TableColumn("significant", f"Holm, family-wise {100 * report.located.alpha:g} %", False),
    ]
    return table(columns, rows, "Each outcome, before any correction")


def trends_table(report: Report, count: int = 8) -> str:
    """The strongest trends of the differences with a launch value (the significant ones, at most `count`)."""
    trends = sorted(report.located.covariates, key=lambda c: -abs(c.t))[:count]
    rows = [
        [
            _label(c.observable),
            COVARIATE_WORDS.get(c.covariate, (c.covariate, ""))[0]
            + f" ({COVARIATE_WORDS.get(c.covariate, ('', ''))[1]})",
            c.slope_per_sd,
            c.t,
            c.p,
            "yes" if c.significant else "",
        ]
        for c in trends
    ]
    columns = [
        TableColumn("observable", "with its unit", False),
        TableColumn("launch value", "with its unit", False),
        TableColumn("change per standard deviation", ROW_UNIT),
        TableColumn("t", "ratio"),
        TableColumn("p", "before Holm correction"),
        TableColumn("significant", f"Holm, family-wise {100 * report.located.alpha:g} %", False),
    ]
    return table(columns, rows, f"The {len(rows)} strongest trends with the launch")


def groups_table(report: Report) -> str:
    """The differences between clubs and sessions the systematic test measured."""
    rows = [
        [
            _label(g.observable),
            g.grouping,
            g.n_groups,
            g.f,
            g.p,
            "yes" if g.significant else "",
            ", ".join(f"{k} {number(v, 2)}" for k, v in g.extremes.items()),
        ]
        for g in report.located.groups
    ]
    columns = [
        TableColumn("observable", "with its unit", False),
        TableColumn("between", "club or session", False),
        TableColumn("groups", "count"),
        TableColumn("F", "ratio"),
        TableColumn("p", "before Holm correction"),
        TableColumn("significant", f"Holm, family-wise {100 * report.located.alpha:g} %", False),
        TableColumn("most different groups: mean difference", ROW_UNIT, False),
    ]
    return table(columns, rows)


def trajectory_table(report: Report) -> str:
    """The mean position difference along the recorded flights ("" without trajectories)."""
    rows = [
        [t.phase, t.height_band, t.n_samples, t.n_shots, t.across_m, t.along_m, t.height_m, t.rms_m]
        for t in report.located.trajectory
    ]
    if not rows:
        return ""
    columns = [
        TableColumn("phase", "", False),
        TableColumn("height band", "m", False),
        TableColumn("samples", "count"),
        TableColumn("shots", "count"),
        TableColumn("across (+ right)", "m"),
        TableColumn("along", "m"),
        TableColumn("height", "m"),
        TableColumn("RMS", "m"),
    ]
    return table(columns, rows, "Mean position difference, recorded − model")


def heldout_table(report: Report) -> str:
    """Per observable: the held-out RMS before and after the correction and the improvement with its interval."""
    held = report.heldout
    rows = []
    for name in OBSERVABLES:
        if name in held.before:
            gain, low, high = held.improvement_by_observable.get(name, (np.nan, np.nan, np.nan))
            rows.append([_label(name), held.before[name], held.after[name], held.expected[name], gain, low, high])
    columns = [
        TableColumn("observable", "with its unit", False),
        TableColumn("RMS, model as is", ROW_UNIT),
        TableColumn("RMS, corrected", ROW_UNIT),
        TableColumn("expected RMS", ROW_UNIT),
        TableColumn("improvement", SCORE_UNIT),
        TableColumn("95 % interval from", SCORE_UNIT),
        TableColumn("to", SCORE_UNIT),
    ]
    return table(columns, rows, f"Shots held out of the fit (folds: {held.grouping})")


def candidates_table(report: Report, count: int = 15) -> str:
    """The `count` best candidates with their fitted sizes in words (± 1 sigma) and held-out scores; the chosen one
    highlighted."""
    named = "+".join(e.name for e in report.effects)
    ranked = sorted(report.candidates, key=lambda c: c.score)[:count]
    rows = [
        [
            effect_words(c.name),
            "; ".join(effect_phrase(e) for e in c.effects),
            c.n_parameters,
            c.heldout_error,
            c.penalty,
            c.score,
        ]
        for c in ranked
    ]
    chosen = next((i for i, c in enumerate(ranked) if report.systematic and c.name == named), None)
    columns = [
        TableColumn("explanation", "", False),
        TableColumn("fitted size", "± 1 standard deviation, with units", False, wide=True),
        TableColumn("parameters", "count"),
        TableColumn("held-out error", SCORE_UNIT),
        TableColumn("penalty", SCORE_UNIT),
        TableColumn("score", SCORE_UNIT),
    ]
    return table(columns, rows, f"The {len(rows)} best of {len(report.candidates)} candidates", chosen)


def _extra_fields(item: Ambiguity) -> str:
    """Fields of an ambiguity this page has no column for (added since), as 'name: value' text."""
    known = {"effects", "score_difference", "difference_ci", "separating_measurement", "note"}
    extra = {k: v for k, v in item.model_dump().items() if k not in known and v is not None}
    return "; ".join(f"{key_words(k)}: {flat_text(v, unit_of(k))}" for k, v in extra.items())


def rivals_table(report: Report) -> str:
    """The explanations the data cannot tell from the chosen one, and what would separate them ("" without)."""
    rows = [
        [
            effect_words(a.effects[1]),
            a.score_difference,
            a.difference_ci[0],
            a.difference_ci[1],
            _label(a.separating_measurement),
            "yes" if a.separating_measurement in report.observables else "no",
            a.note + (f" ({_extra_fields(a)})" if _extra_fields(a) else ""),
        ]
        for a in report.ambiguities
    ]
    if not rows:
        return ""
    columns = [
        TableColumn("rival", "", False),
        TableColumn("score − chosen's", SCORE_UNIT),
        TableColumn("95 % interval from", SCORE_UNIT),
        TableColumn("to", SCORE_UNIT),
        TableColumn("separating observable", "with its unit", False),
        TableColumn("recorded", "", False),
        TableColumn("why they cannot be told apart", "", False, wide=True),
    ]
    return table(columns, rows)


def flat_text(value: object, unit: str = "") -> str:
    """A value of report.json as words: numbers with their unit, lists joined, mappings as 'name value' pairs."""
    if isinstance(value, dict):
        return "; ".join(f"{key_words(k)} {flat_text(v, unit_of(k))}" for k, v in value.items())
    if isinstance(value, list | tuple):
        return ", ".join(flat_text(v, unit) for v in value)
    text = number(value) if isinstance(value, float) else str(value)
    return f"{text}{unit}" if unit == "°" else f"{text} {unit}".strip()


def flat_rows(value: dict, prefix: str = "") -> list[list[object]]:
    """(setting, value, unit) rows of a nested mapping, names in words."""
    rows = []
    for key, item in value.items():
        name = f"{prefix}{key_words(key)}"
        if isinstance(item, dict):
            rows += flat_rows(item, f"{name}: ")
        elif item is not None:
            unit = unit_of(key) or ("×" if key.endswith(("scale", "ratio")) else "")
            rows.append([name, item if isinstance(item, float) else flat_text(item), unit])
    return rows


def settings_table(report: Report) -> str:
    """The service settings of the correction, one setting a row ("" where there are none)."""
    rows = flat_rows(report.service_settings.model_dump(exclude_none=True))
    if not rows:
        return "<p>None: the model as is needs no correction.</p>"
    return table(
        [TableColumn("setting", "", False), TableColumn("value", "in the unit beside it"), TableColumn("unit", "", False)], rows
    )


def expected_table(report: Report) -> str:
    """The error each observable was expected to have, by part, and where the recordings' own scatter replaced it."""
    model = report.model
    rows = [
        [
            _label(n),
            model.model_error[n],
            model.model_error_source.get(n, ""),
            model.outcome_noise[n],
            model.launch_noise[n],
            model.scatter[n].ratio if n in model.scatter else np.nan,
            ("yes" if model.scatter[n].applied else "no") if n in model.scatter else "",
        ]
        for n in OBSERVABLES
        if n in model.model_error
    ]
    columns = [
        TableColumn("observable", "with its unit", False),
        TableColumn("model's own error", ROW_UNIT),
        TableColumn("source", "", False),
        TableColumn("outcome noise", ROW_UNIT),
        TableColumn("launch noise", ROW_UNIT),
        TableColumn("recordings' scatter", "times the expected"),
        TableColumn("scatter used", "", False),
    ]
    return table(columns, rows)


def _decision_value(key: str, value: object) -> object:
    """A systematic-test entry for a reader: candidates in words, yes/no for a flag, numbers as they are."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, str) and key.startswith("best_"):
        return effect_words(value)
    return value if isinstance(value, float) else flat_text(value)


def decision_table(report: Report) -> str:
    """The numbers the choice was made on (`systematic_test`), one a row, names in words."""
    test = report.systematic_test
    rows = [[key_words(k).replace("gain low", "gain, lower bound"), _decision_value(k, v)] for k, v in test.items()]
    columns = [TableColumn("quantity", "", False), TableColumn("value", f"{SCORE_UNIT} where a number")]
    return table(columns, rows)


def baseline_table(baseline: BaselineInfo) -> str:
    """What the baseline session taught and how far it reaches: its held-out error before and after the learned form,
    the discrepancy left per observable, its airs and the new shots outside its launches."""
    def span(values: list[float]) -> str:
        return " – ".join(number(v, 3) for v in values)

    discrepancy = [
        [f"discrepancy far from the baseline: {LABELS[name]}", sd, unit_of(name)]
        for name, sd in baseline.discrepancy_sd.items()
    ]
    rows: list[list[object]] = [
        ["baseline shots", baseline.n_shots, "shots"],
        ["held-out error of the model as is", baseline.heldout_error_before, SCORE_UNIT],
        ["held-out error with the learned form", baseline.heldout_error_after, SCORE_UNIT],
        *discrepancy,
        ["air density of the baseline, lowest – highest", span(baseline.baseline_density_kg_m3), "kg/m³"],
        ["air density assumed for the new shots", span(baseline.new_density_kg_m3), "kg/m³"],
        ["new shots outside the baseline's launches", baseline.outside_shots, "shots"],
    ]
    columns = [
        TableColumn("quantity", "", False),
        TableColumn("value", "in the unit beside it"),
        TableColumn("unit", "", False),
    ]
    return SCORE_NOTE + table(columns, rows)
