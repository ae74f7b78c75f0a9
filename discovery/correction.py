"""The unlisted effect: a learned extra acceleration in the equations of motion, summarised as a short expression.

The correction is a weighted sum of physical terms of the air-relative velocity v, the spin w and the height h: drag
and Magnus-direction lift, each with weights on |v|^2, |v| and 1 (a coefficient change that depends on speed, i.e.
on the Reynolds number), sideways-only drag, constant side and vertical forces, and a push across or along the line
growing with height and speed (the drag of a wind that grows with height, which no uniform wind has): from the
ground, and from each of two knots up (hinges, |v| max(0, h - H): a wind that only starts above the ground's
shelter; the knots split the flights' median apex in thirds, a linear spline in height over the heights flown, set
by the recordings' flights and not by any effect). It is learned
on top of the best library explanation: the full linearised term library is fitted first (ridge), then terms are
removed one at a time, weakest first, while the weakest is not clearly needed (|t| < MIN_T), at most MAX_TERMS kept:
as small as the fit allows. The kept terms are refitted through the simulator and read out as an expression.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np
from golfflight.discovery.effects import Context, Effect, Parameter, Reported
from golfflight.discovery.fit import Fit, Problem, blocks, fit, residuals_and_jacobian
from golfflight.discovery.recordings import OBSERVABLES
from golfflight.discovery.schema import Unlisted
from golfflight.discovery.simulator import Setup
from golfflight.errors import InputError

NAME = "unlisted"
MIN_T = 4.0
MAX_TERMS = 3
KNOT_SHARES = (1.0 / 3.0, 2.0 / 3.0)
"""The height terms' hinges, as shares of the median apex of the flights the correction is fitted on: with the
shear from the ground, a linear spline in height with equally spaced knots over the heights the balls fly through."""
MIN_KNOT_M = 1.0
"""Below this a hinge is the shear from the ground again: no knots (e.g. putts, recordings that never leave it)."""
HELD = 1e-7
"""A held parameter's bounds lie this share of its range either side of its value (`held`)."""
BOUND = 20.0
"""Each weight stays within this many typical sizes: larger would be a different ball, not a correction."""


@dataclass(frozen=True)
class Term:
    """One physical term of the extra acceleration."""

    name: str
    unit: str
    typical: float
    meaning: str


TERMS: tuple[Term, ...] = (
    Term("-|v| v", "1/m", 2e-4, "extra quadratic drag (a drag coefficient change at every speed)"),
    Term("-v", "1/s", 1e-2, "extra drag growing linearly with speed (a drag change that fades at high speed)"),
    Term("-v/|v|", "m/s^2", 0.3, "extra constant deceleration (a drag change concentrated at low speed)"),
    Term("|v|^2 m", "1/m", 1e-4, "extra Magnus-direction lift, quadratic in speed (m = unit (w x v))"),
    Term("|v| m", "1/s", 5e-3, "extra Magnus-direction lift, linear in speed"),
    Term("m", "m/s^2", 0.3, "extra constant Magnus-direction lift (a lift change concentrated at low speed)"),
    Term("-|v| v_x x", "1/m", 2e-4, "quadratic drag on the sideways motion only"),
    Term("|v|^2 x", "1/m", 1e-4, "a constant side force coefficient (+ pushes right)"),
    Term("|v|^2 z", "1/m", 1e-4, "vertical lift that does not depend on spin"),
    Term("z", "m/s^2", 0.2, "a constant vertical acceleration"),
    Term(
        "|v| h x",
        "1/(m s)",
        5e-4,
        "a push to the right growing with height h and speed (a crosswind growing with height)",
    ),
    Term(
        "|v| h y",
        "1/(m s)",
        5e-4,
        "a push down the line growing with height h and speed (a tailwind growing with height)",
    ),
)


HINGE = re.compile(r"^\|v\| \(h-(?P<knot>[0-9.]+)\)\+ (?P<axis>[xy])$")
"""The name of a hinge term: '|v| (h-9.5)+ x'."""


def hinge_terms(knots: tuple[float, ...]) -> tuple[Term, ...]:
    """The height terms with a hinge at each knot (m): a push across, then along, the line growing with speed and with
    the height above the knot, nothing below it."""
    terms = []
    for knot in knots:
        terms.append(
            Term(
                f"|v| (h-{knot:g})+ x",
                "1/(m s)",
                5e-4,
                f"a push to the right growing with speed and with height above {knot:g} m, none below (a crosswind "
                f"that starts {knot:g} m up)",
            )
        )
        terms.append(
            Term(
                f"|v| (h-{knot:g})+ y",
                "1/(m s)",
                5e-4,
                f"a push down the line growing with speed and with height above {knot:g} m, none below (a tailwind "
                f"that starts {knot:g} m up)",
            )
        )
    return tuple(terms)


