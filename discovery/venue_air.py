"""Venue air as an explanation when the recordings carry none.

Recordings without air (e.g. `golfflight convert pbp`) are flown in the model's own air (ICAO), so a venue's thinner
or denser air is a mismatch like any other, and it can look like another effect: with only the apex recorded,
thinner air and more drag both lower it. Whatever explanation is chosen is therefore set against air density
explicitly: the chosen explanation with air density in place of its main library effect (air density alone for a
single effect; in place of the anchor of a pair, keeping the other), fitted through the simulator and judged by the
tool's own separability test (`report.ambiguity`: the session-bootstrap 95 % interval of the held-out difference).
Where the data cannot separate them, air is listed first among the rivals with the venue air it implies (density
ratio and the equivalent standard-atmosphere altitude at 15 degC) and the observables that would separate them;
where they can, the statement says air is ruled out. Recordings that carry their air get no such comparison: air is
not offered as their explanation.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from golfflight.discovery.effects import EFFECTS, Context, Effect
from golfflight.discovery.fit import Fit, Problem, Scored, cluster_bootstrap, fit, per_shot
from golfflight.discovery.noise import ExpectedError
from golfflight.discovery.recordings import LABELS, OBSERVABLES
from golfflight.discovery.schema import AirRival, Ambiguity
from golfflight.flight.air import STANDARD_TEMPERATURE_C

AIR: Effect = EFFECTS["air_density"]

HOW_THEY_ACT = {
    "drag_scale": "thin air lowers lift and drag together (and the Reynolds number, so the coefficients are read as "
    "for a slower ball) and slows the spin's decay, where a drag scale changes drag alone at every speed and spin",
    "lift_scale": "thin air lowers lift and drag together (and the Reynolds number) and slows the spin's decay, where "
    "a lift scale changes lift alone",
}
"""How air density differs from the library effects it is most often confused with, in words."""

TREND_COVARIATES = ("ball_speed_mps", "spin_rpm")
"""The launch values the two explanations' difference on a recorded observable is followed along (the drag and the
lift of a ball scale differently with its speed and its spin)."""


def air_rival(
    problem: Problem,
    chosen: Scored,
    predicted: np.ndarray,
    scored: list[Scored],
    score: Callable[[Fit], Scored],
    rows: np.ndarray,
    expected: ExpectedError,
) -> AirRival:
    """Air density against the chosen explanation (whose predictions are `predicted` [N, 5]) on recordings that carry
    no air: the explanation with air density in place of the chosen main library effect (fitted and scored with
    `score` where `scored` lacks it), the venue air it implies, whether the data separate the two and the observable
    that would. They are separated where air is worse beyond doubt on held-out shots AND the two predict some
    recorded observable further apart (RMS over the shots) than the model's own error there (`expected.model`): a
    smaller difference can be the model's own error, not the physics (as a richer explanation that removes no more
    than the model's error of response is not claimed, `Diagnoser.response_error`)."""
    names = {e.name for e in chosen.fit.effects}
    rival = chosen if AIR.name in names else _in_place_of_main(problem, chosen, scored, score, rows)
    block = _air_block(rival.fit)
    density = float(np.median(problem.base.density_kg_m3))
    parameters, uncertainty = AIR.describe(
        rival.fit.theta[block], rival.fit.covariance[block, block], Context(density, STANDARD_TEMPERATURE_C)
    )
    base, count = per_shot(chosen.heldout_z)
    theirs, _ = per_shot(rival.heldout_z)
    draws = cluster_bootstrap(theirs - base, count, problem.recordings.session, np.random.default_rng(2))
    low, high = (float(q) for q in np.quantile(draws, [0.025, 0.975]))
    everyone = np.arange(len(problem.recordings))
    difference = problem.predict(rival.fit.effects, rival.fit.theta, everyone)[0] - predicted
    within = _within_model_error(problem, difference, expected.model)
    separable = rival is not chosen and low > 0 and not within
    measurements = _separating(problem, difference)
    air = (
        f"air {parameters['ratio']:.3f} ± {uncertainty['ratio']:.3f} times as dense as assumed "
        f"({parameters['ratio'] * density:.3f} kg/m³, as at {parameters['equivalent_altitude_m']:.0f} m in the "
        f"standard atmosphere at {STANDARD_TEMPERATURE_C:.0f} °C)"
    )
    if rival is chosen:
        note = f"the recordings carry no air, and the air is named: {air}"
    else:
        note = _note(problem, chosen, rival, air, difference, measurements, (low, high), within)
    return AirRival(
        explanation=rival.fit.name,
        named=rival is chosen,
        ratio=parameters["ratio"],
        ratio_sd=uncertainty["ratio"],
        equivalent_altitude_m=parameters["equivalent_altitude_m"],
        heldout_error=rival.error,
        difference_ci=(low, high),
        separable=separable,
        separating_measurement=None if rival is chosen else measurements[0],
        note=note,
    )


