"""The form's terms: smooth multipliers of C_L, C_D and C_M as functions of the spin ratio and the Reynolds number,
applied inside a Flyer's coefficients (`formed_flyer`), so a learned form flies through any air, wind or launch.

    C_L' = C_L exp(sum_k a_k f_k),  C_D' = C_D exp(sum_k b_k f_k),  f = 1, s, s^2, r, s r, s^2 r, r^2, s r^2
    C_M' = C_M exp(c0 + c1 s + c2 r)
    each exponent held within LOG_MULTIPLIER_BOUND
    s = ln(S / 0.2), S = R |w| / |v| (spin ratio);  r = ln(Re / 1.5e5), Re = 2 R |v| / nu
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.flight.constants import BALL_RADIUS_M
from golfflight.flight.field import take
from golfflight.flight.flyer import Flyer
from golfflight.flight.physics import CoefficientModel, at_least_tiny, spin_ratio_of

SPIN_RATIO_REF = 0.2
"""The spin ratio at which the form's spin terms vanish (s = 0): between a driver's 0.08 and a wedge's 0.5."""
REYNOLDS_REF = 1.5e5
"""The Reynolds number at which its Reynolds terms vanish (r = 0): a ball at about 51 m/s in ICAO air."""
SPIN_RANGE = (-2.0, 2.0)
"""s is held at these ends (S from 0.027 to 1.5): beyond them the surface is flat rather than extrapolated."""
REYNOLDS_RANGE = (-1.5, 1.0)
"""r is held at these ends (Re from 33,000 to 410,000, about 11 to 140 m/s in ICAO air)."""
SPIN_RATIO_FLOOR = 1e-3
"""The spin ratio below which s is held (a ball with no spin has no spin-ratio dependence to read)."""
LOG_MULTIPLIER_BOUND = np.array([1.25, 1.25, 4.0])
"""The largest |ln multiplier| of C_L, C_D and C_M the form's terms add up to anywhere (x 3.5 and x 55): beyond two
flight models' difference, short of what a 0.25 s RK4 step cannot fly. Drag slows a 70 m/s drive in ICAO air at
C_D rho A v / m = 0.8 /s (lift turns it alike), spin decays at about 0.07 /s: at their bounds 2.8 and 3.7 /s, a step
takes 0.7 and 0.9 of them against RK4's stability limit of 2.8. At every corner of the bounds, conceal's bag flown at
0.25 s lands within 3 m of 0.05 s; with lift and drag held at 1.5, lift x 4.5 and drag x 0.22 looped a shot 130 m
off (tests/test_discovery_baseline.py). Unheld, 19 weights at their own bounds reach C_M x e^18 (a fitted form sat
at e^13 on a wedge and flew it to NaN)."""


@dataclass(frozen=True)
class FormTerm:
    """One term of the form: which coefficient it multiplies (0 = C_L, 1 = C_D, 2 = C_M) and its feature."""

    name: str
    column: int
    feature: str
    """One of SURFACE's features of s and r (the spin decay's: '1', 's', 'r')."""
    bound: float = 1.0
    """The largest |log-multiplier weight| allowed: the spin torque differs most between flight models."""


SURFACE = ("1", "s", "s^2", "r", "s r", "s^2 r", "r^2", "s r^2")
"""The features of the lift and drag multipliers: a smooth surface over the spin ratio and the Reynolds number (the
served networks read speed and spin rate, so their difference from another ball's physics is one)."""

TERMS: tuple[FormTerm, ...] = (
    *(FormTerm(f"lift x {f}", 0, f) for f in SURFACE),
    *(FormTerm(f"drag x {f}", 1, f) for f in SURFACE),
    FormTerm("spin decay", 2, "1", 4.0),
    FormTerm("spin decay x s", 2, "s", 4.0),
    FormTerm("spin decay x r", 2, "r", 4.0),
)
"""The form's log-multipliers, in parameter order."""


def log_multipliers(
    v_rel: np.ndarray, omega: np.ndarray, viscosity: np.ndarray | float, weights: np.ndarray
) -> np.ndarray:
    """ln of the multipliers of (C_L, C_D, C_M) [N,3] at air-relative velocity and spin [N,3] in air of kinematic
    viscosity `viscosity` (one or per ball), for weights [K] or [N,K] in TERMS order."""
    speed = at_least_tiny(np.linalg.norm(v_rel, axis=1))
    s = np.log(np.maximum(spin_ratio_of(speed, np.linalg.norm(omega, axis=1)), SPIN_RATIO_FLOOR) / SPIN_RATIO_REF)
    r = np.log(2.0 * BALL_RADIUS_M * speed / np.asarray(viscosity) / REYNOLDS_REF)
    s, r = np.clip(s, *SPIN_RANGE), np.clip(r, *REYNOLDS_RANGE)
    feature = {"1": np.ones_like(s), "s": s, "s^2": s**2, "r": r, "s r": s * r, "s^2 r": s**2 * r, "r^2": r**2,
               "s r^2": s * r**2}
    out = np.zeros((len(speed), 3))
    w = np.broadcast_to(weights, (len(speed), len(TERMS)))
    for k, term in enumerate(TERMS):
        out[:, term.column] += w[:, k] * feature[term.feature]
    return np.clip(out, -LOG_MULTIPLIER_BOUND, LOG_MULTIPLIER_BOUND)


@dataclass(frozen=True)
class FormedCoefficients:
    """A coefficient model read in air of kinematic viscosity `viscosity` with the form's multipliers applied."""

    base: CoefficientModel
    viscosity: np.ndarray | float
    weights: np.ndarray
    """[K] for every ball, or [N,K] one set per ball."""

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        out = self.base(v_rel, omega)
        out[:, :3] *= np.exp(log_multipliers(v_rel, omega, self.viscosity, self.weights))
        return out

    def take(self, index: np.ndarray) -> FormedCoefficients:
        weights = self.weights[index] if self.weights.ndim == 2 else self.weights
        return FormedCoefficients(take(self.base, index), take(self.viscosity, index), weights)


@dataclass(frozen=True)
class FormedModel:
    """A Flyer's model in air (`flight.flyer.ModelInAir`) with the form applied in any air: read at the Reynolds
    number that air gives, or, with `read_at`, at one kinematic viscosity whatever the air (the form along the
    speed: at the air it was learned in the two readings agree)."""

    base: object
    weights: np.ndarray
    read_at: float | None = None

    def in_air(self, kinematic_viscosity_m2_s: float | np.ndarray) -> CoefficientModel:
        reading = kinematic_viscosity_m2_s if self.read_at is None else self.read_at
        return FormedCoefficients(self.base.in_air(kinematic_viscosity_m2_s), reading, self.weights)


def formed_flyer(flyer: Flyer, weights: np.ndarray) -> Flyer:
    """The same Flyer (step, step rule, air, card) with the form's weights applied to its coefficients."""
    return flyer.replaced(model=FormedModel(flyer.model, np.asarray(weights, dtype=float)))


