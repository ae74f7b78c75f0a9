"""The readable parts of a diagnosis: fitted effects in the report's conventions, the service settings, the
ambiguities (explanations the data cannot tell apart, and what measurement would) and the plain-words statement."""

from __future__ import annotations

import numpy as np
from golfflight.discovery.effects import EFFECTS, Context
from golfflight.discovery.effects.parts import plus_minus as plus_minus
from golfflight.discovery.fit import Fit, Problem, Scored, cluster_bootstrap, per_shot
from golfflight.discovery.locate import has_structure
from golfflight.discovery.recordings import OBSERVABLES
from golfflight.discovery.schema import Ambiguity, CorrectionSettings, EffectResult, Heldout, Located, Unlisted
from golfflight.discovery.words import OBSERVABLE_WORDS, UNITS, effect_words, key_words, quantity, unit_of, with_unit

MATERIAL = 0.05
"""Share above the expected error that counts as a material excess (as in `discovery.diagnose`)."""

CARRY_ALIKE = {"wind", "air_density", "air_density_only", "ball_speed_bias", "landing_elevation", "drag_scale"}
"""Effects that all move carry along the line and need the other observables to be told apart."""


def effect_results(result: Fit, context: Context) -> list[EffectResult]:
    """Each effect of a fit with its reported parameters and 1-sigma uncertainties."""
    out, start = [], 0
    for effect in result.effects:
        block = slice(start, start + effect.size)
        parameters, uncertainty = effect.describe(result.theta[block], result.covariance[block, block], context)
        out.append(EffectResult(name=effect.name, kind=effect.kind, parameters=parameters, uncertainty=uncertainty))
        start += effect.size
    return out


def service_settings(
    effects: list[EffectResult], context: Context, wind_factor: float | None = None
) -> CorrectionSettings:
    """The correction as the service's request options (wind, air) plus launch and model corrections, each effect's
    own (`Effect.setting`). `wind_factor` (the log profile's uniform-equivalent factor along the corrected flights)
    adds the fitted wind as a 10 m station reading with the log profile."""
    settings = CorrectionSettings()
    for effect in effects:
        known = EFFECTS.get(effect.name)
        if known is not None and known.setting is not None:
            known.setting(settings, effect.parameters, context, wind_factor)
    return settings


def _separation(problem: Problem, predicted: np.ndarray, b: Fit) -> tuple[str, float, float]:
    """(observable, RMS difference, the same in expected sigmas) where the explanation that predicts `predicted`
    [N, 5] and another fitted one differ most."""
    rows = np.arange(len(problem.recordings))
    diff = predicted - problem.predict(b.effects, b.theta, rows)[0]
    rms = np.sqrt(np.nanmean(diff**2, axis=0))
    in_sigma = np.sqrt(np.nanmean((diff / problem.sigma) ** 2, axis=0))
    j = int(np.nanargmax(in_sigma))
    return OBSERVABLES[j], float(rms[j]), float(in_sigma[j])


def ambiguity(
    problem: Problem,
    chosen: Scored,
    predicted: np.ndarray,
    scored: list[Scored],
    rng: np.random.Generator,
    limit: int = 3,
) -> list[Ambiguity]:
    """Candidates with no more effects than the chosen one (whose predictions are `predicted` [N, 5]) whose
    held-out error is not clearly worse."""
    out = []
    mine = {e.name for e in chosen.fit.effects}
    base, count = per_shot(chosen.heldout_z)
    for other in sorted(scored, key=lambda s: s.score):
        names = {e.name for e in other.fit.effects}
        if other is chosen or len(names) > len(mine) or names <= mine or names >= mine:
            continue
        theirs, _ = per_shot(other.heldout_z)
        draws = cluster_bootstrap(theirs - base, count, problem.recordings.session, rng)
        low, high = (float(q) for q in np.quantile(draws, [0.025, 0.975]))
        if low > 0:
            continue
        observable, rms, in_sigma = _separation(problem, predicted, other.fit)
        recorded = observable in problem.recordings.observed_names
        label, apart = OBSERVABLE_WORDS[observable], with_unit(f"{rms:.2g}", UNITS[observable])
        if in_sigma < 0.5:
            note = (
                f"the two explanations predict nearly the same for every outcome of these launches (at most "
                f"{in_sigma:.2g} expected sigma apart, in {label}): launches they treat differently (other clubs, "
                "speeds or spins) or recorded trajectories would separate them"
            )
        elif recorded:
            note = (
                f"on these shots the two explanations differ most in {label}, by {apart} RMS "
                f"({in_sigma:.2g} expected sigma per shot): more shots, or clubs with other launches, would separate them"
            )
        else:
            note = (
                f"{label} is not recorded; the two explanations predict it {apart} apart RMS "
                f"({in_sigma:.2g} expected sigma per shot): recording it would separate them"
            )
        out.append(
            Ambiguity(
                effects=(chosen.fit.name, other.fit.name),
                score_difference=float(other.score - chosen.score),
                difference_ci=(low, high),
                separating_measurement=observable,
                note=note,
            )
        )
        if len(out) == limit:
            break
    return out


