"""The reference world's aerodynamics: lift, drag and spin decay from the literature (docs/reference_world.md).

Lift and drag depend on the spin ratio S = R|w|/|v| AND the Reynolds number Re = |v| d / nu, with the golf ball's
drag crisis and low-Re lift collapse; spin decays through a moment coefficient fitted to TrackMan's measured Pro V1x
spin losses. The equations and their sources are in docs/reference_world.md; `shots.calibrate_reference` fits the
free parameters, `shots.reference_world` flies it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
from golfflight.flight import xp
from golfflight.flight.constants import BALL_RADIUS_M
from golfflight.flight.ground.vectors import norm
from golfflight.flight.physics import spin_ratio_of

BALL_DIAMETER_M = 2.0 * BALL_RADIUS_M

SUBCRITICAL_DRAG = 0.5
"""C_D below the drag crisis (Lyu et al. 2018: about 0.5 at Re = 5e4)."""

CRISIS_WIDTH_RE = 7.0e3
"""Width of the logistic drag crisis: 96 % subcritical at Re_c - 2.2e4, 2 % at Re_c + 2.7e4 (Lyu 2018's 5e4 -> 1e5)."""

DRAG_SPIN_SATURATION = 0.3
"""Spin-ratio scale of C_D's saturating rise; with it the tanh matches Ferguson 2022's quadratic for S <= 0.56."""

POSTCRITICAL_DRAG_RISE = 0.06
"""Amplitude of the slow supercritical rise of C_D with Re (Smits & Smith 1994's 0.06 sin term)."""

POSTCRITICAL_CENTRE_RE = 1.5e5
POSTCRITICAL_WIDTH_RE = 1.0e5

SPIN_DECAY_REFERENCE_RE = 1.0e5
"""Re at which C_M = k S^p exactly (the Reynolds factor is (Re / 1e5)^-n)."""

MAX_SPIN_RATIO = 10.0
"""Caps S for a ball almost at rest in the air (a tailwind as fast as the ball): keeps C_M finite."""

MIN_SPIN_RATIO = 1.0e-12
"""Floors S inside C_M's logarithm: a ball without spin gets a negligible C_M instead of log(0)."""

MIN_REYNOLDS = 1.0e3
"""Floors Re (|v_rel| < 0.4 m/s) so (Re / 1e5)^-n stays finite."""

REFERENCE_DT_S = 0.01
"""RK4 step: landings within 1.1 cm (p99 6 mm) of a dt/4 run over the whole launch range (docs/reference_world.md)."""

REFERENCE_T_MAX_S = 20.0
"""Longest flight simulated (the canonical records' flight-time limit); a batch stops once every ball has landed."""

@dataclass(frozen=True)
class ReferenceParameters:
    """Free parameters of the reference aerodynamics, plus three effect knobs (1.0 = the calibrated world)."""

    drag_base: float
    """Supercritical C_D of a ball without spin."""
    drag_spin_span: float
    """How much C_D rises with spin ratio before it saturates."""
    lift_max: float
    """C_L approached at high spin ratio (supercritical)."""
    lift_half_spin_ratio: float
    """Spin ratio at which C_L reaches half of lift_max."""
    critical_reynolds: float
    """Centre of the drag crisis and of the lift collapse."""
    lift_spin_protection: float
    """Spin-ratio scale over which spin keeps the Magnus lift alive below the critical Re."""
    spin_decay_coefficient: float
    """k in C_M = k S^p (Re / 1e5)^-n."""
    spin_decay_spin_exponent: float
    """p in C_M = k S^p (Re / 1e5)^-n."""
    spin_decay_reynolds_exponent: float
    """n in C_M = k S^p (Re / 1e5)^-n."""
    drag_scale: float = 1.0
    """Effect knob: multiplies C_D."""
    lift_scale: float = 1.0
    """Effect knob: multiplies C_L."""
    spin_decay_scale: float = 1.0
    """Effect knob: multiplies C_M."""


FREE_PARAMETERS: tuple[str, ...] = (
    "drag_base",
    "drag_spin_span",
    "lift_max",
    "lift_half_spin_ratio",
    "critical_reynolds",
    "lift_spin_protection",
    "spin_decay_coefficient",
    "spin_decay_spin_exponent",
    "spin_decay_reynolds_exponent",
)
"""The fields `shots.calibrate_reference.fit_reference` adjusts (the knobs stay at 1.0)."""

# Obtained with `golfflight calibrate-reference --fit`: the training split of the measured real sources (TrackMan
# outdoor Premium drivers, the 2022 Sentry, THE PLAYERS 2020) and TrackMan's normalized 7-iron set, by ball-speed band,
# plus TrackMan's spin decay. The held-out PGA 2023 averages are a check only (docs/reference_world.md).
CALIBRATED = ReferenceParameters(
    drag_base=0.16041,
    drag_spin_span=0.17797,
    lift_max=0.45471,
    lift_half_spin_ratio=0.17146,
    critical_reynolds=74809.0,
    lift_spin_protection=0.82059,
    spin_decay_coefficient=0.011512,
    spin_decay_spin_exponent=1.1771,
    spin_decay_reynolds_exponent=0.48727,
)


def subcritical_fraction(reynolds: np.ndarray, critical_reynolds: float) -> np.ndarray:
    """Smooth 1 -> 0 switch across the drag crisis: how far the boundary layer is still laminar."""
    return 0.5 * (1.0 - np.tanh((reynolds - critical_reynolds) / (2.0 * CRISIS_WIDTH_RE)))


class ReferenceAerodynamics:
    """Coefficient model (v_rel, omega) -> [N,4] = C_L, C_D, C_M, C_Q of the reference world.

    `kinematic_viscosity` (m^2/s) is a scalar or one value per shot of the batch, as in `Air`.
    """

    def __init__(self, params: ReferenceParameters, kinematic_viscosity: float | np.ndarray) -> None:
        self.params = params
        self.reynolds_per_speed = BALL_DIAMETER_M / np.asarray(kinematic_viscosity, dtype=float)

    def in_air(self, kinematic_viscosity: float | np.ndarray) -> ReferenceAerodynamics:
        """The reference world's aerodynamics in air of this kinematic viscosity (its Reynolds numbers)."""
        return ReferenceAerodynamics(self.params, kinematic_viscosity)

    def coefficients(self, spin_ratio: np.ndarray, reynolds: np.ndarray) -> np.ndarray:
        """C_L, C_D, C_M, C_Q [N,4] as functions of spin ratio and Reynolds number [N]."""
        p = self.params
        s = np.minimum(spin_ratio, MAX_SPIN_RATIO)
        re = np.maximum(reynolds, MIN_REYNOLDS)
        laminar = subcritical_fraction(re, p.critical_reynolds)
        drag_super = (
            p.drag_base
            + p.drag_spin_span * np.tanh(s * (1.0 / DRAG_SPIN_SATURATION))
            + POSTCRITICAL_DRAG_RISE * np.tanh((re - POSTCRITICAL_CENTRE_RE) * (1.0 / POSTCRITICAL_WIDTH_RE))
        )
        out = np.empty(s.shape + (4,))
        out[:, 0] = (p.lift_scale * p.lift_max) * s / (s + p.lift_half_spin_ratio) * (
            1.0 - laminar * np.exp(s * (-1.0 / p.lift_spin_protection))
        )
        out[:, 1] = p.drag_scale * (drag_super + laminar * (SUBCRITICAL_DRAG - drag_super))
        log_moment = p.spin_decay_spin_exponent * np.log(np.maximum(s, MIN_SPIN_RATIO))
        log_moment -= p.spin_decay_reynolds_exponent * (np.log(re) - np.log(SPIN_DECAY_REFERENCE_RE))
        out[:, 2] = (p.spin_decay_scale * p.spin_decay_coefficient) * np.exp(log_moment)
        out[:, 3] = 0.5
        return out

    def take(self, index: np.ndarray) -> ReferenceAerodynamics:
        """The same model for some of the balls (their own air)."""
        if self.reynolds_per_speed.ndim == 0:
            return self
        other = copy.copy(self)
        other.reynolds_per_speed = self.reynolds_per_speed[index]
        return other

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        speed = norm(xp.columns(v_rel))
        return self.coefficients(spin_ratio_of(speed, norm(xp.columns(omega))), speed * self.reynolds_per_speed)
