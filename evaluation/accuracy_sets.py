"""The real sets `golfflight accuracy` flies, read by path from the shared data folder (never copied), and the
errors of a flight against each: the held-out sets (`shots.heldout`: TrackMan drivers from line
2943, rounds 3-4 of the TOUR Championship 2020), the PGA 2023 averages table (a training set of the real-data model,
fitted per club) and the Sentry 2022 trajectories (a training set too, kept for its full-path errors).
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.constants import FOOT_M, YARD_M
from golfflight.flight.flyer import Flyer
from golfflight.flight.outcomes import Flight
from golfflight.shots.clubs import straight_launches
from golfflight.shots.heldout import HELD_OUT, held_out_rounds, shot_round
from golfflight.shots.pbp import load_pbp
from golfflight.shots.records import ShotSet
from golfflight.shots.reference_world import ClubAverage
from golfflight.shots.synth import MIN_APEX_M
from golfflight.shots.trackman import load_trackman, read_table

TRACKMAN_HELD_OUT, TOUR_CHAMPIONSHIP_HELD_OUT = HELD_OUT
DRIVER_FILE = TRACKMAN_HELD_OUT.path
TOUR_CHAMPIONSHIP_PBP = TOUR_CHAMPIONSHIP_HELD_OUT.path
TOURCAST_TRAJECTORIES = Path("real/pga_tourcast_trackman/shot_trajectory/shot_trajectory_2021_016_656.csv")
TOURCAST_PBP = Path("real/pga_tourcast_trackman/pbp/pbp_2021_016_656.csv")
SONY_TRAJECTORIES = Path("real/pga_tourcast_trackman/shot_trajectory/shot_trajectory_2021_006_006.csv")
PREMIUM = "Premium"
"""The ball type of the TrackMan target row (TrackMan's own name for tour-type balls)."""

PGA_TARGETS = (2.0, 1.5, 1.5)
"""Mean absolute error the default model must reach on the PGA table (a training fit): carry (yd), max height (yd),
land angle (deg)."""
TRACKMAN_TARGETS = {"landing": 6.0, "apex": 1.2}
"""The issue's targets on the held-out TrackMan Premium drivers: landing error and max height MAE (yd)."""
TOUR_CHAMPIONSHIP_TARGET_FT = 5.5
"""The issue's target on rounds 3-4 of the TOUR Championship 2020: apex MAE (ft), and below Ferguson 2022's on the
same shots."""
HOLE = re.compile(r"-H(?P<hole>\d+)-P")
"""The hole of a tour shot id (`shots.tourcast.shot_id`)."""
TEE_GROUPS = {"par3": (3,), "par4_5": (4, 5)}
"""Tee shots grouped by the par of their hole: irons and hybrids on the par 3s, mostly drivers on the others."""


@dataclass
class ClubComparison:
    """Model and TrackMan carry (yd), max height (yd) and land angle (deg) per club [n, 3]."""

    clubs: list[ClubAverage]
    model: np.ndarray
    density_kg_m3: float

    @property
    def targets(self) -> np.ndarray:
        return np.array([[c.carry_yd, c.max_height_yd, c.land_angle_deg] for c in self.clubs])

    @property
    def mean_absolute_error(self) -> np.ndarray:
        return np.mean(np.abs(self.model - self.targets), axis=0)

    @property
    def bias(self) -> np.ndarray:
        return np.mean(self.model - self.targets, axis=0)


def compare_clubs(flyer: Flyer, clubs: Sequence[ClubAverage], air: Air | None = None) -> ClubComparison:
    """Fly each club's average launch (launch direction and spin axis 0) and compare with TrackMan's averages."""
    launch = straight_launches(clubs)
    density = flyer.density_kg_m3 if air is None else float(air.density_kg_m3)
    flight = flyer.flight(launch_problem(launch, air))
    model = np.stack([flight.carry_m / YARD_M, flight.apex_m / YARD_M, flight.landing_angle_deg], axis=1)
    return ClubComparison(list(clubs), model, density)


OUTCOMES = {
    "carry_m": ("carry", "m"),
    "side_m": ("side", "m"),
    "landing_m": ("landing point (distance)", "m"),
    "apex_m": ("max height", "m"),
    "landing_angle_deg": ("land angle", "deg"),
    "flight_time_s": ("flight time", "s"),
}
"""Outcome errors reported for real shots: key -> (name, unit)."""


def outcome_errors(flight: Flight, shots: ShotSet) -> dict[str, np.ndarray]:
    """Per-shot model - recorded errors of every outcome in OUTCOMES (NaN where not recorded or not landed);
    the landing-point error is the unsigned distance between the two landing points."""
    x, y = shots.column("carry_x_m"), shots.column("carry_y_m")
    return {
        "carry_m": flight.carry_m - np.hypot(x, y),
        "side_m": flight.lateral_m - x,
        "landing_m": np.hypot(flight.landing_position[:, 0] - x, flight.landing_position[:, 1] - y),
        "apex_m": flight.apex_m - shots.column("apex_m"),
        "landing_angle_deg": flight.landing_angle_deg - shots.column("landing_angle_deg"),
        "flight_time_s": flight.flight_time_s - shots.column("flight_time_s"),
    }


@dataclass(frozen=True)
class Metric:
    """One row of a comparison table: a statistic of one outcome error, in display units."""

    name: str
    key: str
    statistic: str  # "mean" (of an unsigned error), "bias" or "mae"
    scale: float = 1.0
    digits: int = 2

    def of(self, errors: dict[str, np.ndarray], mask: np.ndarray | None = None) -> float:
        values = errors[self.key] if mask is None else errors[self.key][mask]
        values = values[np.isfinite(values)]
        if not len(values):
            return float("nan")
        if self.statistic == "mae":
            values = np.abs(values)
        return float(np.mean(values)) / self.scale


LANDING_ERROR = Metric("landing error, yd", "landing_m", "mean", YARD_M)
APEX_MAE_YD = Metric("max height MAE, yd", "apex_m", "mae", YARD_M)
FLIGHT_METRICS = (
    LANDING_ERROR,
    Metric("carry MAE, yd", "carry_m", "mae", YARD_M),
    Metric("carry bias, yd", "carry_m", "bias", YARD_M),
    Metric("side MAE, yd", "side_m", "mae", YARD_M),
    Metric("side bias, yd", "side_m", "bias", YARD_M),
    APEX_MAE_YD,
    Metric("max height bias, yd", "apex_m", "bias", YARD_M),
    Metric("land angle MAE, deg", "landing_angle_deg", "mae"),
    Metric("land angle bias, deg", "landing_angle_deg", "bias"),
    Metric("flight time MAE, s", "flight_time_s", "mae"),
    Metric("flight time bias, s", "flight_time_s", "bias"),
)
"""What each model is scored on where a set records whole flights (TrackMan drivers, the Sentry trajectories): the
landing error (a distance, unsigned) and every outcome's MAE with its bias (model - recorded) beside it."""
APEX_METRICS = (
    Metric("apex MAE, ft", "apex_m", "mae", FOOT_M, 1),
    Metric("apex bias, ft", "apex_m", "bias", FOOT_M, 1),
)
"""What each model is scored on where a set records the apex only (the TOUR Championship pbp)."""


def held_out_driver_shots(path: str | os.PathLike) -> tuple[ShotSet, str]:
    """The outdoor (radar-tracked) driver shots on the held-out lines of the TrackMan export (`shots.heldout`) whose
    apex reaches the training filter's 8 yd (malformed rows are left out, as the loader reports), and a sentence
    saying what was kept. Lines before the held-out range are not read as shots at all."""
    first = TRACKMAN_HELD_OUT.first_line
    conversion = load_trackman(path, lines=(first, 10**9), skip_bad_rows=True)
    shots = ShotSet(conversion.records)
    landed = ~np.isnan(shots.column("carry_x_m")) & ~np.isnan(shots.column("carry_y_m"))
    keep = landed & (shots.column("apex_m") >= MIN_APEX_M)
    note = (
        f"lines {first} onward (held out: never trained on): {conversion.report.rows_in} rows; "
        f"{conversion.report.kept} measured outdoor flights (radar track >= 90 % of the flight, launch complete and in "
        f"range); {int(keep.sum())} of them with a carry and a max height of at least 8 yd (the training filter)"
    )
    return shots.subset(keep), note


def ball_types(path: str | os.PathLike) -> dict[str, str]:
    """The 'Ball' cell of every row of a TrackMan export, keyed like the loader's shot_id (the file line number),
    read by the loader's own table reader (which also skips an optional 'sep=,' first line)."""
    header, _, rows = read_table(Path(path))
    if "Ball" not in header:
        return {}
    column = header.index("Ball")
    return {str(line): row[column].strip() for line, row in rows if len(row) > column}


def tour_championship_shots(path: str | os.PathLike) -> tuple[ShotSet, str]:
    """The tee shots of the TOUR Championship 2020's held-out rounds (3-4, `shots.heldout`) with a radar launch, spin
    and apex (`shots.pbp.load_pbp`; spin axis 0), and a sentence saying what was kept; rounds 1-2 are left out."""
    rounds = held_out_rounds(path)
    conversion = load_pbp(path, apex=True, skip_bad_rows=True)
    held = [r for r in conversion.records if shot_round(r.shot_id) in rounds]
    shots = ShotSet([r for r in held if r.apex_m is not None])
    note = (
        f"{conversion.report.rows_in} pbp rows in; {conversion.report.kept} tee shots converted (radar launch and "
        f"spin; no spin axis in the data, so 0), {len(held)} of them in {TOUR_CHAMPIONSHIP_HELD_OUT.rows()} (held "
        f"out: never trained on; the other rounds may be), {len(shots)} with a radar apex"
    )
    return shots, note


def shot_hole(shot_id: str) -> int:
    """The hole of a tour shot id ('060-R3-H15-P29725-S1' -> 15)."""
    match = HOLE.search(shot_id)
    if match is None:
        raise InputError(f"{shot_id!r} names no hole")
    return int(match["hole"])


def tee_groups(shots: ShotSet, pars: dict[int, int]) -> dict[str, np.ndarray]:
    """A mask of the tee shots of each of TEE_GROUPS, by the par of each shot's hole (`shots.pbp.hole_pars`; a hole
    whose par is unknown is in no group)."""
    par = np.array([pars.get(shot_hole(r.shot_id or ""), 0) for r in shots.records], dtype=int)
    return {name: np.isin(par, group) for name, group in TEE_GROUPS.items()}


@dataclass
class PathErrors:
    """3-D position error (m) between the model's flight and the measured path, for the shots in flight at each time."""

    times_s: np.ndarray
    errors_m: list[np.ndarray]

    def at(self, time_s: float) -> np.ndarray:
        return self.errors_m[int(np.argmin(np.abs(self.times_s - time_s)))]


def path_errors(flight: Flight, trajectories: Sequence[np.ndarray]) -> PathErrors:
    """Compare the model's states (every step, relative to its start point) with each measured trajectory [T, 4] of
    t, x, y, z (relative to the start), interpolated to the step times; a shot counts while both are in the air."""
    if flight.states is None or flight.times_s is None:
        raise InputError("the flight was simulated without keep_states")
    positions = np.stack([s.position for s in flight.states]) - flight.states[0].position[None]
    model_end = np.where(flight.landed, flight.flight_time_s, np.inf)
    errors = []
    for i, t in enumerate(flight.times_s):
        in_air = [j for j, path in enumerate(trajectories) if t < min(model_end[j], path[-1, 0])]
        measured = np.array(
            [[np.interp(t, trajectories[j][:, 0], trajectories[j][:, k]) for k in (1, 2, 3)] for j in in_air]
        ).reshape(-1, 3)
        errors.append(np.linalg.norm(positions[i, in_air] - measured, axis=-1))
    return PathErrors(np.asarray(flight.times_s), errors)