def with_air(ambiguities: list[Ambiguity], chosen: Scored, rival: AirRival | None) -> list[Ambiguity]:
    """The ambiguities with air density first where it is an inseparable rival (any other entry naming it dropped)."""
    if rival is None or rival.named or rival.separable:
        return ambiguities
    others = [a for a in ambiguities if AIR.name not in a.effects[1].split("+")]
    first = Ambiguity(
        effects=(chosen.fit.name, rival.explanation),
        score_difference=rival.heldout_error - chosen.error,
        difference_ci=rival.difference_ci,
        separating_measurement=rival.separating_measurement or "",
        note=rival.note,
    )
    return [first] + others


def air_sentence(rival: AirRival | None) -> str:
    """The statement's sentence where air density was compared and ruled out (empty otherwise: an inseparable air
    is the statement's first ambiguity, a named air its explanation)."""
    if rival is None or not rival.separable:
        return ""
    return f" The recordings carry no air; the venue's air is ruled out as the explanation: {rival.note}."


def _air_block(result: Fit) -> slice:
    """The air-density parameter's place in a fit's parameters."""
    start = 0
    for effect in result.effects:
        if effect is AIR:
            return slice(start, start + 1)
        start += effect.size
    raise ValueError(f"{result.name} has no air density")


def _in_place_of_main(
    problem: Problem, chosen: Scored, scored: list[Scored], score: Callable[[Fit], Scored], rows: np.ndarray
) -> Scored:
    """The chosen library effects with air density in place of the first, its main one (the best single effect
    that a pair or a learned correction was built on; air alone where no library effect is left), taken from `scored`
    or fitted from the chosen parameters and the single air fit."""
    known = {frozenset(e.name for e in s.fit.effects): s for s in scored}
    alone = known[frozenset([AIR.name])]
    kept = [(e, block) for e, block in _blocks(chosen.fit) if e.correction is None][1:]
    effects = tuple(e for e, _ in kept) + (AIR,)
    key = frozenset(e.name for e in effects)
    if key not in known:
        start = np.concatenate([chosen.fit.theta[block] for _, block in kept] + [alone.fit.theta])
        known[key] = score(fit(problem, effects, start, rows))
    return known[key]


def _blocks(result: Fit) -> list[tuple[Effect, slice]]:
    """Each effect of a fit with its parameters' place in the fit's parameter vector."""
    out, start = [], 0
    for effect in result.effects:
        out.append((effect, slice(start, start + effect.size)))
        start += effect.size
    return out


def _separating(problem: Problem, difference: np.ndarray) -> list[str]:
    """The observables where two explanations differing by `difference` [N, 5] differ by half an expected sigma or
    more per shot, unrecorded first (recording one separates them), each group largest first; the largest of all
    where none differs that much."""
    in_sigma = np.sqrt(np.nanmean((difference / problem.sigma) ** 2, axis=0))
    recorded = problem.recordings.observed_names
    finite = [j for j in range(len(OBSERVABLES)) if np.isfinite(in_sigma[j])]
    order = sorted(finite, key=lambda j: (OBSERVABLES[j] in recorded, -in_sigma[j]))
    apart = [OBSERVABLES[j] for j in order if in_sigma[j] >= 0.5]
    return apart or [OBSERVABLES[max(finite, key=lambda j: in_sigma[j])]]


def _name_and_unit(observable: str) -> tuple[str, str]:
    """('carry along the line', 'm') from the observable's label."""
    label = LABELS[observable]
    return label.split(" (")[0], label.split("(")[-1].split(",")[0].rstrip(")")


