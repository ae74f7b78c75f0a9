"""The high-fidelity "reference world": the flight model synthetic sessions are generated from.

Its aerodynamics (`flight.reference_aero`) flown by the flight core with RK4 at 0.01 s, the air it is calibrated
in, and the reader of the PGA TOUR averages table, a held-out check (`shots.calibrate_reference` fits the free
parameters on recordings that may be trained on).
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.conditions import BatchAir
from golfflight.flight.constants import MPH_TO_MPS, YARD_M
from golfflight.flight.flyer import Flyer
from golfflight.flight.integrator import RUNGE_KUTTA_4
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import State
from golfflight.flight.problem import FlightProblem
from golfflight.flight.reference_aero import (
    CALIBRATED,
    REFERENCE_DT_S,
    REFERENCE_T_MAX_S,
    ReferenceAerodynamics,
    ReferenceParameters,
)
from golfflight.flight.wind import CALM, Wind
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import CSV_ENCODING
from pydantic import BaseModel, ConfigDict

CALIBRATION_AIR = Air.from_conditions(temperature_c=25.0, altitude_m=0.0, humidity_pct=50.0)
"""The air the unrecorded-air sources are calibrated and the tour-average table checked in: TrackMan's normalize
temperature (77 F), sea level, 50 % humidity."""

TOUR_AVERAGES_FILE = Path("reference") / "trackman_tour_averages_pga_2023.csv"
"""The PGA TOUR 2023 averages, relative to the shared data folder."""


def reference_flyer(params: ReferenceParameters = CALIBRATED, air: Air = CALIBRATION_AIR) -> Flyer:
    """The reference world as a Flyer: its aerodynamics flown by RK4 at REFERENCE_DT_S for up to REFERENCE_T_MAX_S,
    in `air` unless a flight is given its own."""
    viscosity = float(air.kinematic_viscosity_m2_s)
    return Flyer(
        ReferenceAerodynamics(params, viscosity),
        dt_s=REFERENCE_DT_S,
        max_flight_time_s=REFERENCE_T_MAX_S,
        density_kg_m3=float(air.density_kg_m3),
        kinematic_viscosity_m2_s=viscosity,
        rule=RUNGE_KUTTA_4,
    )


def fly_reference(
    state: State,
    air: Air,
    wind: Wind = CALM,
    ground_height_m: float | np.ndarray = 0.0,
    keep_states: bool = False,
    params: ReferenceParameters = CALIBRATED,
) -> Flight:
    """Fly a batch through the reference world (`reference_flyer`) in `air` (per shot or shared) until every ball
    has landed."""
    flyer = reference_flyer(params)
    air_columns = BatchAir(air.density_kg_m3, air.kinematic_viscosity_m2_s, wind)
    return flyer.flight(FlightProblem(state, air_columns, ground_height_m, keep_states=keep_states))


class ClubAverage(BaseModel):
    """One row of TrackMan's tour-averages table (its units: mph, degrees, rpm, yards)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    club: str
    club_speed_mph: float
    attack_angle_deg: float
    ball_speed_mph: float
    smash_factor: float
    launch_angle_deg: float
    spin_rpm: float
    max_height_yd: float
    land_angle_deg: float
    carry_yd: float

    @property
    def club_speed_mps(self) -> float:
        return self.club_speed_mph * MPH_TO_MPS

    @property
    def ball_speed_mps(self) -> float:
        return self.ball_speed_mph * MPH_TO_MPS

    @property
    def max_height_m(self) -> float:
        return self.max_height_yd * YARD_M

    @property
    def carry_m(self) -> float:
        return self.carry_yd * YARD_M


def default_tour_averages_path() -> Path:
    """The PGA 2023 table in the shared data folder (see `shots.paths.shared_data_dir`)."""
    return shared_data_dir() / TOUR_AVERAGES_FILE


def read_tour_averages(path: str | os.PathLike) -> list[ClubAverage]:
    """Read a TrackMan tour-averages CSV (one row per club) into validated rows, in file order."""
    path = Path(path)
    with path.open(newline="", encoding=CSV_ENCODING) as handle:
        rows = list(csv.DictReader(handle))
    if not rows:
        raise InputError(f"{path}: no rows")
    clubs = []
    for line, row in enumerate(rows, start=2):
        try:
            clubs.append(ClubAverage(**row))
        except ValueError as error:
            raise InputError(f"{path} line {line}: {error}") from None
    return clubs
