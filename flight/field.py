"""Vector fields: the right-hand side d/dt (position, velocity, spin) the integrator steps, bound to a batch.

A field knows its balls' per-ball values (density, wind, coefficient scales, correction weights), so `take(index)`
gives the field of some of them: the integrator drops balls from the batch as they land.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from golfflight.flight import xp
from golfflight.flight.physics import CoefficientModel, ExtraAcceleration, State, derivatives
from golfflight.flight.wind import CALM, Wind


class VectorField(Protocol):
    """d/dt of a batch's state, and the same field for some of its balls."""

    def __call__(self, state: State) -> State: ...

    def take(self, index: np.ndarray) -> VectorField: ...


def take(part: Any, index: np.ndarray) -> Any:
    """Some balls' share of a per-ball value: an array's rows, a model's own `take`; a scalar, or a model without
    per-ball values, is everyone's."""
    if xp.is_number(part) or xp.is_array(part):
        return xp.rows(part, index)
    return part.take(index) if hasattr(part, "take") else part


@dataclass(frozen=True)
class BallInAir:
    """The equations of motion in the air (`flight.physics.derivatives`): coefficients, air density and wind, per
    ball or shared, and an optional extra acceleration."""

    coefficients: CoefficientModel
    density: np.ndarray | float
    wind: Wind = CALM
    extra: ExtraAcceleration | None = None

    def __call__(self, state: State) -> State:
        return derivatives(state, self.coefficients, self.density, self.wind, self.extra)

    def take(self, index: np.ndarray) -> BallInAir:
        return BallInAir(*(take(part, index) for part in (self.coefficients, self.density, self.wind, self.extra)))


@dataclass(frozen=True)
class ScaledCoefficients:
    """A coefficient model with C_L, C_D, C_M multiplied per ball (scale [N,3]): discovery's coefficient effects."""

    base: CoefficientModel
    scale: np.ndarray

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        out = self.base(v_rel, omega)
        out[:, :3] *= self.scale
        return out

    def take(self, index: np.ndarray) -> ScaledCoefficients:
        return ScaledCoefficients(take(self.base, index), self.scale[index])


@dataclass(frozen=True)
class WeightedCorrection:
    """An extra acceleration term(v_rel, omega, position, weights) [N,3] with per-ball weights [N,K]: discovery's
    learned correction, corrected flights being the equations plus this term."""

    term: Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    weights: np.ndarray

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray, position: np.ndarray) -> np.ndarray:
        return self.term(v_rel, omega, position, self.weights)

    def take(self, index: np.ndarray) -> WeightedCorrection:
        return WeightedCorrection(self.term, self.weights[index])