def _within_model_error(problem: Problem, difference: np.ndarray, model_error: dict[str, float]) -> str:
    """Where two explanations differing by `difference` [N, 5] predict every recorded observable closer (RMS over
    the shots) than the model's own error there, those differences in words ("" where one differs by more)."""
    parts = []
    for name in problem.recordings.observed_names:
        j = OBSERVABLES.index(name)
        rms, own = float(np.sqrt(np.nanmean(difference[:, j] ** 2))), model_error.get(name, 0.0)
        if rms >= own:
            return ""
        label, unit = _name_and_unit(name)
        parts.append(f"{label} {rms:.2g} {unit} RMS against the model's own {own:.2g} {unit}")
    return ", ".join(parts)


def _trend(problem: Problem, difference: np.ndarray) -> str:
    """How the two explanations' difference on the recorded observable where it is largest follows the ball speed
    and the spin (per SD of each, from a joint linear fit), in words."""
    recorded = [j for j, name in enumerate(OBSERVABLES) if name in problem.recordings.observed_names]
    size = {j: np.sqrt(np.nanmean((difference[:, j] / problem.sigma[:, j]) ** 2)) for j in recorded}
    j = max(size, key=lambda k: size[k])
    y = difference[:, j]
    launch = problem.recordings.launch
    x = np.column_stack([(launch[c] - launch[c].mean()) / max(launch[c].std(), 1e-12) for c in TREND_COVARIATES])
    finite = np.isfinite(y)
    design = np.column_stack([np.ones(finite.sum()), x[finite]])
    slopes = np.linalg.lstsq(design, y[finite], rcond=None)[0][1:]
    name, unit = _name_and_unit(OBSERVABLES[j])
    per = " and ".join(
        f"{slope:+.2f} {unit} per SD of {covariate.split('_')[0].replace('ball', 'ball speed')}"
        for slope, covariate in zip(slopes, TREND_COVARIATES)
    )
    return (
        f"on the recorded {name} the two differ in how they follow the launch (air minus the chosen explanation: "
        f"{per}), so shots over a wider range of speeds and spins would separate them too"
    )


def _note(
    problem: Problem,
    chosen: Scored,
    rival: Scored,
    air: str,
    difference: np.ndarray,
    measurements: list[str],
    interval: tuple[float, float],
    within: str,
) -> str:
    """The comparison in words: the venue air implied, the held-out errors, whether the model's own error hides the
    difference (`within`, from `_within_model_error`), how air acts unlike the chosen effect, what the two predict
    apart where they differ most and what would separate them."""
    errors = (
        f"held-out error {rival.error:.3f} against {chosen.error:.3f} for {chosen.fit.name}, the difference "
        f"{interval[0]:+.3f} to {interval[1]:+.3f} (95 %)"
    )
    if interval[0] > 0 and not within:
        return f"{rival.fit.name} fits {air} but is worse beyond doubt: {errors}"
    if interval[0] > 0:
        text = (
            f"{rival.fit.name} fits {air}; held-out shots prefer {chosen.fit.name} ({errors}), but the two "
            f"predict what is recorded closer than the model's own error ({within}), so the preference can be the "
            "model's own error, not the physics; "
        )
    else:
        text = f"{rival.fit.name} fits {air} about as well ({errors}); "
    recorded = problem.recordings.observed_names
    apart = []
    for name in [m for m in measurements if m not in recorded][:2] or measurements[:1]:
        j = OBSERVABLES.index(name)
        mean = float(np.nanmean(difference[:, j]))
        in_sigma = float(np.sqrt(np.nanmean((difference[:, j] / problem.sigma[:, j]) ** 2)))
        label, unit = _name_and_unit(name)
        apart.append(f"{label} {mean:+.3g} {unit} on average ({in_sigma:.2g} expected sigma per shot)")
    how = [HOW_THEY_ACT[e.name] for e in chosen.fit.effects if e.name in HOW_THEY_ACT][:1]
    text += (f"{how[0]}, so " if how else "") + (
        f"on these launches the air explanation predicts, against {chosen.fit.name}, {' and '.join(apart)}: "
    )
    text += (
        f"recording {'either' if len(apart) > 1 else 'it'} beside what is recorded would separate them"
        if measurements[0] not in recorded
        else "more shots, or other launches, would separate them"
    )
    return text + "; " + _trend(problem, difference)
