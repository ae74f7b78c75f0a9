"""The unlisted effect: a learned extra acceleration in the equations of motion, summarised as a short expression.

The correction is a weighted sum of physical terms of the air-relative velocity v, the spin w and the height h: drag
and Magnus-direction lift, each with weights on |v|^2, |v| and 1 (a coefficient change that depends on speed, i.e.
on the Reynolds number), sideways-only drag, constant side and vertical forces, and a push across or along the line
growing with height and speed (the drag of a wind that grows with height, which no uniform wind has). It is learned
on top of the best library explanation: the full linearised term library is fitted first (ridge), then terms are
removed one at a time, weakest first, while the weakest is not clearly needed (|t| < MIN_T), at most MAX_TERMS kept:
as small as the fit allows. The kept terms are refitted through the simulator and read out as an expression.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from discovery.effects import Context, Effect, Parameter, Reported
from discovery.fit import Fit, Problem, fit, residuals_and_jacobian
from discovery.schema import Unlisted
from discovery.simulator import Setup

NAME = "unlisted"
MIN_T = 4.0
MAX_TERMS = 3
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


def features(v: np.ndarray, w: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Every term's acceleration per unit weight [N, len(TERMS), 3] at air-relative velocity, spin and position
    [N,3]."""
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
    return np.stack(columns, axis=1)


def correction_effect(kept: tuple[int, ...]) -> Effect:
    """The learned term restricted to `kept` terms, as an effect the fitter treats like any other."""
    kept = tuple(kept)

    def accelerate(v: np.ndarray, w: np.ndarray, r: np.ndarray, weights: np.ndarray) -> np.ndarray:
        return np.einsum("nk,nkc->nc", weights, features(v, w, r)[:, kept])

    def apply(theta: np.ndarray, conditions: Setup) -> Setup:
        out = conditions.copy()
        out.correction_weights = theta
        return out

    def describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
        names = [TERMS[i].name for i in kept]
        return (
            {n: float(t) for n, t in zip(names, theta)},
            {n: float(np.sqrt(max(covariance[i, i], 0.0))) for i, n in enumerate(names)},
        )

    parameters = tuple(
        Parameter(
            TERMS[i].name,
            TERMS[i].unit,
            0.0,
            -BOUND * TERMS[i].typical,
            BOUND * TERMS[i].typical,
            TERMS[i].typical,
            0.3 * TERMS[i].typical,
        )
        for i in kept
    )
    return Effect(
        NAME, parameters, apply, describe, "a learned extra acceleration: " + expression_of(kept, None), accelerate
    )


def is_correction(effect: Effect) -> bool:
    return effect.name == NAME


def expression_of(kept: tuple[int, ...], theta: np.ndarray | None) -> str:
    """'a_extra = c1 * term1 + c2 * term2' (symbols where no values are given)."""
    parts = []
    for i, index in enumerate(kept):
        coefficient = f"c{i + 1}" if theta is None else f"{theta[i]:.3g}"
        parts.append(f"{coefficient} * [{TERMS[index].name}]")
    return (
        "a_extra = " + " + ".join(parts) + " (m/s^2; v air-relative velocity, m = unit (w x v) for spin w, "
        "h height, x right, y down the line, z up)"
    )


def select_terms(z: np.ndarray, jacobian: np.ndarray) -> tuple[int, ...]:
    """Backward elimination on the linearised problem: drop the weakest term while |t| < MIN_T or too many."""
    used = np.isfinite(z)
    r = z[used]
    J_all = jacobian[used]
    kept = list(range(J_all.shape[1]))
    while kept:
        J = J_all[:, kept]
        scale = np.linalg.norm(J, axis=0)
        scale[scale == 0] = 1.0
        ridge = 1e-6 * np.eye(len(kept))
        normal = (J / scale).T @ (J / scale) + ridge
        step = np.linalg.solve(normal, -(J / scale).T @ r)
        resid = r + (J / scale) @ step
        s2 = resid @ resid / max(len(r) - len(kept), 1)
        t = np.abs(step) / np.sqrt(s2 * np.diag(np.linalg.inv(normal)))
        weakest = int(np.argmin(t))
        if t[weakest] >= MIN_T and len(kept) <= MAX_TERMS:
            return tuple(kept)
        kept.pop(weakest)
    return ()


def fit_correction(problem: Problem, rows: np.ndarray, base: Fit) -> Fit | None:
    """The sparse learned correction on top of `base` (the best library explanation), or None if no term holds."""
    everything = correction_effect(tuple(range(len(TERMS))))
    effects = base.effects + (everything,)
    theta = np.concatenate([base.theta, everything.null])
    z, jacobian = residuals_and_jacobian(problem, effects, theta, rows)
    kept = select_terms(z, jacobian[..., base.k :])
    if not kept:
        return None
    term = correction_effect(kept)
    return fit(problem, base.effects + (term,), np.concatenate([base.theta, term.null]), rows)


def summary(result: Fit, error: float, library_error: float) -> Unlisted:
    """The learned correction of a fit as the report's readable expression with its coefficients."""
    start = 0
    for effect in result.effects:
        if is_correction(effect):
            theta = result.theta[start : start + effect.size]
            cov = result.covariance[start : start + effect.size, start : start + effect.size]
            kept = tuple(next(i for i, t in enumerate(TERMS) if t.name == p.name) for p in effect.parameters)
            return Unlisted(
                expression=expression_of(kept, theta),
                terms={TERMS[i].name: float(v) for i, v in zip(kept, theta)},
                uncertainty={TERMS[i].name: float(np.sqrt(max(cov[j, j], 0.0))) for j, i in enumerate(kept)},
                meaning={TERMS[i].name: TERMS[i].meaning for i in kept},
                heldout_error=error,
                library_heldout_error=library_error,
            )
        start += effect.size
    raise ValueError(f"{result.name} holds no learned correction")
