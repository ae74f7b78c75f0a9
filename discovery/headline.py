"""report.json's `headline`: the verdict read in ten seconds, at most three sentences of at most 35 words each, built
from the report alone. (1) What differs: carry, apex and side in metres with their direction, or that the recordings
match the model within noise; (2) the most likely cause with its fitted value ± 1 sigma in a person's terms (thin
air as an altitude, a wind's direction as the golfer feels it, a launch monitor's reading in per cent); (3) the
runner-up: the explanation the data cannot yet tell from it, or the closest one the held-out shots rule out.
report.html's verdict lists (`discovery.verdict`) give the reasoning below it."""

from __future__ import annotations

import numpy as np
from golfflight.discovery.effects import AIR_VARIANTS, DENSITY_ONLY
from golfflight.discovery.effects.ball import DRAG_AND_LIFT
from golfflight.discovery.schema import Ambiguity, EffectResult, Report
from golfflight.discovery.verdict import Flagged, candidate, flagged, ruled_out, strongest_trend
from golfflight.discovery.words import COVARIATE_WORDS, DIRECTIONS, OBSERVABLE_WORDS, UNITS, effect_words, key_words
from golfflight.discovery.words import unit_of, with_unit
from golfflight.flight.air import STANDARD_TEMPERATURE_C, ZERO_CELSIUS_K, Air

MAX_SENTENCES = 3
MAX_WORDS = 35
"""The headline's size: sentences, and words in each (split at whitespace)."""

MOST_OUTCOMES = 3
"""Outcomes named in the first sentence, in the order of OUTCOME_VERBS."""

OUTCOME_VERBS = {
    "carry_y_m": "carry",
    "apex_m": "peak",
    "carry_x_m": "land",
    "flight_time_s": "stay up",
    "landing_angle_deg": "land",
}
"""Each outcome as what the shots do ('carry 12.3 m shorter', 'peak 2.1 m lower', 'land 5.2 m further left'), in
the order a golfer looks at them: carry, apex, side, then flight time and landing angle."""

WIND_SECTORS = (
    "a headwind",
    "from the front right",
    "from the right",
    "from behind right",
    "a tailwind",
    "from behind left",
    "from the left",
    "from the front left",
)
"""The direction a wind blows from as the golfer feels it, per 45° clockwise from the target line."""

MONITOR_SCALES = {"ball_speed_bias": "ball speed", "spin_bias": "spin"}
"""Launch-monitor biases fitted as true = recorded × scale."""

MONITOR_OFFSETS = {
    "launch_angle_bias": ("launch angle", ("low", "high")),
    "launch_direction_bias": ("launch direction", ("too far left", "too far right")),
    "spin_axis_bias": ("spin axis", ("too far left", "too far right")),
}
"""Launch-monitor biases fitted as true = recorded + offset, and how a positive and a negative offset read."""

FORM_SCALES = {
    "drag_scale": "drag",
    "lift_scale": "lift",
    "spin_decay": "spin decay",
    "spin_decay_scale": "spin decay",
    "reynolds_scale": "Reynolds number",
}
"""Coefficient scales (the form effects' `scale` and the ball's parameters) in words."""

OWN_FORM = "the model's own form, not the venue or the monitor"
"""The cause where every named effect is of the model's form."""

STANDARD_DENSITY_KG_M3 = Air.standard().density_kg_m3


def headline(report: Report) -> list[str]:
    """The headline of a report: what differs, the most likely cause with its value, the runner-up."""
    return [s for s in (what_differs(report), likely_cause(report), runner_up(report)) if s]


def word_count(sentence: str) -> int:
    """Words as the headline counts them: split at whitespace ('0.79 ± 0.01' is three)."""
    return len(sentence.split())


def _within(*options: str) -> str:
    """The first option of at most MAX_WORDS words (the last, shortest one where none is)."""
    return next((o for o in options if word_count(o) <= MAX_WORDS), options[-1])


def _places(sd: float, most: int) -> int:
    """Decimals that show an uncertainty to one significant digit, at most `most`: a number read at a glance."""
    if not (sd > 0 and np.isfinite(sd)):
        return min(2, most)
    return int(np.clip(-np.floor(np.log10(sd)), 0, most))


def _plus_minus(value: float, sd: float, most: int = 4) -> str:
    """'0.79 ± 0.01', '4.2 ± 0.3': the uncertainty to one significant digit."""
    places = _places(sd, most)
    return f"{value:.{places}f} ± {sd:.{places}f}"


def _joined(parts: list[str]) -> str:
    """'a', 'a and b', 'a, b and c'."""
    return parts[0] if len(parts) == 1 else f"{', '.join(parts[:-1])} and {parts[-1]}"