def terms_for(knots: tuple[float, ...]) -> tuple[Term, ...]:
    """The whole term library with hinges at `knots`: TERMS, then two terms per knot."""
    return TERMS + hinge_terms(knots)


def term_named(name: str) -> Term:
    """A term of any library by its name (a hinge's knot is in its name)."""
    for term in TERMS:
        if term.name == name:
            return term
    match = HINGE.match(name)
    if match is None:
        raise KeyError(name)
    x, y = hinge_terms((float(match["knot"]),))
    return x if match["axis"] == "x" else y


def knots_for(apex_m: np.ndarray) -> tuple[float, ...]:
    """The hinges (m, to 0.1 m) at KNOT_SHARES of the median apex of the flights; none for low flights."""
    apex = np.asarray(apex_m, dtype=float)
    apex = apex[np.isfinite(apex)]
    if not len(apex):
        return ()
    median = float(np.median(apex))
    return tuple(round(share * median, 1) for share in KNOT_SHARES if share * median >= MIN_KNOT_M)


def features(v: np.ndarray, w: np.ndarray, r: np.ndarray, knots: tuple[float, ...] = ()) -> np.ndarray:
    """Every term's acceleration per unit weight [N, len(terms_for(knots)), 3] at air-relative velocity, spin and
    position [N,3]."""
    speed = np.linalg.norm(v, axis=1)
    sheared = speed * np.maximum(r[:, 2], 0.0)
    unit_v = v / np.maximum(speed, 1e-12)[:, None]
    magnus = np.cross(w, v)
    unit_m = magnus / np.maximum(np.linalg.norm(magnus, axis=1), 1e-12)[:, None]
    zero = np.zeros_like(speed)
    columns = [
        -speed[:, None] * v,
        -v,
        -unit_v,
        (speed**2)[:, None] * unit_m,
        speed[:, None] * unit_m,
        unit_m,
        np.stack([-speed * v[:, 0], zero, zero], 1),
        np.stack([speed**2, zero, zero], 1),
        np.stack([zero, zero, speed**2], 1),
        np.stack([zero, zero, np.ones_like(speed)], 1),
        np.stack([sheared, zero, zero], 1),
        np.stack([zero, sheared, zero], 1),
    ]
    for knot in knots:
        hinged = speed * np.maximum(r[:, 2] - knot, 0.0)
        columns += [np.stack([hinged, zero, zero], 1), np.stack([zero, hinged, zero], 1)]
    return np.stack(columns, axis=1)


def correction_effect(kept: tuple[int, ...], knots: tuple[float, ...] = ()) -> Effect:
    """The learned term restricted to `kept` terms of `terms_for(knots)`, as an effect the fitter treats like any
    other."""
    kept, terms = tuple(kept), terms_for(knots)

    def accelerate(v: np.ndarray, w: np.ndarray, r: np.ndarray, weights: np.ndarray) -> np.ndarray:
        return np.einsum("nk,nkc->nc", weights, features(v, w, r, knots)[:, kept])

    def apply(theta: np.ndarray, conditions: Setup) -> Setup:
        out = conditions.copy()
        out.correction_weights = theta
        return out

    def describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
        names = [terms[i].name for i in kept]
        return (
            {n: float(t) for n, t in zip(names, theta)},
            {n: float(np.sqrt(max(covariance[i, i], 0.0))) for i, n in enumerate(names)},
        )

    parameters = tuple(
        Parameter(
            terms[i].name,
            terms[i].unit,
            0.0,
            -BOUND * terms[i].typical,
            BOUND * terms[i].typical,
            terms[i].typical,
            0.3 * terms[i].typical,
        )
        for i in kept
    )
    names = tuple(terms[i].name for i in kept)
    return Effect(
        NAME, parameters, apply, describe, "a learned extra acceleration: " + expression_of(names, None), accelerate
    )


def is_correction(effect: Effect) -> bool:
    return effect.name == NAME


