"""The high-fidelity "reference world": the flight model synthetic sessions are generated from.

Lift and drag depend on the spin ratio S = R|w|/|v| AND the Reynolds number Re = |v| d / nu, with the
golf ball's drag crisis and low-Re lift collapse (NOTES.md section 2); spin decays through a moment
coefficient fitted to TrackMan's measured Pro V1x spin losses. The equations and their sources are in
docs/reference_world.md; `shots.calibrate_reference` fits the free parameters.
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict

from service.air import Air
from service.constants import BALL_RADIUS_M, MPH_TO_MPS, YARD_M
from service.flight import Flight, simulate
from service.physics import State
from service.wind import CALM, Wind
from shots.paths import shared_data_dir

BALL_DIAMETER_M = 2.0 * BALL_RADIUS_M

SUBCRITICAL_DRAG = 0.5
"""C_D below the drag crisis (Lyu et al. 2018: about 0.5 at Re = 5e4)."""

CRISIS_WIDTH_RE = 7.0e3
"""Width of the logistic drag crisis: 96 % subcritical at Re_c - 2.2e4, 2 % at Re_c + 2.7e4 (Lyu 2018's 5e4 -> 1e5)."""

DRAG_SPIN_SATURATION = 0.3
"""Spin-ratio scale of C_D's saturating rise; with it the tanh matches Ferguson 2022's quadratic for S <= 0.56."""

POSTCRITICAL_DRAG_RISE = 0.06
"""Amplitude of the slow supercritical rise of C_D with Re (Smits & Smith 1994's 0.06 sin term)."""

POSTCRITICAL_CENTRE_RE = 1.5e5
POSTCRITICAL_WIDTH_RE = 1.0e5

SPIN_DECAY_REFERENCE_RE = 1.0e5
"""Re at which C_M = k S^p exactly (the Reynolds factor is (Re / 1e5)^-n)."""

MAX_SPIN_RATIO = 10.0
"""Caps S for a ball almost at rest in the air (a tailwind as fast as the ball): keeps C_M finite."""

MIN_SPIN_RATIO = 1.0e-12
"""Floors S inside C_M's logarithm: a ball without spin gets a negligible C_M instead of log(0)."""

MIN_REYNOLDS = 1.0e3
"""Floors Re (|v_rel| < 0.4 m/s) so (Re / 1e5)^-n stays finite."""

REFERENCE_DT_S = 0.01
"""RK4 step: landings within 1.1 cm (p99 6 mm) of a dt/4 run over the whole launch range (docs/reference_world.md)."""

REFERENCE_T_MAX_S = 20.0
"""Longest flight simulated (the canonical records' flight-time limit); a batch stops once every ball has landed."""

CALIBRATION_AIR = Air.from_conditions(temperature_c=25.0, altitude_m=0.0, humidity_pct=50.0)
"""The air the tour-average table is fitted in: TrackMan's normalize temperature (77 F), sea level, 50 % humidity."""

TOUR_AVERAGES_FILE = Path("reference") / "trackman_tour_averages_pga_2023.csv"
"""The PGA TOUR 2023 averages, relative to the shared data folder."""


@dataclass(frozen=True)
class ReferenceParameters:
    """Free parameters of the reference aerodynamics, plus three effect knobs (1.0 = the calibrated world)."""

    drag_base: float
    """Supercritical C_D of a ball without spin."""
    drag_spin_span: float
    """How much C_D rises with spin ratio before it saturates."""
    lift_max: float
    """C_L approached at high spin ratio (supercritical)."""
    lift_half_spin_ratio: float
    """Spin ratio at which C_L reaches half of lift_max."""
    critical_reynolds: float
    """Centre of the drag crisis and of the lift collapse."""
    lift_spin_protection: float
    """Spin-ratio scale over which spin keeps the Magnus lift alive below the critical Re."""
    spin_decay_coefficient: float
    """k in C_M = k S^p (Re / 1e5)^-n."""
    spin_decay_spin_exponent: float
    """p in C_M = k S^p (Re / 1e5)^-n."""
    spin_decay_reynolds_exponent: float
    """n in C_M = k S^p (Re / 1e5)^-n."""
    drag_scale: float = 1.0
    """Effect knob: multiplies C_D."""
    lift_scale: float = 1.0
    """Effect knob: multiplies C_L."""
    spin_decay_scale: float = 1.0
    """Effect knob: multiplies C_M."""


FREE_PARAMETERS: tuple[str, ...] = (
    "drag_base",
    "drag_spin_span",
    "lift_max",
    "lift_half_spin_ratio",
    "critical_reynolds",
    "lift_spin_protection",
    "spin_decay_coefficient",
    "spin_decay_spin_exponent",
    "spin_decay_reynolds_exponent",
)
"""The fields `shots.calibrate_reference.fit_reference` adjusts (the knobs stay at 1.0)."""

# Obtained with `golfflight calibrate-reference --fit` (PGA 2023 table at CALIBRATION_AIR + TrackMan spin decay).
CALIBRATED = ReferenceParameters(
    drag_base=0.16795,
    drag_spin_span=0.17726,
    lift_max=0.47209,
    lift_half_spin_ratio=0.1779,
    critical_reynolds=73295.0,
    lift_spin_protection=0.85043,
    spin_decay_coefficient=0.011489,
    spin_decay_spin_exponent=1.1733,
    spin_decay_reynolds_exponent=0.49846,
)


def subcritical_fraction(reynolds: np.ndarray, critical_reynolds: float) -> np.ndarray:
    """Smooth 1 -> 0 switch across the drag crisis: how far the boundary layer is still laminar."""
    return 0.5 * (1.0 - np.tanh((reynolds - critical_reynolds) / (2.0 * CRISIS_WIDTH_RE)))


class ReferenceAerodynamics:
    """Coefficient model (v_rel, omega) -> [N,4] = C_L, C_D, C_M, C_Q of the reference world.

    `kinematic_viscosity` (m^2/s) is a scalar or one value per shot of the batch, as in `Air`.
    """

    def __init__(self, params: ReferenceParameters, kinematic_viscosity: float | np.ndarray) -> None:
        self.params = params
        self.reynolds_per_speed = BALL_DIAMETER_M / np.asarray(kinematic_viscosity, dtype=float)

    def coefficients(self, spin_ratio: np.ndarray, reynolds: np.ndarray) -> np.ndarray:
        """C_L, C_D, C_M, C_Q [N,4] as functions of spin ratio and Reynolds number [N]."""
        p = self.params
        s = np.minimum(spin_ratio, MAX_SPIN_RATIO)
        re = np.maximum(reynolds, MIN_REYNOLDS)
        laminar = subcritical_fraction(re, p.critical_reynolds)
        drag_super = (
            p.drag_base
            + p.drag_spin_span * np.tanh(s * (1.0 / DRAG_SPIN_SATURATION))
            + POSTCRITICAL_DRAG_RISE * np.tanh((re - POSTCRITICAL_CENTRE_RE) * (1.0 / POSTCRITICAL_WIDTH_RE))
        )
        out = np.empty(s.shape + (4,))
        out[:, 0] = (p.lift_scale * p.lift_max) * s / (s + p.lift_half_spin_ratio) * (
            1.0 - laminar * np.exp(s * (-1.0 / p.lift_spin_protection))
        )
        out[:, 1] = p.drag_scale * (drag_super + laminar * (SUBCRITICAL_DRAG - drag_super))
        log_moment = p.spin_decay_spin_exponent * np.log(np.maximum(s, MIN_SPIN_RATIO))
        log_moment -= p.spin_decay_reynolds_exponent * (np.log(re) - np.log(SPIN_DECAY_REFERENCE_RE))
        out[:, 2] = (p.spin_decay_scale * p.spin_decay_coefficient) * np.exp(log_moment)
        out[:, 3] = 0.5
        return out

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        speed = np.sqrt(v_rel[:, 0] * v_rel[:, 0] + v_rel[:, 1] * v_rel[:, 1] + v_rel[:, 2] * v_rel[:, 2])
        spin = np.sqrt(omega[:, 0] * omega[:, 0] + omega[:, 1] * omega[:, 1] + omega[:, 2] * omega[:, 2])
        spin_ratio = BALL_RADIUS_M * spin / np.maximum(speed, 1e-9)
        return self.coefficients(spin_ratio, speed * self.reynolds_per_speed)


def fly_reference(
    state: State,
    air: Air,
    wind: Wind = CALM,
    ground_height_m: float | np.ndarray = 0.0,
    keep_states: bool = False,
    params: ReferenceParameters = CALIBRATED,
) -> Flight:
    """Fly a batch through the reference world (RK4 at REFERENCE_DT_S) until every ball has landed."""
    model = ReferenceAerodynamics(params, air.kinematic_viscosity_m2_s)
    return simulate(
        state,
        model,
        air.density_kg_m3,
        wind,
        dt=REFERENCE_DT_S,
        t_max=REFERENCE_T_MAX_S,
        method="rk4",
        ground_height_m=ground_height_m,
        keep_states=keep_states,
    )


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
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    if not rows:
        raise ValueError(f"{path}: no rows")
    clubs = []
    for line, row in enumerate(rows, start=2):
        try:
            clubs.append(ClubAverage(**row))
        except ValueError as error:
            raise ValueError(f"{path} line {line}: {error}") from None
    return clubs