def _subject(report: Report) -> tuple[str, str]:
    """Who differs and from what: the shots from the model, or the new shots from the baseline session."""
    if report.baseline is None:
        return "Shots", " than the model"
    return f"Against the baseline session ({report.baseline.n_shots:,} shots), the new shots", ""


def _outcome(f: Flagged) -> str:
    """'carry 12.3 m shorter': the mean difference of one outcome, to the decimal its standard error allows (at most
    one for metres and degrees, two for seconds) but never rounded to nothing."""
    o = f.stat
    unit = UNITS[o.name]
    places = max(_places(o.bias_se, 2 if unit == "s" else 1), _places(abs(o.bias), 3))
    size = f"{abs(o.bias):.{places}f}"
    way = DIRECTIONS[o.name][0 if o.bias > 0 else 1]
    return f"{OUTCOME_VERBS[o.name]} {with_unit(size, unit)} {way}"


def _departure(report: Report) -> str | None:
    """What the systematic test found where no mean difference is flagged: a scatter, a trend or a group."""
    scatter = [f.stat for f in flagged(report.located) if f.scatter]
    if scatter:
        worst = max(scatter, key=lambda o: o.rms_ratio)
        return f"{OBSERVABLE_WORDS[worst.name]} scatters {worst.rms_ratio:.1f} times as much as expected"
    trend = strongest_trend(report.located)
    if trend is not None:
        way = "grows" if trend.slope_per_sd > 0 else "falls"
        launch = COVARIATE_WORDS.get(trend.covariate, (trend.covariate.replace("_", " "),))[0]
        return f"the {OBSERVABLE_WORDS[trend.observable]} difference {way} with {launch}"
    group = min((g for g in report.located.groups if g.significant), key=lambda g: g.p, default=None)
    return None if group is None else f"{OBSERVABLE_WORDS[group.observable]} differs between {group.grouping}s"


def _departs(report: Report) -> bool:
    """Whether the systematic test finds anything: a mean difference, a scatter, a trend or a group."""
    return any(f.bias for f in flagged(report.located)) or _departure(report) is not None


def what_differs(report: Report) -> str:
    """Sentence 1: the outcomes whose mean differs, in metres with their direction, or that nothing does."""
    subject, than = _subject(report)
    by_name = {f.stat.name: f for f in flagged(report.located) if f.bias}
    outcomes = [_outcome(by_name[name]) for name in OUTCOME_VERBS if name in by_name][:MOST_OUTCOMES]
    if outcomes:
        return f"{subject} {_joined(outcomes)}{than}."
    departure = _departure(report)
    if departure is not None:
        return f"{subject} differ from {'the model' if than else 'it'} beyond noise: {departure}."
    if than:
        return "The recordings match the model within noise: nothing departs beyond the expected error."
    return f"{subject} match it within noise."


def _air(name: str, ratio: float, sd: float | None, altitude_m: float | None, assumed_kg_m3: float) -> str:
    """'thin air: 0.79 ± 0.01 × standard density, as at 1,930 m'; without sd, 'thin air (0.79 × standard)'."""
    air = "thin air" if ratio < 1 else "dense air"
    alone = name == DENSITY_ONLY
    standard = abs(assumed_kg_m3 / STANDARD_DENSITY_KG_M3 - 1) < 0.005
    if sd is None:
        return f"{air} ({ratio:.2f} × {'standard' if standard else 'assumed'}{', density alone' if alone else ''})"
    lead = f"{air} (density alone)" if alone else air
    reference = "standard density" if standard else "the assumed density"
    return f"{lead}: {_plus_minus(ratio, sd)} × {reference}, {_where(ratio, altitude_m, standard)}"


def _where(ratio: float, altitude_m: float | None, standard: bool) -> str:
    """Where air is that dense: 'as at 1,930 m' for thin air; dense air at sea level is cold air, 'as in −6 °C air
    at sea level' (standard air is 15 °C at sea level)."""
    if ratio > 1 and standard:
        celsius = (STANDARD_TEMPERATURE_C + ZERO_CELSIUS_K) / ratio - ZERO_CELSIUS_K
        return f"as in {celsius:.0f} °C air at sea level".replace("-", "−")
    if altitude_m is None:
        return "as at another altitude"
    metres = f"{abs(round(altitude_m, -1)):,.0f} m"
    return f"as at {metres}" if altitude_m >= 0 else f"as {metres} below sea level"


def _wind(p: dict[str, float], u: dict[str, float], full: bool) -> str:
    """'a 4.2 ± 0.3 m/s wind from 30° (from the front right)'; brief, 'a 4.2 m/s wind from 30°'."""
    direction = p["from_deg"] % 360
    if not full:
        return f"a {p['speed_mps']:.1f} m/s wind from {direction:.0f}°"
    sector = WIND_SECTORS[int(round(direction / 45)) % len(WIND_SECTORS)]
    return f"a {_plus_minus(p['speed_mps'], u['speed_mps'])} m/s wind from {direction:.0f}° ({sector})"


