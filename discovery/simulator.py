"""Fly recorded launches through the diagnosed model under modified conditions, many variants in one batch.

A `Setup` holds everything per shot (launch, air, uniform wind, landing ground, coefficient scales, correction
weights, a form's weights); `simulate_setup` flies it through the model's `flight.flyer.Flyer` (`Flyer.flight`, the one batch flight):
effect fits fly the same shots under several parameter sets stacked into one batch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields

import numpy as np
from golfflight.discovery.form_terms import formed_flyer
from golfflight.flight.conditions import BatchAir
from golfflight.flight.field import WeightedCorrection
from golfflight.flight.flyer import Flyer
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.flight.wind import Wind

CHUNK_SHOTS = 25_000
"""Batches larger than this are flown in chunks of it when no positions are kept: the flight of each shot is its own,
so the outcomes are the same, and the memory a batch needs stays bounded (a 100,000-shot diagnosis flies batches of
up to five times its shots at once)."""

Correction = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""Extra acceleration [N,3] from (air-relative velocity [N,3], spin [N,3], position [N,3], per-shot weights [N,K])."""


@dataclass
class Setup:
    """Everything one simulation of N shots uses: launches, air, wind, landing ground, coefficient scales."""

    launch: dict[str, np.ndarray]
    density_ratio: np.ndarray
    """True air density over the density the model assumes for the shot [N]."""
    density_kg_m3: np.ndarray
    """The density the model assumes for each shot (recorded conditions, else the model's reference air) [N]."""
    wind_xy_mps: np.ndarray
    """Uniform air velocity [N,2] (x right, y to the target)."""
    ground_height_m: np.ndarray
    """Height of the landing ground above the tee's ground [N]."""
    coefficient_scale: np.ndarray
    """Multipliers of C_L, C_D, C_M [N,3]."""
    correction_weights: np.ndarray | None = None
    """Weights [N,K] of an extra-acceleration term (see `discovery.correction`), None = no term."""
    kinematic_viscosity_m2_s: np.ndarray | None = None
    """The kinematic viscosity the model assumes for each shot [N] (recorded air, as the service computes it from
    the temperature and density), None = the model's nominal air."""
    viscosity_ratio: np.ndarray | None = None
    """True kinematic viscosity over the assumed one [N] (ones where not given): real thinner air has a
    proportionally larger one (the Reynolds number falls with the density), a density-only change leaves it."""
    form_weights: np.ndarray | None = None
    """Weights [N,K] of a form's coefficient multipliers (`discovery.form_terms`), None = the model's own form."""

    def __post_init__(self) -> None:
        if self.viscosity_ratio is None:
            self.viscosity_ratio = np.ones(len(self.density_ratio))

    def __len__(self) -> int:
        return len(self.density_ratio)

    def take(self, index: np.ndarray) -> Setup:
        values = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "launch":
                values[f.name] = {k: v[index] for k, v in value.items()}
            else:
                values[f.name] = None if value is None else value[index]
        return Setup(**values)

    def copy(self) -> Setup:
        return self.take(np.arange(len(self)))

    def viscosity(self, nominal_m2_s: float) -> np.ndarray:
        """The kinematic viscosity each shot flies in [N]: the assumed one (`nominal_m2_s` where none is set) times
        the effects' ratio."""
        assumed = self.kinematic_viscosity_m2_s if self.kinematic_viscosity_m2_s is not None else nominal_m2_s
        return assumed * self.viscosity_ratio


def concatenate(parts: list[Setup]) -> Setup:
    """Stack several condition sets of the same shots into one batch."""
    values = {}
    for f in fields(Setup):
        items = [getattr(p, f.name) for p in parts]
        if f.name == "launch":
            values[f.name] = {k: np.concatenate([i[k] for i in items]) for k in items[0]}
        else:
            values[f.name] = None if items[0] is None else np.concatenate(items)
    return Setup(**values)


