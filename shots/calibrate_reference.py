"""Calibrate the reference world on recordings that may be trained on, each in its own air.

The fit is a bounded least squares over calibration cells (one source's shots in one ball-speed band, each shot
flown with its own launch and in its source's air; or one club of TrackMan's tour-averages table) plus TrackMan's
Pro V1x spin losses after 1/3/5 s. A cell contributes the difference between the mean of the model's outcomes and
the mean of the recorded ones, per observable it has. A source that recorded no air (range sessions) gets a fitted
density factor with a loose prior (`fit_reference`), so the sources with known air set the level of a carry.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.coefficients import QuadraticSpinRatio
from golfflight.flight.constants import YARD_M
from golfflight.flight.flyer import FixedCoefficients, Flyer
from golfflight.flight.integrator import RUNGE_KUTTA_4
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import State, initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.flight.reference_aero import (
    CALIBRATED,
    FREE_PARAMETERS,
    REFERENCE_DT_S,
    REFERENCE_T_MAX_S,
    ReferenceParameters,
)
from golfflight.shots.clubs import CLUBS, straight_launches
from golfflight.shots.markdown import signed
from golfflight.shots.progress import progress_bar
from golfflight.shots.records import ShotRecord
from golfflight.shots.reference_world import CALIBRATION_AIR, ClubAverage, fly_reference
from scipy.optimize import least_squares

DECAY_TIMES_S = (1.0, 3.0, 5.0)
TRACKMAN_SPIN_LOSS_PCT = {"Driver": (3.1, 8.8, 12.8), "5-iron": (3.4, 9.7, 15.5), "8-iron": (3.6, 9.0, 13.3)}
"""Spin lost (%) after 1/3/5 s, TrackMan on a Pro V1x (published in a TrackMan patent; docs/reference_world.md),
flown with these clubs' launch in `shots.clubs.CLUBS`."""

OBSERVABLES = ("carry_y_m", "apex_m", "landing_angle_deg")
"""What a cell can match, in the order of every per-cell array: the carry along the launch monitor's target line
(what the records hold, not the straight-line distance), the apex (max height), the landing angle."""

RESIDUAL_SCALES = {"carry_y_m": 3.0 * YARD_M, "apex_m": 2.0 * YARD_M, "landing_angle_deg": 2.0, "spin_loss_pct": 0.5}
"""Each residual is divided by its scale: the flight targets of the product (3 yd, 2 yd, 2 deg), half a percentage
point for spin."""

SPEED_BANDS_MPS = (0.0, 52.0, 60.0, 66.0, 72.0, 200.0)
"""Ball-speed bands a source's shots are grouped into: wedges and short irons, mid irons, long irons and hybrids,
fairway woods, drivers (the 2020 pbp files name no club)."""

MIN_CELL_SHOTS = 15
"""A band with fewer recorded values of an observable leaves that observable out (its mean is mostly wind)."""
TABLE_CELL_WEIGHT = 2.0
"""A tour-averages club counts as two cells: its residuals are divided by half the scales (1.5 yd, 1 yd, 1 deg)."""
MAX_CELL_SHOTS = 150
"""A bigger band is thinned to every k-th shot in file order (k = ceil(n / 150)): the mean of 150 shots is within
about a yard of all of theirs, and one flight of every cell costs seconds, which a fit repeats hundreds of times."""

BOUNDS: dict[str, tuple[float, float]] = {
    "drag_base": (0.05, 0.30),
    "drag_spin_span": (0.0, 0.50),
    "lift_max": (0.20, 0.70),
    "lift_half_spin_ratio": (0.05, 0.60),
    "critical_reynolds": (6.0e4, 9.0e4),
    "lift_spin_protection": (0.05, 2.0),
    "spin_decay_coefficient": (0.001, 0.05),
    "spin_decay_spin_exponent": (0.5, 2.0),
    "spin_decay_reynolds_exponent": (-1.0, 1.5),
}
"""Search box of the fit; critical Re kept inside Lyu 2018's crisis (C_D 0.5 at 5e4, 0.2 by 1e5)."""


UNKNOWN_AIR_PRIOR_SD = 0.1
"""Prior sd of the log density factor of a source that recorded no air: range days from cold to hot and from the coast
to a few hundred metres up differ by up to about 10 %."""
AIR_FACTOR_LOG_BOUND = 0.3
"""The search box of each log density factor."""