def _monitor_scale(what: str, scale: float, sd: float, full: bool) -> str:
    """'the launch monitor reads spin 9 % low (true = recorded × 1.09 ± 0.02)'; brief, 'a monitor reading spin 9 %
    low' (true = recorded × scale: a scale above 1 reads low)."""
    percent = f"{100 * abs(scale - 1):.{_places(100 * sd, 1)}f} % {'low' if scale > 1 else 'high'}"
    if not full:
        return f"a monitor reading {what} {percent}"
    return f"the launch monitor reads {what} {percent} (true = recorded × {_plus_minus(scale, sd)})"


def _monitor_offset(name: str, offset: float, sd: float, full: bool) -> str:
    """'the launch monitor reads launch angle 1.2 ± 0.1° low'; brief, 'a monitor reading launch angle 1.2° low'
    (true = recorded + offset: a positive offset reads low, or too far left)."""
    what, (positive, negative) = MONITOR_OFFSETS[name]
    way = positive if offset > 0 else negative
    if not full:
        return f"a monitor reading {what} {abs(offset):.1f}° {way}"
    return f"the launch monitor reads {what} {_plus_minus(abs(offset), sd, 2)}° {way}"


def _ground(height_m: float, sd: float, full: bool) -> str:
    """'the landing ground lies 6.1 ± 0.4 m below the tee'; brief, 'the ground 6.1 m below the tee'."""
    where = "below" if height_m < 0 else "above"
    if not full:
        return f"the ground {abs(height_m):.1f} m {where} the tee"
    return f"the landing ground lies {_plus_minus(abs(height_m), sd, 2)} m {where} the tee"


def _scale(name: str, scale: float, sd: float | None) -> str:
    """'drag × 1.04 ± 0.01'; without sd, 'drag × 1.04'."""
    words = FORM_SCALES.get(name, key_words(name))
    return f"{words} × {_plus_minus(scale, sd) if sd is not None else f'{scale:.2f}'}"


def _ball_scales(effect: EffectResult, full: bool) -> str:
    """The ball's drag and lift scales that depart from 1 beyond 2 sigma (the further one where neither does),
    furthest first, the first with its ± where `full`; not its spin decay, which these outcomes do not measure
    (`ball.DRAG_AND_LIFT`)."""
    p, u = effect.parameters, effect.uncertainty

    def departure(key: str) -> float:
        return abs(p[key] - 1) / u[key] if u.get(key, 0) > 0 else abs(p[key] - 1)

    keys = sorted((k for k in p if k in DRAG_AND_LIFT), key=departure, reverse=True)
    shown = [k for k in keys if departure(k) > 2] or keys[:1]
    return ", ".join(_scale(k, p[k], u.get(k) if full and i == 0 else None) for i, k in enumerate(shown))


def _ball(report: Report, effect: EffectResult, full: bool) -> str:
    """'another ball: it carries 5.2 m shorter (drag × 1.06 ± 0.01)' where it alone explains a carry difference;
    'another ball (drag × 1.06)' otherwise."""
    scales = _ball_scales(effect, full)
    carry = next((f.stat for f in flagged(report.located) if f.bias and f.stat.name == "carry_y_m"), None)
    if full and carry is not None and len(report.effects) == 1:
        way = DIRECTIONS["carry_y_m"][0 if carry.bias > 0 else 1]
        return f"another ball: it carries {abs(carry.bias):.{_places(carry.bias_se, 1)}f} m {way} ({scales})"
    return f"another ball ({scales})"


def _learned(report: Report, full: bool) -> str:
    """The learned extra acceleration, with the share of the error above noise it removes where `full`."""
    share = report.heldout.explained_fraction
    learned = "a learned extra acceleration no library effect matches"
    if not full or share is None:
        return learned
    return f"{learned}, removing {100 * share:.0f} % of the error above noise"


def _listed(effect: EffectResult, full: bool) -> str:
    """An effect this module has no words for: its name and parameters."""
    p, u = effect.parameters, effect.uncertainty
    sizes = ", ".join(
        f"{key_words(k)} {with_unit(_plus_minus(v, u[k]) if full and k in u else f'{v:.3g}', unit_of(k))}"
        for k, v in p.items()
    )
    return f"{effect_words(effect.name)} ({sizes})"