@dataclass
class Outcomes:
    """Outcome of a batch: landing point (x, y), apex, flight time, landing angle; NaN where a ball did not land."""

    landing_xy: np.ndarray
    apex_m: np.ndarray
    flight_time_s: np.ndarray
    landing_angle_deg: np.ndarray
    positions: np.ndarray | None = None
    """[T, N, 3] positions at t = 0, dt, 2 dt, ... (NaN after landing), when asked for."""
    dt_s: float = 0.0

    def outcomes(self) -> np.ndarray:
        """[N, 5] in `discovery.recordings.OBSERVABLES` order."""
        return np.stack(
            [self.landing_xy[:, 1], self.landing_xy[:, 0], self.apex_m, self.flight_time_s, self.landing_angle_deg],
            axis=1,
        )


FLOWN_OUTCOMES = ("landing_xy", "apex_m", "flight_time_s", "landing_angle_deg")
"""The per-shot fields of an `Outcomes` batch, in order."""


def setup_flight(
    setup: Setup,
    flyer: Flyer,
    correction: Correction | None = None,
    keep_states: bool = False,
    air: Wind | None = None,
) -> Flight:
    """The Flyer's `Flight` of every shot of a setup down through its landing ground (`Flyer.flight`, the one batch
    flight): what `simulate_setup` summarises, and what `discovery.conceal` records when it hides effects in the
    diagnosed model's own flights. Each shot flies in its true air (assumed density and viscosity times the effects'
    ratios) with its coefficient scales and correction weights.

    `air` replaces the setup's uniform wind with air whose motion depends on the ball's height (an outside effect's,
    `discovery.outside.HeightGust`), so the gust acts through the model's own coefficients like any wind."""
    density = setup.density_kg_m3 * setup.density_ratio
    wind = air if air is not None else Wind.from_components(setup.wind_xy_mps[:, 0], setup.wind_xy_mps[:, 1])
    extra = None if correction is None else WeightedCorrection(correction, setup.correction_weights)
    if setup.form_weights is not None:
        flyer = formed_flyer(flyer, setup.form_weights)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        air_columns = BatchAir(density, setup.viscosity(flyer.kinematic_viscosity_m2_s), wind)
        return flyer.flight(FlightProblem(initial_state(**setup.launch), air_columns, setup.ground_height_m,
                                          setup.coefficient_scale, extra, keep_states))


def simulate_setup(
    setup: Setup, flyer: Flyer, correction: Correction | None = None, keep_positions: bool = False
) -> Outcomes:
    """Every shot's outcomes (`setup_flight`), down through its landing ground (or the Flyer's maximum time).

    A parameter set far outside reality may make a ball diverge; its outcome is then NaN (not landed), silently.
    """
    if not keep_positions and len(setup) > CHUNK_SHOTS:
        settings = (flyer, correction)
        chunks = [
            simulate_setup(setup.take(np.arange(start, min(start + CHUNK_SHOTS, len(setup)))), *settings)
            for start in range(0, len(setup), CHUNK_SHOTS)
        ]
        values = [np.concatenate([getattr(c, name) for c in chunks]) for name in FLOWN_OUTCOMES]
        return Outcomes(*values, dt_s=flyer.dt_s)
    flight = setup_flight(setup, flyer, correction, keep_positions)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        landing_angle = flight.landing_angle_deg
    landing_xy, apex, flight_time = flight.landing_position[:, :2].copy(), flight.apex_m, flight.flight_time_s
    apex[~flight.landed] = np.nan
    finite = np.isfinite(landing_xy).all(axis=1) & np.isfinite(landing_angle)
    for values in (landing_xy, apex, flight_time, landing_angle):
        values[~finite] = np.nan
    positions = _positions(flight) if keep_positions else None
    return Outcomes(landing_xy, apex, flight_time, landing_angle, positions, flyer.dt_s)


def _positions(flight: Flight) -> np.ndarray:
    """[T, N, 3] positions at every step, NaN after the step on which a ball came down through its ground."""
    positions = np.stack([state.position for state in flight.states])
    step = np.arange(len(positions))[:, None]
    positions[flight.landed[None, :] & (step > flight.last_step[None, :] + 1)] = np.nan
    return positions