def expression_of(names: tuple[str, ...], theta: np.ndarray | None) -> str:
    """'a_extra = c1 * term1 + c2 * term2' (symbols where no values are given)."""
    parts = []
    for i, name in enumerate(names):
        coefficient = f"c{i + 1}" if theta is None else f"{theta[i]:.3g}"
        parts.append(f"{coefficient} * [{name}]")
    return (
        "a_extra = " + " + ".join(parts) + " (m/s^2; v air-relative velocity, m = unit (w x v) for spin w, "
        "h height, (h-H)+ = max(0, h - H), x right, y down the line, z up)"
    )


def select_terms(z: np.ndarray, jacobian: np.ndarray, free: int = 0) -> tuple[int, ...]:
    """Backward elimination on the linearised problem: drop the weakest term while |t| < MIN_T or too many. The first
    `free` columns (the library explanation's parameters) are fitted beside the terms and never dropped, so a term
    does not have to take up what the explanation's own parameters would; the kept terms' indices count from after
    them."""
    used = np.isfinite(z)
    r = z[used]
    J_all = jacobian[used]
    kept = list(range(free, J_all.shape[1]))
    while kept:
        columns = list(range(free)) + kept
        J = J_all[:, columns]
        scale = np.linalg.norm(J, axis=0)
        scale[scale == 0] = 1.0
        ridge = 1e-6 * np.eye(len(columns))
        normal = (J / scale).T @ (J / scale) + ridge
        step = np.linalg.solve(normal, -(J / scale).T @ r)
        resid = r + (J / scale) @ step
        s2 = resid @ resid / max(len(r) - len(columns), 1)
        t = (np.abs(step) / np.sqrt(s2 * np.diag(np.linalg.inv(normal))))[free:]
        weakest = int(np.argmin(t))
        if t[weakest] >= MIN_T and len(kept) <= MAX_TERMS:
            return tuple(k - free for k in kept)
        kept.pop(weakest)
    return ()


def fit_correction(problem: Problem, rows: np.ndarray, base: Fit) -> Fit | None:
    """The sparse learned correction on top of `base` (the best library explanation), or None if no term holds. The
    height terms' hinges come from the apex of the flights `base` predicts for these shots.

    The terms are chosen with `base`'s parameters free (`select_terms`), then fitted with them held where `base`
    has them (`held`): the correction is the model's form, what the physical explanation leaves, and fitted jointly
    it trades against that explanation's parameters (1,900 m air, 0.776 x ICAO, concealed in the reference world:
    air fitted 0.74 alone and 0.70 beside a constant drag term fitted with it; held, 0.74 beside it)."""
    knots = knots_for(problem.predict(base.effects, base.theta, rows)[0, :, OBSERVABLES.index("apex_m")])
    everything = correction_effect(tuple(range(len(terms_for(knots)))), knots)
    effects = base.effects + (everything,)
    theta = np.concatenate([base.theta, everything.null])
    z, jacobian = residuals_and_jacobian(problem, effects, theta, rows)
    kept = select_terms(z, jacobian, free=base.k)
    if not kept:
        return None
    term = correction_effect(kept, knots)
    result = fit(problem, held(base) + (term,), np.concatenate([base.theta, term.null]), rows)
    return replace(result, effects=base.effects + (term,))


def held(base: Fit) -> tuple[Effect, ...]:
    """`base`'s effects with each parameter's bounds closed to within HELD of its fitted value: the fitter then
    leaves them where they are (the effects themselves, unchanged, go back into the fit it returns)."""
    effects = []
    for effect, block in blocks(base):
        parameters = []
        for parameter, value in zip(effect.parameters, base.theta[block], strict=True):
            margin = HELD * (parameter.high - parameter.low)
            parameters.append(replace(parameter, low=value - margin, high=value + margin))
        effects.append(replace(effect, parameters=tuple(parameters)))
    return tuple(effects)


def summary(result: Fit, error: float, library_error: float) -> Unlisted:
    """The learned correction of a fit as the report's readable expression with its coefficients."""
    for effect, block in blocks(result):
        if is_correction(effect):
            theta, cov = result.theta[block], result.covariance[block, block]
            names = tuple(p.name for p in effect.parameters)
            return Unlisted(
                expression=expression_of(names, theta),
                terms={n: float(v) for n, v in zip(names, theta)},
                uncertainty={n: float(np.sqrt(max(cov[j, j], 0.0))) for j, n in enumerate(names)},
                meaning={n: term_named(n).meaning for n in names},
                heldout_error=error,
                library_heldout_error=library_error,
            )
    raise InputError(f"{result.name} holds no learned correction")