@dataclass(frozen=True)
class CalibrationCell:
    """Shots of one source in one ball-speed band (or one club's average shot): their launches, the air they are
    flown in, what was recorded."""

    name: str
    launch: dict[str, np.ndarray]
    air: Air
    recorded: np.ndarray
    """[n_shots, len(OBSERVABLES)]; NaN where a shot has no record of an observable."""
    min_shots: int = MIN_CELL_SHOTS
    """Recorded values an observable needs to enter the fit: a band's mean of fewer is mostly wind; a table's
    average needs one."""
    weight: float = 1.0
    """Each residual of the cell is multiplied by this: a table's average over thousands of shots in many events'
    weather is known better than a band's mean of one event or session (`TABLE_CELL_WEIGHT`)."""

    @property
    def n_shots(self) -> int:
        return len(self.recorded)

    @property
    def source(self) -> str:
        """The source the cell belongs to (its name's first word)."""
        return self.name.split(" ")[0]

    def used(self) -> np.ndarray:
        """Which observables this cell has enough recorded values of to enter the fit [len(OBSERVABLES)]."""
        return np.sum(np.isfinite(self.recorded), axis=0) >= self.min_shots

    def in_denser_air(self, factor: float) -> CalibrationCell:
        """The cell flown in air `factor` times as dense at the same temperature (μ unchanged, so ν = μ/ρ divides by
        the factor)."""
        air = Air(self.air.density_kg_m3 * factor, self.air.kinematic_viscosity_m2_s / factor)
        return dataclasses.replace(self, air=air)


def with_air_factors(cells: list[CalibrationCell], factors: dict[str, float]) -> list[CalibrationCell]:
    """Every cell of a source named in `factors` flown in its source's fitted air."""
    return [c.in_denser_air(factors[c.source]) if c.source in factors else c for c in cells]


