"""Closed-form coefficient models (NumPy): constants for tests and Ferguson et al. 2022's quadratics in spin ratio."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.flight.physics import spin_ratio

BASE_DYNAMIC_PRESSURE = 0.5
"""C_Q that makes q = C_Q rho |v|^2 the usual dynamic pressure 1/2 rho |v|^2."""


@dataclass(frozen=True)
class ConstantCoefficients:
    """The same C_L, C_D, C_M for every ball at every step (vacuum: all zero)."""

    c_lift: float = 0.0
    c_drag: float = 0.0
    c_moment: float = 0.0
    c_q: float = BASE_DYNAMIC_PRESSURE

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        row = np.array([self.c_lift, self.c_drag, self.c_moment, self.c_q])
        return np.broadcast_to(row, (v_rel.shape[0], 4)).copy()


FERGUSON_2022 = (0.0504, 1.2031, -1.1490, 0.1304, 0.9287, -0.8259, 0.011)
"""Ferguson, McNally & McPhee 2022: C_L = p0 + p1 S + p2 S^2, C_D = p3 + p4 S + p5 S^2; C_M = p6 S (Smits/Tavares)."""


@dataclass(frozen=True)
class QuadraticSpinRatio:
    """The Phys-Q family: C_L and C_D quadratic in the spin ratio S, C_M proportional to S; C_L kept >= 0."""

    params: tuple[float, ...] = FERGUSON_2022

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        p = self.params
        s = spin_ratio(v_rel, omega)
        c_lift = np.maximum(0.0, p[0] + p[1] * s + p[2] * s**2)
        c_drag = p[3] + p[4] * s + p[5] * s**2
        return np.stack([c_lift, c_drag, p[6] * s, np.full_like(s, BASE_DYNAMIC_PRESSURE)], -1)
