"""The model being diagnosed: a coefficient model inside the equations of motion, its integrator and assumed air.

`from_bundle` is what users run, flown as the service flies it (a shipped ONNX bundle in the flight core, forward
Euler at the card's dt, the card's air; air `ratio` x denser also has 1/ratio the kinematic viscosity, for the
reference world's Reynolds numbers as for the bundle's input scale);
`reference` is the reference world itself (RK4 at 0.1 s, within 2 cm of its 0.01 s flights), a perfect model
of clean synthetic data that `golfflight prove` uses to measure the method apart from any model error.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from golfflight.discovery.recordings import OBSERVABLES
from golfflight.discovery.simulator import CoefficientsFor, Correction, Flown, Setup, fly_setup, simulate_setup
from golfflight.flight.air import Air
from golfflight.flight.limits import FLIGHT_TIME_S
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.flight.outcomes import Flight
from golfflight.flight.reference_aero import CALIBRATED, ReferenceAerodynamics, ReferenceParameters
from golfflight.flight.wind import Wind

DEFAULT_BUNDLE = Path(__file__).resolve().parents[1] / "models" / "default"
REFERENCE = "reference"
"""`--model reference` diagnoses against the reference world instead of a bundle."""

MIN_T_MAX_S = 15.0
"""Flights are integrated for at least this long, so a shot the effects lengthen still lands."""


@dataclass
class FlightModel:
    """A simulator of recorded launches: coefficients, integrator, assumed air and its own expected error."""

    name: str
    coefficients_for: CoefficientsFor
    density_kg_m3: float
    """Air density the model assumes when a shot has no recorded conditions."""
    dt_s: float
    method: Literal["euler", "rk4"]
    t_max_s: float
    model_error: dict[str, float] = field(default_factory=dict)
    """1-sigma error of the model itself per observable (from its validation); missing ones are estimated."""
    error_source: dict[str, str] = field(default_factory=dict)
    temperature_c: float = 15.0
    """Temperature of the assumed air (for the equivalent altitude of a density ratio)."""
    control: FlightModel | None = None
    """The physics the model was trained to imitate. When set, diagnose flies the recorded launches through it
    too and adds the difference to every prediction: the model's own known error on these launches is taken out
    before anything is fitted, so it is not mistaken for left-out physics."""

    def simulate(self, setup: Setup, correction: Correction | None = None, keep_positions: bool = False) -> Flown:
        """Fly a setup's shots through this model (`discovery.simulator.simulate_setup`)."""
        settings = (self.dt_s, self.t_max_s, self.method, correction, keep_positions)
        return simulate_setup(setup, self.coefficients_for, *settings)

    def fly(
        self, setup: Setup, correction: Correction | None = None, keep_states: bool = False, air: Wind | None = None
    ) -> Flight:
        """The flight core's own `Flight` of a setup through this model (`discovery.simulator.fly_setup`; `air`
        replaces the setup's uniform wind)."""
        settings = (self.dt_s, self.t_max_s, self.method, correction, keep_states, air)
        return fly_setup(setup, self.coefficients_for, *settings)


def from_bundle(directory: str | os.PathLike, control: bool = False) -> FlightModel:
    """The bundle as the service flies it, expecting its card's own error (`own_error`, measured where the truth is
    known), or, on a card without one, letting `discovery.noise` estimate it; never the card's validation error,
    which is mostly its data's noise and unrecorded weather. With `control`, its difference from the reference
    world on the recorded launches is added to every prediction instead: that diagnoses the reference world as
    seen through the bundle, not the model the service runs."""
    coefficients = OnnxCoefficients(directory)
    card = coefficients.card
    error: dict[str, float] = {}
    source: dict[str, str] = {}
    if card.own_error is not None:
        error = dict(card.own_error.sigma)
        source = {name: f"model card: own error against {card.own_error.measured_against}" for name in error}
    if control:
        error = {name: 0.0 for name in OBSERVABLES}
        source = {
            name: "taken out: the model's difference from the reference world on these launches" for name in error
        }
    physics = card.physics
    return FlightModel(
        f"bundle {Path(directory)} ({card.variant})",
        lambda ratio: coefficients.in_air(physics.kinematic_viscosity_m2_s / np.asarray(ratio, dtype=float)),
        physics.air_density_kg_m3,
        physics.dt_s,
        "euler",
        max(physics.t_sim_s, FLIGHT_TIME_S.high),  # the engine's limit: a shot not down by then fails there
        error,
        source,
        control=reference() if control else None,
    )


def reference(params: ReferenceParameters = CALIBRATED, air: Air | None = None) -> FlightModel:
    """The reference world as the model (RK4, dt 0.1 s): no model error, only measurement noise is expected."""
    air = air or Air.standard()
    viscosity = float(air.kinematic_viscosity_m2_s)
    zero = {name: 0.0 for name in OBSERVABLES}
    return FlightModel(
        "reference world (RK4, dt 0.1 s)",
        lambda ratio: ReferenceAerodynamics(params, viscosity / np.asarray(ratio, dtype=float)),
        float(air.density_kg_m3),
        0.1,
        "rk4",
        MIN_T_MAX_S,
        zero,
        {k: "the reference world is the model: no model error" for k in zero},
    )


def load_model(spec: str | os.PathLike | None, control: bool = False) -> FlightModel:
    """`reference`, a bundle directory, or None for the shipped default bundle (`control`: see `from_bundle`)."""
    if str(spec) == REFERENCE:
        return reference()
    return from_bundle(DEFAULT_BUNDLE if spec is None else spec, control)
