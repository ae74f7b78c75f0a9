"""The verdict that follows report.html's headline (`discovery.headline`), in plain words: what differs (the
quantity, by how much, with its unit and sign, on what share of shots), which physics explains it (the named effect
and its fitted size ± 1 sigma, or none found), the rivals the data cannot tell from it and why, how sure the tool is
(its tests in words) and what to record next. Built from report.json alone (the per-shot residuals, where given, add
the share of shots), so a reader never has to read the JSON to learn the answer."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.discovery.effects import DENSITY_ONLY
from golfflight.discovery.recordings import LABELS, OBSERVABLES
from golfflight.discovery.report import effect_phrase, share_interval
from golfflight.discovery.schema import Ambiguity, Candidate, CovariateStat, Located, ObservableStat, Report
from golfflight.discovery.words import (
    COVARIATE_WORDS,
    DIRECTIONS,
    OBSERVABLE_WORDS,
    UNITS,
    effect_words,
    p_value,
    quantity,
    signed,
)


@dataclass(frozen=True)
class Verdict:
    """One short list per question a reader asks, after the headline (`discovery.headline`)."""

    differs: list[str]
    physics: list[str]
    rivals: list[str]
    sure: list[str]
    record_next: list[str]


@dataclass(frozen=True)
class FamilyTest:
    """One test of the systematic test's Holm family: what it asks, in words, and its p-value."""

    what: str
    p: float


def family_tests(located: Located) -> list[FamilyTest]:
    """Every test of the systematic test's one Holm family (`discovery.locate.locate`), in words."""
    tests = []
    for o in located.observables:
        tests.append(FamilyTest(f"the mean difference in {OBSERVABLE_WORDS[o.name]}", o.bias_p))
        tests.append(FamilyTest(f"the scatter of {OBSERVABLE_WORDS[o.name]}", o.excess_p))
    for c in located.covariates:
        words = COVARIATE_WORDS.get(c.covariate, (c.covariate,))[0]
        tests.append(FamilyTest(f"the trend of {OBSERVABLE_WORDS[c.observable]} with {words}", c.p))
    for g in located.groups:
        tests.append(FamilyTest(f"the difference in {OBSERVABLE_WORDS[g.observable]} between {g.grouping}s", g.p))
    return tests


def holm_adjusted(pvalues: np.ndarray) -> np.ndarray:
    """Holm's adjusted p-values: a test is significant at family-wise level alpha exactly when its adjusted p is
    at most alpha (the same decisions as `discovery.locate.holm`)."""
    p = np.asarray(pvalues, dtype=float)
    if p.size == 0:
        return p
    order = np.argsort(p)
    stepped = np.maximum.accumulate((p.size - np.arange(p.size)) * p[order])
    adjusted = np.empty_like(p)
    adjusted[order] = np.minimum(stepped, 1.0)
    return adjusted


def _share_of_shots(residual: np.ndarray | None, name: str, sign: float) -> str:
    """', on 84 % of shots': the share of shots whose residual has the bias's sign ('' without residuals)."""
    if residual is None:
        return ""
    values = residual[:, OBSERVABLES.index(name)]
    values = values[np.isfinite(values)]
    if values.size == 0:
        return ""
    return f", on {100 * np.mean(np.sign(values) == sign):.0f} % of shots"


def _observable_line(o: ObservableStat, residual: np.ndarray | None, bias_found: bool) -> str:
    """'apex 0.99 ± 0.10 m lower than the model, on 90 % of shots', saying when the shift alone is not significant."""
    words, unit = OBSERVABLE_WORDS[o.name], UNITS[o.name]
    way = DIRECTIONS[o.name][0 if o.bias > 0 else 1]
    share = _share_of_shots(residual, o.name, np.sign(o.bias))
    line = f"{words} {quantity(abs(o.bias), o.bias_se, unit)} {way} than the model{share}"
    if bias_found:
        return line
    return line + f" (this shift alone is not significant; the scatter is {o.rms_ratio:.1f} times the expected error)"


@dataclass(frozen=True)
class Flagged:
    """One observable and whether the systematic test's Holm family flags its mean difference and its scatter."""

    stat: ObservableStat
    bias: bool
    scatter: bool


def flagged(located: Located) -> list[Flagged]:
    """Every observable with the systematic test's decisions on its mean difference and its scatter."""
    adjusted = holm_adjusted(np.array([t.p for t in family_tests(located)]))
    found = adjusted <= located.alpha
    return [Flagged(o, bool(found[2 * k]), bool(found[2 * k + 1])) for k, o in enumerate(located.observables)]


def strongest_trend(located: Located) -> CovariateStat | None:
    """The significant trend of a difference with a launch value that is furthest from chance (None without one)."""
    return max((c for c in located.covariates if c.significant), key=lambda c: abs(c.t), default=None)


