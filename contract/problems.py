"""Launch columns (an accuracy set's, a physics check's, a script's) as one `flight.problem.FlightProblem`: the one
translation from the canonical launch columns to what an engine flies."""

from __future__ import annotations

import numpy as np
from golfflight.flight.air import Air
from golfflight.flight.conditions import BatchAir
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.flight.wind import CALM, Wind


def launch_problem(
    launch: dict[str, np.ndarray],
    air: Air | None = None,
    wind: Wind = CALM,
    keep_states: bool = False,
    max_time_s: float | None = None,
    ground_height_m: float | np.ndarray = 0.0,
) -> FlightProblem:
    """Launches (the canonical launch columns, arrays) in `air` (None: the flyer's own) and `wind`, down to planes at
    `ground_height_m` (a large negative height flies past the ground: the wind fit compares positions at fixed
    times), for `max_time_s` (None: the flyer's maximum flight time), every state kept where asked."""
    columns = BatchAir(None, None, wind) if air is None else BatchAir(air.density_kg_m3, air.kinematic_viscosity_m2_s,
                                                                       wind)
    return FlightProblem(initial_state(**launch), columns, ground_height_m, keep_states=keep_states,
                         max_time_s=max_time_s)