def cells_from_records(
    source: str, records: list[ShotRecord], air: Air, bands: tuple[float, ...] = SPEED_BANDS_MPS
) -> list[CalibrationCell]:
    """Split one source's records by ball-speed band; bands without any usable observable are left out."""
    speed = np.array([r.ball_speed_mps for r in records])
    cells = []
    for low, high in itertools.pairwise(bands):
        chosen = [r for r, s in zip(records, speed) if low <= s < high]
        if not chosen:
            continue
        chosen = chosen[::-(-len(chosen) // MAX_CELL_SHOTS)]
        launch = {
            key: np.array([getattr(r, key) for r in chosen])
            for key in ("ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm", "spin_axis_deg")
        }
        recorded = np.array([[_value(r.carry_y_m), _value(r.apex_m), _value(r.landing_angle_deg)]
                             for r in chosen])
        cell = CalibrationCell(f"{source} {low:g}-{high:g} m/s" if high < bands[-1] else f"{source} >= {low:g} m/s",
                               launch, air, recorded)
        if cell.used().any():
            cells.append(cell)
    return cells


def table_cells(source: str, clubs: list[ClubAverage], air: Air) -> list[CalibrationCell]:
    """One cell per club of a tour-averages table: its average launch, straight, and its average outcomes."""
    cells = []
    for club in clubs:
        launch = straight_launches([club])
        recorded = np.array([[club.carry_yd * YARD_M, club.max_height_yd * YARD_M, club.land_angle_deg]])
        cells.append(CalibrationCell(f"{source} {club.club}", launch, air, recorded, min_shots=1,
                                     weight=TABLE_CELL_WEIGHT))
    return cells


def _value(x: float | None) -> float:
    return np.nan if x is None else float(x)


@dataclass(frozen=True)
class CellEvaluation:
    """Model and recorded means per cell and observable (NaN where a cell does not use one) and the spin losses."""

    cells: list[CalibrationCell]
    model_mean: np.ndarray
    recorded_mean: np.ndarray
    spin_loss_pct: dict[str, np.ndarray]

    def scaled_errors(self) -> np.ndarray:
        """(model - recorded) / scale per cell and observable [n_cells, 3]; NaN where unused."""
        scales = np.array([RESIDUAL_SCALES[k] for k in OBSERVABLES])
        return (self.model_mean - self.recorded_mean) / scales


def _fly_cells(cells: list[CalibrationCell], params: ReferenceParameters) -> list[np.ndarray]:
    """Carry, apex, landing angle [n_shots, 3] per cell, flown as one batch (each shot in its cell's air)."""
    launch = {key: np.concatenate([c.launch[key] for c in cells]) for key in cells[0].launch}
    air = Air(np.concatenate([np.full(c.n_shots, c.air.density_kg_m3) for c in cells]),
              np.concatenate([np.full(c.n_shots, c.air.kinematic_viscosity_m2_s) for c in cells]))
    flight = fly_reference(initial_state(**launch), air, params=params)
    ends = np.cumsum([c.n_shots for c in cells])
    outcomes = np.stack([flight.landing_position[:, 1], flight.apex_m, flight.landing_angle_deg], axis=1)
    return np.split(outcomes, ends[:-1])


def evaluate(cells: list[CalibrationCell], params: ReferenceParameters = CALIBRATED) -> CellEvaluation:
    """Fly every cell's shots and the spin-decay launches through the reference world."""
    model_mean = np.full((len(cells), len(OBSERVABLES)), np.nan)
    recorded_mean = np.full_like(model_mean, np.nan)
    for i, (cell, model) in enumerate(zip(cells, _fly_cells(cells, params))):
        for k in np.flatnonzero(cell.used()):
            has = np.isfinite(cell.recorded[:, k])
            model_mean[i, k] = np.mean(model[has, k])
            recorded_mean[i, k] = np.mean(cell.recorded[has, k])
    return CellEvaluation(cells, model_mean, recorded_mean, spin_losses(params))


def decay_launch() -> State:
    """The launches of the spin-decay clubs (`shots.clubs.CLUBS`), straight, no spin-axis tilt."""
    clubs = {c.name: c for c in CLUBS}
    return initial_state(**straight_launches([clubs[name] for name in TRACKMAN_SPIN_LOSS_PCT]))


def spin_losses(params: ReferenceParameters = CALIBRATED, air: Air = CALIBRATION_AIR) -> dict[str, np.ndarray]:
    """Percentage of the launch spin each decay club has lost after DECAY_TIMES_S."""
    flight = fly_reference(decay_launch(), air, keep_states=True, params=params)
    return dict(zip(TRACKMAN_SPIN_LOSS_PCT, spin_loss_pct(flight, list(range(len(TRACKMAN_SPIN_LOSS_PCT))))))


def spin_loss_pct(flight: Flight, rows: list[int], times_s: tuple[float, ...] = DECAY_TIMES_S) -> np.ndarray:
    """Percentage of the launch spin lost at each time [len(rows), len(times)], from a keep_states flight."""
    spin = np.stack([np.linalg.norm(s.spin[rows], axis=-1) for s in flight.states])
    index = [int(round(t / (flight.times_s[1] - flight.times_s[0]))) for t in times_s]
    if index[-1] >= len(spin):
        raise InputError(f"the flights end before {times_s[-1]} s: no spin loss to compare")
    return 100.0 * (1.0 - spin[index].T / spin[0][:, None])


def residuals(params: ReferenceParameters, cells: list[CalibrationCell]) -> np.ndarray:
    """Scaled misfits: every used (cell, observable) mean difference, then the nine spin losses."""
    result = evaluate(cells, params)
    flight = result.scaled_errors() * np.array([c.weight for c in cells])[:, None]
    flight = flight[np.isfinite(result.recorded_mean)]
    spin = np.concatenate([result.spin_loss_pct[name] - np.array(pct) for name, pct in TRACKMAN_SPIN_LOSS_PCT.items()])
    return np.nan_to_num(np.concatenate([flight, spin / RESIDUAL_SCALES["spin_loss_pct"]]), nan=1e3)


@dataclass(frozen=True)
class FitScaling:
    """FREE_PARAMETERS as a least-squares fit sees them: each divided by its start value, inside BOUNDS; the knobs
    and everything else stay as in `start`."""

    start: ReferenceParameters

    @property
    def typical(self) -> np.ndarray:
        return np.array([abs(getattr(self.start, name)) or 1.0 for name in FREE_PARAMETERS])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of the scaled values."""
        return (np.array([BOUNDS[name][0] for name in FREE_PARAMETERS]) / self.typical,
                np.array([BOUNDS[name][1] for name in FREE_PARAMETERS]) / self.typical)

    def start_values(self) -> np.ndarray:
        """The start's scaled values, clipped into the bounds."""
        return np.clip(np.array([getattr(self.start, name) for name in FREE_PARAMETERS]) / self.typical, *self.bounds())

    def parameters(self, x: np.ndarray) -> ReferenceParameters:
        """The parameters of scaled values x."""
        return dataclasses.replace(self.start, **{n: float(v) for n, v in zip(FREE_PARAMETERS, x * self.typical)})


@dataclass(frozen=True)
class Calibration:
    """A fit's parameters, the fitted density factor of each source that recorded no air, and the cost."""

    params: ReferenceParameters
    air_factors: dict[str, float]
    cost: float


def fit_reference(
    cells: list[CalibrationCell], start: ReferenceParameters = CALIBRATED, max_evaluations: int = 200,
    unknown_air: tuple[str, ...] = (), prior_sd: float = UNKNOWN_AIR_PRIOR_SD, progress: bool = True,
) -> Calibration:
    """Least-squares fit of FREE_PARAMETERS (each scaled by its start value) inside BOUNDS, together with a log
    density factor per `unknown_air` source (Gaussian prior of `prior_sd` about its cells' air); knobs stay as in
    start. With `progress`, a count of the cells' flights (each a trial of the parameters, the Jacobian's among
    them) goes to standard error: a fit takes minutes."""
    scaling = FitScaling(start)
    n = len(FREE_PARAMETERS)
    low, high = scaling.bounds()
    low = np.append(low, np.full(len(unknown_air), -AIR_FACTOR_LOG_BOUND))
    high = np.append(high, np.full(len(unknown_air), AIR_FACTOR_LOG_BOUND))

    def unpack(x: np.ndarray) -> tuple[ReferenceParameters, dict[str, float]]:
        return scaling.parameters(x[:n]), dict(zip(unknown_air, np.exp(x[n:]).tolist()))

    trials = progress_bar(desc="fitting the reference world", unit="flight", shown=progress)

    def misfit(x: np.ndarray) -> np.ndarray:
        params, factors = unpack(x)
        misfits = np.concatenate([residuals(params, with_air_factors(cells, factors)), x[n:] / prior_sd])
        trials.update()
        return misfits

    with trials:
        solution = least_squares(misfit, np.append(scaling.start_values(), np.zeros(len(unknown_air))),
                                 bounds=(low, high), diff_step=1e-3, max_nfev=max_evaluations)
    params, factors = unpack(solution.x)
    return Calibration(params, factors, float(solution.cost))


@dataclass(frozen=True)
class CalibrationClub:
    """A model's outcomes for the tour-averages table's clubs, beside TrackMan's."""

    clubs: list[ClubAverage]
    carry_yd: np.ndarray
    max_height_yd: np.ndarray
    land_angle_deg: np.ndarray

    def targets(self) -> np.ndarray:
        """TrackMan's carry, max height, land angle [n_clubs, 3]."""
        return np.array([[c.carry_yd, c.max_height_yd, c.land_angle_deg] for c in self.clubs])

    def outcomes(self) -> np.ndarray:
        """The model's carry, max height, land angle [n_clubs, 3]."""
        return np.stack([self.carry_yd, self.max_height_yd, self.land_angle_deg], axis=1)

    def mean_absolute_error(self) -> np.ndarray:
        """MAE over the clubs of carry (yd), max height (yd), land angle (deg)."""
        return np.mean(np.abs(self.outcomes() - self.targets()), axis=0)


def club_launch_state(clubs: list[ClubAverage]) -> State:
    """Initial state of each club's average launch, straight at the target with no spin-axis tilt."""
    return initial_state(**straight_launches(clubs))


def _club_check(flight: Flight, clubs: list[ClubAverage]) -> CalibrationClub:
    return CalibrationClub(clubs, flight.carry_m / YARD_M, flight.apex_m / YARD_M, flight.landing_angle_deg)


def evaluate_clubs(
    clubs: list[ClubAverage], params: ReferenceParameters = CALIBRATED, air: Air = CALIBRATION_AIR
) -> CalibrationClub:
    """Fly every club's average launch through the reference world."""
    return _club_check(fly_reference(club_launch_state(clubs), air, params=params), clubs)


def evaluate_clubs_ferguson(clubs: list[ClubAverage], air: Air = CALIBRATION_AIR) -> CalibrationClub:
    """The same shots with Ferguson 2022's quadratics (the open-model baseline), same integrator and air."""
    flyer = Flyer(FixedCoefficients(QuadraticSpinRatio()), REFERENCE_DT_S, REFERENCE_T_MAX_S, air.density_kg_m3,
                  air.kinematic_viscosity_m2_s, RUNGE_KUTTA_4)
    return _club_check(flyer.flight(FlightProblem(club_launch_state(clubs))), clubs)


def parameters_literal(params: ReferenceParameters) -> str:
    """Source of `CALIBRATED = ReferenceParameters(...)` with the fitted values, to paste into
    flight/reference_aero.py."""
    lines = [f"    {name}={_round(getattr(params, name))!r}," for name in FREE_PARAMETERS]
    return "CALIBRATED = ReferenceParameters(\n" + "\n".join(lines) + "\n)"


def _round(value: float) -> float:
    return float(f"{value:.5g}")


def render_markdown(evaluation: CellEvaluation, params: ReferenceParameters, check: CalibrationClub | None = None,
                    ferguson: CalibrationClub | None = None, air_factors: dict[str, float] | None = None) -> str:
    """Markdown: the parameters (and fitted air factors), the per-cell fit table, the spin-decay table and the
    tour-averages table per club."""
    out = ["### Parameters", "", "| parameter | value |", "|---|---|"]
    out += [f"| `{name}` | {_round(getattr(params, name)):g} |" for name in FREE_PARAMETERS]
    out += [f"| air density factor of `{source}` (fitted: recorded no air) | {factor:.3f} |"
            for source, factor in (air_factors or {}).items()]
    out += [
        "",
        "### Calibration cells: mean of the model's flights vs mean of the recordings",
        "",
        ("| cell | shots | carry model (yd) | carry recorded | err | max h model (yd) | recorded | err "
         "| land model (°) | recorded | err |"),
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    units = np.array([YARD_M, YARD_M, 1.0])
    for cell, model, recorded in zip(evaluation.cells, evaluation.model_mean / units, evaluation.recorded_mean / units):
        cells = ["—| —| —" if np.isnan(m) else f"{m:.1f} | {r:.1f} | {signed(m - r)}" for m, r in zip(model, recorded)]
        out.append(f"| {cell.name} | {cell.n_shots} | " + " | ".join(cells) + " |")
    header = " | ".join(f"{t:g} s model | {t:g} s TM" for t in DECAY_TIMES_S)
    out += ["", "### Spin lost (%) after 1 / 3 / 5 s: model vs TrackMan (Pro V1x)", "", f"| shot | {header} |"]
    out.append("|---|" + "---:|" * (2 * len(DECAY_TIMES_S)))
    for name, target in TRACKMAN_SPIN_LOSS_PCT.items():
        cells = [f"{m:.1f} | {t:g}" for m, t in zip(evaluation.spin_loss_pct[name], target)]
        out.append(f"| {name} | " + " | ".join(cells) + " |")
    if check is not None:
        out += _club_check_markdown(check, ferguson)
    return "\n".join(out) + "\n"


def _club_check_markdown(check: CalibrationClub, ferguson: CalibrationClub | None) -> list[str]:
    out = [
        "",
        "### PGA TOUR 2023 averages per club, model vs TrackMan (the training clubs are cells of the fit)",
        "",
        "| club | carry model | carry TM | err | max h model | max h TM | err | land model | land TM | err |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for club, model, target in zip(check.clubs, check.outcomes(), check.targets()):
        cells = [f"{m:.1f} | {t:g} | {signed(m - t)}" for m, t in zip(model, target)]
        out.append(f"| {club.club} | " + " | ".join(cells) + " |")
    mae = check.mean_absolute_error()
    bias = np.mean(check.outcomes() - check.targets(), axis=0)
    out.append("| **MAE (bias)** | | | " + " | | | ".join(
        f"**{e:.2f}** ({signed(b)})" for e, b in zip(mae, bias)) + " |")
    if ferguson is not None:
        ref = ferguson.mean_absolute_error()
        ref_bias = np.mean(ferguson.outcomes() - ferguson.targets(), axis=0)
        out.append("| Ferguson 2022 MAE (bias) | | | " + " | | | ".join(
            f"{e:.2f} ({signed(b)})" for e, b in zip(ref, ref_bias)) + " |")
    return out
