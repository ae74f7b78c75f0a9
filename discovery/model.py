"""The model being diagnosed: a `flight.flyer.Flyer` (coefficients, step rule, step, maximum flight time, assumed air)
with its own expected error.

`from_bundle` is what users run, flown as the service flies it (the bundle's Flyer from `flight.flyer.load_flyer`:
forward Euler at the card's dt for the engine's maximum flight time, the card's air, or each shot's recorded air with
the kinematic viscosity the service gives it; the coefficients are read at every shot's own Reynolds numbers,
`Setup.viscosity`);
`reference` is the reference world itself (RK4 at 0.1 s, within 2 cm of its 0.01 s flights), a perfect model
of clean synthetic data that `golfflight prove` uses to measure the method apart from any model error.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from golfflight.discovery.choices import REFERENCE
from golfflight.discovery.discrepancy import Discrepancy
from golfflight.discovery.recordings import OBSERVABLES
from golfflight.discovery.simulator import Correction, Outcomes, Setup, simulate_setup
from golfflight.flight.air import Air
from golfflight.flight.flyer import Flyer, load_flyer
from golfflight.flight.integrator import RUNGE_KUTTA_4
from golfflight.flight.reference_aero import CALIBRATED, ReferenceAerodynamics, ReferenceParameters

MIN_T_MAX_S = 15.0
"""Flights are integrated for at least this long, so a shot the effects lengthen still lands."""


@dataclass
class FlightModel:
    """A simulator of recorded launches: a Flyer (coefficients, integrator, assumed air) and its own expected
    error."""

    name: str
    flyer: Flyer
    model_error: dict[str, float] = field(default_factory=dict)
    """1-sigma error of the model itself per observable (from its validation); missing ones are estimated."""
    error_source: dict[str, str] = field(default_factory=dict)
    temperature_c: float = 15.0
    """Temperature of the assumed air (for the equivalent altitude of a density ratio)."""
    control: FlightModel | None = None
    """The physics the model was trained to imitate. When set, diagnose flies the recorded launches through it
    too and adds the difference to every prediction: the model's own known error on these launches is taken out
    before anything is fitted, so it is not mistaken for left-out physics."""
    discrepancy: Discrepancy | None = None
    """What a baseline session taught beyond the form held in `flyer` (`discovery.form`): its mean at the launches
    flown is added to every prediction (`simulate`) and its SD to every shot's expected error."""

    def simulate(self, setup: Setup, correction: Correction | None = None, keep_positions: bool = False) -> Outcomes:
        """A setup's outcomes through this model (`discovery.simulator.simulate_setup`), with the discrepancy's mean at
        the launches flown where a baseline taught one."""
        flown = simulate_setup(setup, self.flyer, correction, keep_positions)
        return flown if self.discrepancy is None else self.discrepancy.shifted(flown, setup.launch)


def from_bundle(directory: str | os.PathLike | None = None, control: bool = False) -> FlightModel:
    """The bundle (None: the served default) as the service flies it, expecting its card's own error (`own_error`,
    measured where the truth is known), or, on a card without one, letting `discovery.noise` estimate it; never the
    card's validation error, which is mostly its data's noise and unrecorded weather. With `control`, its difference
    from the reference world on the recorded launches is added to every prediction instead: that diagnoses the
    reference world as seen through the bundle, not the model the service runs."""
    flyer = load_flyer(directory)
    card = flyer.card
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
    return FlightModel(
        f"bundle {flyer.bundle_dir} ({card.variant})",
        flyer,
        error,
        source,
        control=reference() if control else None,
    )


def reference(params: ReferenceParameters = CALIBRATED, air: Air | None = None) -> FlightModel:
    """The reference world as the model (RK4, dt 0.1 s): no model error, only measurement noise is expected."""
    air = air or Air.standard()
    viscosity = float(air.kinematic_viscosity_m2_s)
    flyer = Flyer(
        ReferenceAerodynamics(params, viscosity),
        dt_s=0.1,
        max_flight_time_s=MIN_T_MAX_S,
        density_kg_m3=float(air.density_kg_m3),
        kinematic_viscosity_m2_s=viscosity,
        rule=RUNGE_KUTTA_4,
    )
    zero = {name: 0.0 for name in OBSERVABLES}
    return FlightModel(
        "reference world (RK4, dt 0.1 s)",
        flyer,
        zero,
        {k: "the reference world is the model: no model error" for k in zero},
    )


def load_model(spec: str | os.PathLike | None, control: bool = False) -> FlightModel:
    """`reference`, a bundle directory, or None for the served default bundle (`control`: see `from_bundle`)."""
    if str(spec) == REFERENCE:
        return reference()
    return from_bundle(spec, control)