def differences(report: Report, residual: np.ndarray | None = None) -> list[str]:
    """What differs, strongest first: each observable the systematic test flags (its mean difference ± standard
    error, with its unit and direction), then the strongest trend with a launch value and group difference."""
    located = report.located
    ranked = []
    for f in flagged(located):
        if f.bias or f.scatter:
            o = f.stat
            strength = abs(o.bias) / o.bias_se if f.bias and o.bias_se > 0 else 0.0
            ranked.append((strength, _observable_line(o, residual, f.bias)))
    out = [line for _, line in sorted(ranked, key=lambda item: -item[0])]
    if not out and located.observables:
        worst = max(located.observables, key=lambda o: o.rms_ratio)
        out.append(
            f"nothing beyond the expected error: the largest departure, {OBSERVABLE_WORDS[worst.name]}, is "
            f"{worst.rms_ratio:.2f} times its expected error (mean difference "
            f"{quantity(worst.bias, worst.bias_se, UNITS[worst.name])})"
        )
    if (c := strongest_trend(located)) is not None:
        words = COVARIATE_WORDS.get(c.covariate, (c.covariate,))[0]
        size = quantity(abs(c.slope_per_sd), None, UNITS[c.observable])
        way = "rises" if c.slope_per_sd > 0 else "falls"
        out.append(
            f"the difference in {OBSERVABLE_WORDS[c.observable]} {way} by {size} per standard deviation of {words}"
        )
    for g in sorted((g for g in located.groups if g.significant), key=lambda g: g.p)[:1]:
        extremes = ", ".join(f"{k} {signed(v, UNITS[g.observable])}" for k, v in g.extremes.items())
        out.append(f"{OBSERVABLE_WORDS[g.observable]} differs between {g.grouping}s ({g.grouping} means: {extremes})")
    return out


def sureness(report: Report) -> list[str]:
    """How sure the tool is: the systematic test's strongest finding after Holm's correction over its family, and
    what the held-out shots say about the chosen explanation."""
    located, held, test = report.located, report.heldout, report.systematic_test
    family = family_tests(located)
    adjusted = holm_adjusted(np.array([t.p for t in family]))
    out = []
    if family:
        best = int(np.argmin(adjusted))
        found = int(np.sum(adjusted <= located.alpha))
        level = f"at the family-wise {100 * located.alpha:g} % level"
        out.append(
            f"The strongest finding, {family[best].what}, has {p_value(adjusted[best])} after Holm correction over "
            f"{len(family)} tests; {found} of the {len(family)} are significant {level}."
            if found
            else f"None of the {len(family)} tests is significant {level} (the smallest p after Holm correction, "
            f"for {family[best].what}, is {adjusted[best]:.2g})."
        )
    errors = f"from {held.before_error:.2f} to {held.after_error:.2f} (mean squared difference in units of the expected error)"
    if report.systematic:
        low, high = held.improvement_ci
        out.append(
            f"On shots held out of the fit the correction lowers the error {errors}; the "
            f"improvement's 95 % interval is {low:.2f} to {high:.2f}, clear of zero."
        )
    elif "best_single" in test:
        gain, low = test.get("best_single_gain", np.nan), test.get("best_single_gain_low", np.nan)
        out.append(
            f"The best candidate, {effect_words(str(test['best_single']))}, lowers the held-out error by only "
            f"{gain:.2g} (its lower bound {low:.2g}), not clearly and materially: no explanation is claimed."
        )
    return out


def _physics(report: Report) -> list[str]:
    """The named effects with their fitted sizes and the share of the excess error they explain, or why none."""
    held = report.heldout
    if not report.systematic:
        return ["None needed: nothing systematic is left to explain."]
    if report.unlisted is not None:
        named = [effect_phrase(e) for e in report.effects if e.name != "unlisted"]
        out = [f"No library effect explains it (best: {' plus '.join(named) or 'none'})."]
        out.append(f"A learned extra acceleration does: {report.unlisted.expression}.")
    else:
        out = [effect_phrase(e)[0].upper() + effect_phrase(e)[1:] + "." for e in report.effects]
    if held.explained_fraction is not None:
        low, high = held.explained_fraction_ci or (np.nan, np.nan)
        share = (
            f"It explains {100 * held.explained_fraction:.0f} % (95 % interval {share_interval(low, high)}) of the "
            "error above measurement noise on held-out shots"
        )
        if held.absorbs_noise:
            share += ", more than the noise allows: part of what it removes is noise"
        out.append(share + ".")
    air = venue_air(report)
    if air and air.get("named") and isinstance(air.get("ratio"), float):
        density = air["ratio"] * report.model.density_kg_m3
        out.append(f"The recordings carry no air, so this is the venue's: {density:.3f} kg/m³.")
        out.append(coefficients_alike(air))
    return out


def coefficients_alike(air: dict) -> str:
    """What else flies as a named air does: the ball's drag, lift and spin torque all scaled by its ratio in the
    assumed air (exactly so for density alone; real air differs from that only through the Reynolds number), and
    the recording that tells the two apart."""
    alone = DENSITY_ONLY in str(air.get("explanation", "")).split("+")
    same = "the same flights" if alone else "nearly the same flights (they differ only through the Reynolds number)"
    return (
        f"A ball whose drag, lift and spin torque were all {air['ratio']:.3f} times the model's would fly {same} in "
        "the assumed air: the venue's air recorded with the shots (its temperature and pressure, or its altitude) "
        "tells the two apart."
    )


