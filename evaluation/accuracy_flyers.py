"""The models `golfflight accuracy` compares, each a `flight.flyer.Flyer` with a label, flown by the same call
(`Flyer.flight` of `contract.problems.launch_problem`: NumPy physics, forward Euler at the bundle card's step, for the
engine's maximum flight time): a bundle's ONNX graph, or a closed-form coefficient model such as Ferguson, McNally &
McPhee 2022's quadratics in spin ratio.
"""

from __future__ import annotations

import os

from golfflight.flight import flyer as core
from golfflight.flight.coefficients import FERGUSON_2022, QuadraticSpinRatio
from golfflight.flight.conditions import STANDARD
from golfflight.flight.physics import CoefficientModel

STANDARD_DENSITY_KG_M3 = 1.225
"""ICAO standard air: the air a closed-form model is flown in (it has no Reynolds-number input)."""


def model_flyer(bundle: str | os.PathLike | None, label: str | None = None) -> core.Flyer:
    """A bundle's Flyer (`flight.flyer.load_flyer`: its ONNX coefficient graph at its card's step for the engine's
    maximum flight time, in the card's air by default), labelled `label` (default: its directory)."""
    flyer = core.load_flyer(bundle)
    if label is not None:
        flyer.label = label
    return flyer


def coefficient_flyer(model: CoefficientModel, label: str, dt_s: float = 0.1, t_sim_s: float = 10.0,
                      density_kg_m3: float = STANDARD_DENSITY_KG_M3) -> core.Flyer:
    """A closed-form coefficient model (C_L, C_D, C_M, C_Q of the spin ratio alone) flown like a bundle."""
    viscosity = STANDARD.air.kinematic_viscosity_m2_s  # unused: the model has no Reynolds-number input
    return core.Flyer(core.FixedCoefficients(model), dt_s, t_sim_s, density_kg_m3, viscosity, label=label)


def ferguson_flyer(dt_s: float = 0.1, t_sim_s: float = 10.0) -> core.Flyer:
    """Ferguson, McNally & McPhee 2022's C_L and C_D (C_M = 0.011 S), calm, standard air, at the given Euler step
    (the comparison uses the bundle's, so the integrator is the same for every model)."""
    return coefficient_flyer(QuadraticSpinRatio(FERGUSON_2022), "Ferguson 2022", dt_s, t_sim_s)


def is_bundle(flyer: core.Flyer) -> bool:
    """Whether a Flyer flies a bundle (it has a card) rather than a closed-form model."""
    return flyer.card is not None
