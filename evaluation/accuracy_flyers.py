"""The models `golfflight accuracy` compares, each flown through the same runtime call (`flight.flyer.Flyer.flight`:
NumPy physics, forward Euler at the bundle card's step, for the engine's maximum flight time): a bundle's ONNX graph,
or a closed-form coefficient model such as Ferguson, McNally & McPhee 2022's quadratics in spin ratio.
"""

from __future__ import annotations

import os

import numpy as np
from golfflight.flight import flyer as core
from golfflight.flight.air import Air
from golfflight.flight.coefficients import FERGUSON_2022, QuadraticSpinRatio
from golfflight.flight.conditions import STANDARD, BatchAir
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import CoefficientModel, initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.flight.wind import CALM, Wind

STANDARD_DENSITY_KG_M3 = 1.225
"""ICAO standard air: the air a closed-form model is flown in (it has no Reynolds-number input)."""


class EvaluatedModel:
    """A labelled `flight.flyer.Flyer`: its model and the air, step and maximum time it is flown at; `simulate` is
    the one flight-core call every model shares.

    `ground_height_m` lets a caller fly past the ground (a large negative height: the wind fit compares positions at
    fixed times, so no ball may stop early); `t_max_s` overrides the simulated time."""

    def __init__(self, flyer: core.Flyer, label: str) -> None:
        self.flyer, self.label = flyer, label

    @property
    def dt_s(self) -> float:
        return self.flyer.dt_s

    @property
    def t_sim_s(self) -> float:
        """The longest flight simulated (a shot not down by then has NaN landing values)."""
        return self.flyer.max_flight_time_s

    @property
    def density_kg_m3(self) -> float:
        """The air a shot without conditions is flown in."""
        return self.flyer.density_kg_m3

    def coefficients_in(self, air: Air | None) -> CoefficientModel:
        """The model in `air` (None: the flyer's own)."""
        return self.flyer.in_air(None if air is None else air.kinematic_viscosity_m2_s)

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
        density, viscosity = (None, None) if air is None else (air.density_kg_m3, air.kinematic_viscosity_m2_s)
        return self.flyer.flight(FlightProblem(initial_state(**launch), BatchAir(density, viscosity, wind),
                                               ground_height_m, keep_states=keep_states, max_time_s=t_max_s))


class ModelFlyer(EvaluatedModel):
    """A bundle's Flyer (`flight.flyer.load_flyer`): its ONNX coefficient graph at its card's step for the engine's
    maximum flight time, in the card's air by default (its density and, through the graph's Reynolds scale, its
    viscosity)."""

    def __init__(self, bundle: str | os.PathLike | None, label: str | None = None) -> None:
        flyer = core.load_flyer(bundle)
        super().__init__(flyer, label or f"`{flyer.bundle_dir}`")
        self.bundle, self.coefficients, self.card = flyer.bundle_dir, flyer.model, flyer.card


class CoefficientFlyer(EvaluatedModel):
    """A closed-form coefficient model (C_L, C_D, C_M, C_Q of the spin ratio alone) flown like a bundle."""

    def __init__(self, model: CoefficientModel, label: str, dt_s: float = 0.1, t_sim_s: float = 10.0,
                 density_kg_m3: float = STANDARD_DENSITY_KG_M3) -> None:
        viscosity = STANDARD.air.kinematic_viscosity_m2_s  # unused: the model has no Reynolds-number input
        super().__init__(core.Flyer(core.FixedCoefficients(model), dt_s, t_sim_s, density_kg_m3, viscosity), label)
        self.model = model


def ferguson_flyer(dt_s: float = 0.1, t_sim_s: float = 10.0) -> CoefficientFlyer:
    """Ferguson, McNally & McPhee 2022's C_L and C_D (C_M = 0.011 S), calm, standard air, at the given Euler step
    (the comparison uses the bundle's, so the integrator is the same for every model)."""
    return CoefficientFlyer(QuadraticSpinRatio(FERGUSON_2022), "Ferguson 2022", dt_s, t_sim_s)
