"""Venue air as an explanation when the recordings carry none.

Recordings without air (e.g. `golfflight convert pbp`) are flown in the model's own air (ICAO), so a venue's thinner or
denser air is a mismatch like any other, and it can look like another effect: with only the apex recorded, thinner air
and more drag both lower it. Whatever explanation is chosen is therefore set against air density on equal terms, in both
its variants (real air, whose Reynolds number changes with it, and density alone): air in place of every effect it
aliases (the coefficient scales), and in place of the main library effect, the rest kept beside it, each fitted through
the simulator and judged by the tool's own separability test (`report.ambiguity`: the session-bootstrap 95 % interval of
the held-out difference). Air is ruled out only when every one of them is separated from the choice; otherwise air is
listed first among the rivals with the venue air it implies (density ratio and the equivalent standard-atmosphere
altitude at 15 degC) and the observables that would separate them (`diagnose` names air itself where an air explanation
wins: `Diagnoser.in_physical_terms`). Recordings that carry their air get no such comparison: air is not offered as
their explanation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from golfflight.discovery.effects import ALIASES, AIR_VARIANTS, DENSITY_ONLY, Context
from golfflight.discovery.fit import Fit, Problem, Scored, blocks, cluster_bootstrap, per_shot
from golfflight.discovery.invariance import Halves
from golfflight.discovery.noise import ExpectedError
from golfflight.discovery.physical import air_in_place
from golfflight.discovery.recordings import LABELS, OBSERVABLES
from golfflight.discovery.schema import AirRival, Ambiguity
from golfflight.flight.air import STANDARD_TEMPERATURE_C

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


def air_explanations(
    problem: Problem, chosen: Scored, scored: list[Scored], score: Callable[[Fit], Scored], rows: np.ndarray
) -> list[Scored]:
    """Air density (each variant) set against the chosen explanation on equal terms: in place of every effect it
    aliases (its coefficient scales) beside the rest, and in place of its main library effect (the first: the best
    single a pair or a learned correction was built on) beside the rest; air alone where it has no library effect.
    Each is fitted from the chosen parameters and the single air fit (taken from `scored` where already fitted);
    best first."""
    known = {frozenset(e.name for e in s.fit.effects): s for s in scored}
    library = [e.name for e in chosen.fit.effects if e.correction is None and e.name not in AIR_VARIANTS]
    aliases = tuple(name for name in library if name in ALIASES)
    ways = {aliases or tuple(library[:1]), tuple(library[:1])}
    tried = {}
    for variant in AIR_VARIANTS:
        alone = known.get(frozenset([variant]))
        ratio = float(alone.fit.theta[0]) if alone is not None else 1.0
        for replaced in ways:
            found = air_in_place(problem, chosen.fit, list(replaced), variant, ratio, rows, score, known)
            tried[id(found)] = found
    return sorted(tried.values(), key=lambda s: s.error)


def air_rival(
    problem: Problem,
    chosen: Scored,
    predicted: np.ndarray,
    scored: list[Scored],
    score: Callable[[Fit], Scored],
    rows: np.ndarray,
    expected: ExpectedError,
    set_aside: Sequence[Halves] = (),
) -> AirRival:
    """Air density against the chosen explanation (whose predictions are `predicted` [N, 5]) on recordings that carry
    no air: every air explanation of `air_explanations` (fitted and scored with `score` where `scored` lacks it),
    the best of them reported with the venue air it implies, whether the data separate it from the choice and the
    observable that would. Air is ruled out only where every air explanation is separated from the choice: worse
    beyond doubt on held-out shots AND predicting some recorded observable further apart (RMS over the shots) than
    the model's own error there (`expected.model`): a smaller difference can be the model's own error, not the
    physics (as a richer explanation that removes no more than the model's error of response is not claimed,
    `Diagnoser.response_error`). Nor is air ruled out where it was `set_aside` as the model's form, its value changing
    with the launch (`discovery.invariance`): the model's form is there, and the venue's air may be there beside it."""
    named = any(e.name in AIR_VARIANTS for e in chosen.fit.effects)
    rivals = [chosen] if named else air_explanations(problem, chosen, scored, score, rows)
    everyone = np.arange(len(problem.recordings))
    base, count = per_shot(chosen.heldout_z)
    judged = []
    for rival in rivals:
        theirs, _ = per_shot(rival.heldout_z)
        draws = cluster_bootstrap(theirs - base, count, problem.recordings.session, np.random.default_rng(2))
        low, high = (float(q) for q in np.quantile(draws, [0.025, 0.975]))
        difference = problem.predict(rival.fit.effects, rival.fit.theta, everyone)[0] - predicted
        within = _within_model_error(problem, difference, expected.model)
        judged.append((rival, (low, high), difference, within, rival is not chosen and low > 0 and not within))
    varied = next((h for h in set_aside if h.effect in AIR_VARIANTS), None)
    separable = all(item[-1] for item in judged) and varied is None
    rival, (low, high), difference, within, _ = min(judged, key=lambda item: (item[-1], item[0].error))
    effect, block = next((e, b) for e, b in blocks(rival.fit) if e.name in AIR_VARIANTS)
    density = float(np.median(problem.base.density_kg_m3))
    parameters, uncertainty = effect.describe(
        rival.fit.theta[block], rival.fit.covariance[block, block], Context(density, STANDARD_TEMPERATURE_C)
    )
    measurements = _separating(problem, difference)
    variant = "density alone, the Reynolds number unchanged" if effect.name == DENSITY_ONLY else "real air"
    air = (
        f"air {parameters['ratio']:.3f} ± {uncertainty['ratio']:.3f} times as dense as assumed "
        f"({parameters['ratio'] * density:.3f} kg/m³, as at {parameters['equivalent_altitude_m']:.0f} m in the "
        f"standard atmosphere at {STANDARD_TEMPERATURE_C:.0f} °C; {variant})"
    )
    if rival is chosen:
        note = f"the recordings carry no air, and the air is named: {air}"
    else:
        note = _note(problem, chosen, rival, air, difference, measurements, (low, high), within)
        if varied is not None:
            note += (f"; yet air's value changes with the launch ({varied.describe()}): the model's form is there, "
                     "and the venue's air beside it is not ruled out")
        if separable and len(judged) > 1:
            note += f" (every one of the {len(judged)} air explanations tried is worse beyond doubt)"
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
    others = [a for a in ambiguities if not set(AIR_VARIANTS) & set(a.effects[1].split("+"))]
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