def cause(report: Report, effect: EffectResult, full: bool) -> str:
    """One fitted effect in a person's terms: with its value ± 1 sigma where `full`, briefly otherwise."""
    p, u, name = effect.parameters, effect.uncertainty, effect.name
    if name == "wind":
        return _wind(p, u, full)
    if name == "landing_elevation":
        return _ground(p["height_m"], u["height_m"], full)
    if name == "unlisted":
        return _learned(report, full)
    if name == "ball":
        return _ball(report, effect, full)
    if "ratio" in p:
        sd = u["ratio"] if full else None
        return _air(name, p["ratio"], sd, p.get("equivalent_altitude_m"), report.model.density_kg_m3)
    if name in MONITOR_SCALES:
        return _monitor_scale(MONITOR_SCALES[name], p["scale"], u["scale"], full)
    if name in MONITOR_OFFSETS:
        return _monitor_offset(name, p["offset_deg"], u["offset_deg"], full)
    if name in FORM_SCALES and "scale" in p:
        return _scale(name, p["scale"], u["scale"] if full else None)
    return _listed(effect, full)


def explanation(report: Report, effects: list[EffectResult], full: bool) -> str:
    """Effects joined in words, the first with its ± where `full`, briefly otherwise; effects all of the model's
    form say so."""
    joined = _joined([cause(report, e, full and i == 0) for i, e in enumerate(effects)])
    if not all(e.kind == "form" for e in effects):
        return joined
    return f"{OWN_FORM}: {joined}" if full else f"the model's own form ({joined})"


def likely_cause(report: Report) -> str:
    """Sentence 2: the chosen explanation with its value, or why none is named."""
    if report.systematic and report.effects:
        return _within(
            f"Most likely {explanation(report, report.effects, True)}.",
            f"Most likely {explanation(report, report.effects, False)}.",
        )
    if _departs(report) and _set_aside(report):
        return (
            "No single cause is claimed: the best fit differs between slower and faster shots, as a difference in "
            "the model's own form would."
        )
    if _departs(report):
        return (
            "No single cause explains it on held-out shots: it changes between shots or sessions (shifting wind, "
            "mixed conditions or noisier readings than assumed)."
        )
    return "No cause is needed: no candidate explanation improves held-out shots clearly."


def _set_aside(report: Report) -> str | None:
    """The candidate set aside because its fit differs between slower and faster shots (the systematic test's
    `varies_with_ball_speed`, 'NAME: slower half ...'), where nothing was claimed."""
    text = report.systematic_test.get("varies_with_ball_speed")
    return None if report.systematic or not isinstance(text, str) else text.split(":", 1)[0]


def _rival_words(report: Report, name: str) -> str:
    """An explanation by candidate name, briefly: its fitted effects where the report has them (the venue's air
    from `air_rival` where that is the one), its name in words otherwise."""
    found = candidate(report, name)
    if found is not None:
        return explanation(report, found.effects, False)
    air = report.air_rival
    if air is not None and air.explanation == name:
        return _joined([_air_rival_part(report, part) for part in name.split("+")])
    return effect_words(name)


def _air_rival_part(report: Report, name: str) -> str:
    """One effect of the venue-air rival (`air_rival`): its air with the fitted ratio, any other by name."""
    if name not in AIR_VARIANTS:
        return effect_words(name)
    return _air(name, report.air_rival.ratio, None, None, report.model.density_kg_m3)


def _separation(report: Report, item: Ambiguity) -> str:
    """What would tell the chosen explanation from an ambiguous rival."""
    measurement = item.separating_measurement
    if not measurement:
        return "more shots would tell them apart"
    if measurement in report.observables:
        return "more shots or other clubs would tell them apart"
    return f"recording {OBSERVABLE_WORDS.get(measurement, measurement.replace('_', ' '))} would tell them apart"


def runner_up(report: Report) -> str | None:
    """Sentence 3: the explanation the data cannot yet tell from the chosen one, else the closest one ruled out
    (for recordings the test finds structure in but nothing explains, the closest candidate)."""
    if not report.systematic:
        tried = [c for c in report.candidates if c.effects and c.heldout_error < report.heldout.before_error]
        if not tried or not _departs(report):
            return None
        closest = min(tried, key=lambda c: c.score)
        words = explanation(report, closest.effects, False)
        if closest.name == _set_aside(report):
            return _within(
                f"Closest: {words}, set aside: slower and faster shots fit it differently.",
                f"Closest, set aside as slower and faster shots fit it differently: {closest.name}.",
            )
        return f"Closest: {words}, too small a gain on held-out shots to claim."
    if report.ambiguities:
        item = report.ambiguities[0]
        return _within(
            f"Runner-up, fitting about as well: {_rival_words(report, item.effects[1])}; {_separation(report, item)}.",
            f"Runner-up, fitting about as well: {effect_words(item.effects[1])}.",
        )
    others = ruled_out(report)
    if not others:
        return None
    closest = min(others, key=lambda c: c.score)
    errors = f"error {closest.heldout_error:.2f} against {report.heldout.after_error:.2f}"
    rival = explanation(report, closest.effects, False)
    return _within(f"Runner-up, ruled out on held-out shots ({errors}): {rival}.", f"Runner-up, ruled out: {rival}.")
