"""The models `golfflight accuracy` compares, each flown through the same runtime call (`flight.integrator.simulate`,
NumPy physics, forward Euler at the card's step): a bundle's ONNX graph, or a closed-form coefficient model such as
Ferguson, McNally & McPhee 2022's quadratics in spin ratio.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from golfflight.flight.air import Air
from golfflight.flight.coefficients import FERGUSON_2022, QuadraticSpinRatio
from golfflight.flight.integrator import simulate
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import CoefficientModel, initial_state
from golfflight.flight.wind import CALM, Wind

STANDARD_DENSITY_KG_M3 = 1.225
"""ICAO standard air: the air a closed-form model is flown in (it has no Reynolds-number input)."""


class Flyer:
    """A coefficient model and the air and step it is flown at; `simulate` is the one flight-core call every model
    shares.

    `ground_height_m` lets a caller fly past the ground (a large negative height: the wind fit compares positions at
    fixed times, so no ball may stop early); `t_max_s` overrides the simulated time."""

    label = "model"

    def __init__(self, dt_s: float, t_sim_s: float, density_kg_m3: float) -> None:
        self.dt_s, self.t_sim_s, self._density = float(dt_s), float(t_sim_s), float(density_kg_m3)

    @property
    def density_kg_m3(self) -> float:
        """The air a shot without conditions is flown in."""
        return self._density

    def coefficients_in(self, air: Air | None) -> CoefficientModel:
        raise NotImplementedError

    def simulate(
        self,
        launch: dict[str, np.ndarray],
        air: Air | None = None,
        keep_states: bool = False,
        wind: Wind = CALM,
        t_max_s: float | None = None,
        ground_height_m: float = 0.0,
    ) -> Flight:
        """Fly launches (the canonical launch columns, arrays) in `air` (default: the flyer's own) and `wind`."""
        density = self.density_kg_m3 if air is None else air.density_kg_m3
        return simulate(
            initial_state(**launch),
            self.coefficients_in(air),
            density,
            wind=wind,
            dt=self.dt_s,
            t_max=self.t_sim_s if t_max_s is None else t_max_s,
            keep_states=keep_states,
            ground_height_m=ground_height_m,
        )


class ModelFlyer(Flyer):
    """A bundle flown with its ONNX coefficient graph at its card's step and simulated time, in the card's air by
    default (its density and, through the graph's Reynolds scale, its viscosity)."""

    def __init__(self, bundle: str | os.PathLike, label: str | None = None) -> None:
        self.bundle = Path(bundle)
        self.coefficients = OnnxCoefficients(bundle)
        self.card = self.coefficients.card
        physics = self.card.physics
        super().__init__(physics.dt_s, physics.t_sim_s, physics.air_density_kg_m3)
        self.label = label or f"`{self.bundle}`"

    def coefficients_in(self, air: Air | None) -> CoefficientModel:
        viscosity = self.card.physics.kinematic_viscosity_m2_s if air is None else air.kinematic_viscosity_m2_s
        return self.coefficients.in_air(viscosity)


class CoefficientFlyer(Flyer):
    """A closed-form coefficient model (C_L, C_D, C_M, C_Q of the spin ratio alone) flown like a bundle."""

    def __init__(self, model: CoefficientModel, label: str, dt_s: float = 0.1, t_sim_s: float = 10.0,
                 density_kg_m3: float = STANDARD_DENSITY_KG_M3) -> None:
        super().__init__(dt_s, t_sim_s, density_kg_m3)
        self.model, self.label = model, label

    def coefficients_in(self, air: Air | None) -> CoefficientModel:
        return self.model


def ferguson_flyer(dt_s: float = 0.1, t_sim_s: float = 10.0) -> CoefficientFlyer:
    """Ferguson, McNally & McPhee 2022's C_L and C_D (C_M = 0.011 S), calm, standard air, at the given Euler step
    (the comparison uses the bundle's, so the integrator is the same for every model)."""
    return CoefficientFlyer(QuadraticSpinRatio(FERGUSON_2022), "Ferguson 2022", dt_s, t_sim_s)