def venue_air(report: Report) -> dict | None:
    """The comparison with the venue's air (`discovery.venue_air`: report.json's `air_rival`) as a mapping, where
    the report has one; read by name so the page works with and without it."""
    return report.model_dump().get("air_rival") or None


def _venue_air_words(report: Report, air: dict) -> str:
    """'air 0.899 ± 0.015 times as dense as assumed (1.101 kg/m³, as at about 888 m)' from the comparison."""
    ratio, sd, altitude = air.get("ratio"), air.get("ratio_sd"), air.get("equivalent_altitude_m")
    if not isinstance(ratio, float):
        return air.get("note", "air density")
    density = f"{ratio * report.model.density_kg_m3:.3f} kg/m³"
    where = (
        f", as at about {altitude:.0f} m in the standard atmosphere".replace("-", "−")
        if isinstance(altitude, float)
        else ""
    )
    return f"air {quantity(ratio, sd)} times as dense as assumed ({density}{where})"


def _worse(report: Report, air: dict) -> str:
    """' (held-out error 1.64 against 0.83)' where the comparison has its held-out error."""
    error = air.get("heldout_error")
    return f" (held-out error {error:.2f} against {report.heldout.after_error:.2f})" if isinstance(error, float) else ""


def candidate(report: Report, name: str) -> Candidate | None:
    """The candidate of this name ('wind+spin_bias'), where the report has it."""
    return next((c for c in report.candidates if c.name == name), None)


def ruled_out(report: Report) -> list[Candidate]:
    """The other explanations of the same size the held-out shots tell apart from the chosen one: candidates with as
    many effects, none of them the chosen one's, that are not among the ambiguities."""
    ambiguous = {item.effects[1] for item in report.ambiguities}
    named = {e.name for e in report.effects}
    return [
        c
        for c in report.candidates
        if c.name not in ambiguous and len(c.effects) == len(named) and not named & {e.name for e in c.effects}
    ]


def _rival_line(report: Report, item: Ambiguity) -> str:
    """One rival: its fitted size, that it fits held-out shots about as well, and why the data cannot tell them
    apart (the interval is in the rivals table)."""
    rival = candidate(report, item.effects[1])
    sizes = "; ".join(effect_phrase(e) for e in rival.effects) if rival else ""
    return (
        f"{effect_words(item.effects[1]).capitalize()}{f' ({sizes})' if sizes else ''} fits held-out shots about "
        f"as well (score {item.score_difference:+.2f}, not clearly worse). Why: {item.note}."
    )


def rivals(report: Report) -> list[str]:
    """The explanations the data cannot tell from the chosen one, and the closest one it does rule out."""
    if not report.systematic:
        return []
    out = [_rival_line(report, item) for item in report.ambiguities]
    others = ruled_out(report)
    air = venue_air(report)
    if air and air.get("separable"):
        out.append(
            f"Venue air ruled out: {_venue_air_words(report, air)} fits held-out shots worse beyond doubt{_worse(report, air)}."
        )
        others = [c for c in others if not {"air_density", "air_density_only"} & {e.name for e in c.effects}]
    if others and not report.ambiguities:
        ruled = min(others, key=lambda c: c.score)
        out.append(
            f"Ruled out: {effect_words(ruled.name)} fits held-out shots clearly worse (error "
            f"{ruled.heldout_error:.2f} against {report.heldout.after_error:.2f})."
        )
    if not report.ambiguities:
        out.insert(0, "None: every other explanation with no more effects fits the held-out shots worse beyond doubt.")
    return out


def record_next(report: Report) -> list[str]:
    """The observable that would separate the chosen explanation from its rivals: one not recorded first."""
    by_measurement: dict[str, list[str]] = {}
    for item in report.ambiguities:
        if item.separating_measurement:
            by_measurement.setdefault(item.separating_measurement, []).append(effect_words(item.effects[1]))
    out = []
    for measurement, names in sorted(by_measurement.items(), key=lambda kv: kv[0] in report.observables):
        label = LABELS.get(measurement, measurement.replace("_", " "))
        chosen = effect_words(report.ambiguities[0].effects[0])
        if measurement in report.observables:
            out.append(
                f"More shots, or other clubs and launches: {label} is recorded but separates {chosen} from "
                f"{', '.join(names)} only weakly on these launches."
            )
        else:
            out.append(f"Record {label}: it would separate {chosen} from {', '.join(names)}.")
    if report.systematic and not out:
        out.append("Nothing more to name it: the recorded outcomes already separate it from every rival tried.")
    return out


def verdict(report: Report, residual: np.ndarray | None = None) -> Verdict:
    """The verdict of a report; `residual` [N, 5] (recorded − model) adds the share of shots each difference has."""
    return Verdict(
        differs=differences(report, residual),
        physics=_physics(report),
        rivals=rivals(report),
        sure=sureness(report),
        record_next=record_next(report),
    )