def effect_phrase(effect: EffectResult) -> str:
    """The fitted effect in words with its size ± 1 sigma and units ('air 0.914 ± 0.002 times as dense as assumed
    (as at about 755 ± 12 m)'), each effect's own (`Effect.phrase`); an effect without one lists its parameters."""
    p, u = effect.parameters, effect.uncertainty
    known = EFFECTS.get(effect.name)
    if known is not None and known.phrase is not None:
        return known.phrase(p, u)
    if effect.name == "unlisted":
        return "a learned extra acceleration (see unlisted)"
    sizes = ", ".join(f"{key_words(k)} {quantity(v, u.get(k), unit_of(k))}" for k, v in p.items())
    return f"{effect_words(effect.name)} ({sizes})"


def _mismatch(located: Located) -> str:
    stats = {o.name: o for o in located.observables}
    parts = []
    if "carry_y_m" in stats:
        b = stats["carry_y_m"].bias
        parts.append(f"carry about {abs(b):.1f} m {'less' if b < 0 else 'more'} down the line than the model")
    others = []
    for name, unit in (("carry_x_m", "m"), ("apex_m", "m"), ("flight_time_s", "s"), ("landing_angle_deg", "°")):
        if name in stats and stats[name].significant:
            others.append(f"{name.split('_')[0] if name != 'carry_x_m' else 'side'} {stats[name].bias:+.2f} {unit}")
    text = "The recordings " + (parts[0] if parts else "depart from the model")
    return text + (f" ({', '.join(others)})" if others else "")


def _contrast(chosen: Scored, scored: list[Scored], ambiguous: set[str]) -> str:
    """Which observables rule out the closest rival explanation of the same size ("" when they do not)."""
    mine = {e.name for e in chosen.fit.effects}
    rivals = [
        s
        for s in scored
        if s is not chosen
        and len(s.fit.effects) == len(chosen.fit.effects)
        and not ({e.name for e in s.fit.effects} & mine)
    ]
    if not rivals:
        return ""
    if mine & CARRY_ALIKE:
        carry_rivals = [s for s in rivals if {e.name for e in s.fit.effects} & CARRY_ALIKE]
        rivals = carry_rivals or rivals
    rival = min(rivals, key=lambda s: s.score)
    if rival.fit.name in ambiguous:
        return ""
    observed = np.isfinite(chosen.heldout_z).any(axis=0) & np.isfinite(rival.heldout_z).any(axis=0)
    worse = np.full(len(OBSERVABLES), np.nan)
    worse[observed] = np.nanmean(rival.heldout_z[:, observed] ** 2, axis=0) - np.nanmean(
        chosen.heldout_z[:, observed] ** 2, axis=0
    )
    order = [
        OBSERVABLES[j] for j in np.argsort(-np.nan_to_num(worse, nan=-np.inf)) if np.isfinite(worse[j]) and worse[j] > 0
    ]
    if not order:
        return ""
    names = " and ".join(n.replace("_m", "").replace("_s", "").replace("_deg", "").replace("_", " ") for n in order[:2])
    return (
        f"{names} say {chosen.fit.name}, not {rival.fit.name} (held-out error {chosen.error:.2f} vs {rival.error:.2f})"
    )


