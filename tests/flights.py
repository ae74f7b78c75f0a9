"""Tests' shorthand for a batch flight of a closed-form coefficient model: the flight core's `Flyer.flight` (the one
batch flight) with a fixed model at a given step, time, step rule and density."""

from __future__ import annotations

import numpy as np
from golfflight.flight.air import Air
from golfflight.flight.conditions import BatchAir
from golfflight.flight.flyer import FixedCoefficients, Flyer
from golfflight.flight.integrator import STEP_RULES, Method
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import CoefficientModel, State
from golfflight.flight.problem import FlightProblem
from golfflight.flight.wind import CALM, Wind

STANDARD = Air.standard()


def simulate(
    state: State,
    coefficient_model: CoefficientModel,
    density: np.ndarray | float,
    wind: Wind = CALM,
    dt: float = 0.1,
    t_max: float = 10.0,
    method: Method = "euler",
    ground_height_m: np.ndarray | float = 0.0,
    keep_states: bool = False,
) -> Flight:
    """Fly a batch in `density` and `wind` down to its ground planes, for t_max at most."""
    flyer = Flyer(FixedCoefficients(coefficient_model), dt, t_max, STANDARD.density_kg_m3,
                  STANDARD.kinematic_viscosity_m2_s, STEP_RULES[method])
    return flyer.flight(FlightProblem(state, BatchAir(density, None, wind), ground_height_m, keep_states=keep_states))