SHARE_CEILING = 5.0
"""Above this the upper end of an explained share's interval is not written as a number: a bootstrap draw whose
excess over the noise floor is near zero makes the share of it anything (a real set once read '7–2825358664 %')."""


def share_interval(low: float, high: float) -> str:
    """'42–278 %', or '7 % to over 500 %' when the upper end is beyond SHARE_CEILING."""
    if not np.isfinite(high) or high > SHARE_CEILING:
        return f"{100 * low:.0f} % to over {100 * SHARE_CEILING:.0f} %"
    return f"{100 * low:.0f}–{100 * high:.0f} %"


def statement(
    systematic: bool,
    located: Located,
    effects: list[EffectResult],
    unlisted: Unlisted | None,
    heldout: Heldout,
    ambiguities: list[Ambiguity],
    scored: list[Scored],
    chosen: Scored,
) -> str:
    """One paragraph in plain words."""
    if not systematic:
        worst = max(located.observables, key=lambda o: o.rms_ratio, default=None)
        best = min(scored, key=lambda s: s.score, default=None)
        gain = (
            f" The best candidate, {best.fit.name}, would remove {heldout.before_error - best.error:.3g} of a "
            f"held-out error of {heldout.before_error:.3g} (1 = the expected error)."
            if best
            else ""
        )
        if has_structure(located):
            return (
                f"The systematic test finds structure the expected error does not make ({located.summary[0]}), but "
                "no candidate explains it consistently on held-out groups: it varies from shot to shot or group to "
                "group (changing wind, mixed conditions or noisier measurements than assumed) rather than being one "
                "systematic effect." + gain
            )
        tail = f" The largest departure is {worst.name} at {worst.rms_ratio:.2f}x its expected error." if worst else ""
        return (
            "No systematic mismatch: no shift of a mean, trend with the launch, difference between clubs or "
            "sessions, or scatter beyond the model's own error and the launch monitor's noise (Holm, family-wise "
            f"{located.alpha:g})." + tail + gain
        )
    sentences = [_mismatch(located) + "."]
    contrast = _contrast(chosen, scored, {a.effects[1] for a in ambiguities})
    named = [effect_phrase(e) for e in effects if e.name != "unlisted"]
    explains = ""
    if heldout.explained_fraction is not None:
        low, high = heldout.explained_fraction_ci or (np.nan, np.nan)
        explains = (
            f" explains {100 * heldout.explained_fraction:.0f} % (95 % interval {share_interval(low, high)}) "
            "of the excess error on held-out shots"
        )
        if heldout.absorbs_noise:
            explains += (
                " (over 100 % beyond doubt: it goes below what measurement noise alone leaves, so it absorbs noise "
                "and the share is no measure of success)"
            )
    if unlisted is not None:
        lead = (
            f"No library effect explains it ({' plus '.join(named) + ' leaves' if named else 'the best leaves'} a held-out "
            f"error of {unlisted.library_heldout_error:.2f}); a learned extra acceleration, {unlisted.expression},"
        )
        sentences.append(lead + explains + ", and is reported as unlisted.")
    else:
        lead = (contrast[0].upper() + contrast[1:] + ": " if contrast else "") + " plus ".join(named)
        sentences.append(lead[0].upper() + lead[1:] + explains + ".")
    for item in ambiguities[:1]:
        sentences.append(f"The data cannot firmly tell {item.effects[0]} from {item.effects[1]}: {item.note}.")
    return " ".join(sentences) + form_sentence(effects)


def form_sentence(effects: list[EffectResult]) -> str:
    """Where every named effect is of the model's form, that in words: the recordings' physics differs from the
    model's in form, and no venue condition or launch-monitor bias is claimed (empty otherwise)."""
    if not effects or any(e.kind != "form" for e in effects):
        return ""
    return (
        " This is the model's form: the recordings' physics differs from the model's own (coefficient scales or a "
        "learned correction), not a condition of the venue or a bias of the launch monitor."
    )
