"""Calibrate the reference world against TrackMan's tour averages and spin-decay figures, and report the fit.

The fit is a bounded least squares over the 12 clubs' carry, max height and land angle (flown at
CALIBRATION_AIR, launch direction and spin axis 0) plus TrackMan's Pro V1x spin losses after 1/3/5 s.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from flight.air import Air
from flight.coefficients import QuadraticSpinRatio
from flight.constants import YARD_M
from flight.integrator import simulate
from flight.outcomes import Flight
from flight.physics import State, initial_state
from flight.reference_aero import (
    CALIBRATED,
    FREE_PARAMETERS,
    REFERENCE_DT_S,
    REFERENCE_T_MAX_S,
    ReferenceParameters,
)
from shots.reference_world import CALIBRATION_AIR, ClubAverage, fly_reference

DECAY_TIMES_S = (1.0, 3.0, 5.0)
TRACKMAN_SPIN_LOSS_PCT = {"Driver": (3.1, 8.8, 12.8), "5-iron": (3.4, 9.7, 15.5), "8-iron": (3.6, 9.0, 13.3)}
"""Spin lost (%) after 1/3/5 s, TrackMan on a Pro V1x (NOTES.md section 2), flown with these clubs' tour launch."""

RESIDUAL_SCALES = {"carry_yd": 3.0, "max_height_yd": 2.0, "land_angle_deg": 2.0, "spin_loss_pct": 0.5}
"""Each residual is divided by its scale: the MAE targets for the flight, half a percentage point for spin."""

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

@dataclass(frozen=True)
class Evaluation:
    """Model outcomes for the table's clubs (arrays in file order) and the spin losses of the decay clubs."""

    clubs: list[ClubAverage]
    carry_yd: np.ndarray
    max_height_yd: np.ndarray
    land_angle_deg: np.ndarray
    spin_loss_pct: dict[str, np.ndarray]

    def targets(self) -> np.ndarray:
        """TrackMan's carry, max height, land angle [12, 3]."""
        return np.array([[c.carry_yd, c.max_height_yd, c.land_angle_deg] for c in self.clubs])

    def outcomes(self) -> np.ndarray:
        """The model's carry, max height, land angle [12, 3]."""
        return np.stack([self.carry_yd, self.max_height_yd, self.land_angle_deg], axis=1)

    def mean_absolute_error(self) -> np.ndarray:
        """MAE over the clubs of carry (yd), max height (yd), land angle (deg)."""
        return np.mean(np.abs(self.outcomes() - self.targets()), axis=0)


def launch_state(clubs: list[ClubAverage]) -> State:
    """Initial state of each club's average launch, straight at the target with no spin-axis tilt."""
    zeros = np.zeros(len(clubs))
    return initial_state(
        np.array([c.ball_speed_mps for c in clubs]),
        np.array([c.launch_angle_deg for c in clubs]),
        zeros,
        np.array([c.spin_rpm for c in clubs]),
        zeros,
    )


def spin_loss_pct(flight: Flight, rows: list[int], times_s: tuple[float, ...] = DECAY_TIMES_S) -> np.ndarray:
    """Percentage of the launch spin lost at each time [len(rows), len(times)], from a keep_states flight."""
    spin = np.stack([np.linalg.norm(s.spin[rows], axis=-1) for s in flight.states])
    index = [int(round(t / (flight.times_s[1] - flight.times_s[0]))) for t in times_s]
    if index[-1] >= len(spin):
        raise ValueError(f"the flights end before {times_s[-1]} s: no spin loss to compare")
    return 100.0 * (1.0 - spin[index].T / spin[0][:, None])


def _outcome(flight: Flight, clubs: list[ClubAverage]) -> Evaluation:
    index = {c.club: i for i, c in enumerate(clubs)}
    missing = [name for name in TRACKMAN_SPIN_LOSS_PCT if name not in index]
    if missing:
        raise ValueError(f"the tour-averages table has no rows for {missing}, needed for the spin-decay figures")
    losses = spin_loss_pct(flight, [index[name] for name in TRACKMAN_SPIN_LOSS_PCT])
    return Evaluation(
        clubs,
        flight.carry_m / YARD_M,
        flight.apex_m / YARD_M,
        flight.landing_angle_deg,
        dict(zip(TRACKMAN_SPIN_LOSS_PCT, losses)),
    )


def evaluate(
    clubs: list[ClubAverage], params: ReferenceParameters = CALIBRATED, air: Air = CALIBRATION_AIR
) -> Evaluation:
    """Fly every club's average launch through the reference world."""
    return _outcome(fly_reference(launch_state(clubs), air, keep_states=True, params=params), clubs)


def evaluate_ferguson(clubs: list[ClubAverage], air: Air = CALIBRATION_AIR) -> Evaluation:
    """The same shots with Ferguson 2022's quadratics (the open-model baseline), same integrator and air."""
    flight = simulate(
        launch_state(clubs), QuadraticSpinRatio(), air.density_kg_m3, dt=REFERENCE_DT_S,
        t_max=REFERENCE_T_MAX_S, method="rk4", keep_states=True,
    )
    return _outcome(flight, clubs)


def residuals(params: ReferenceParameters, clubs: list[ClubAverage]) -> np.ndarray:
    """Scaled misfits: (model - TrackMan) / scale for every club's three outcomes, then the nine spin losses."""
    result = evaluate(clubs, params)
    flight_scale = np.array([RESIDUAL_SCALES[k] for k in ("carry_yd", "max_height_yd", "land_angle_deg")])
    flight = ((result.outcomes() - result.targets()) / flight_scale).ravel()
    spin = np.concatenate([result.spin_loss_pct[name] - np.array(pct) for name, pct in TRACKMAN_SPIN_LOSS_PCT.items()])
    spin /= RESIDUAL_SCALES["spin_loss_pct"]
    return np.nan_to_num(np.concatenate([flight, spin]), nan=1e3)


def fit_reference(
    clubs: list[ClubAverage], start: ReferenceParameters = CALIBRATED, max_evaluations: int = 200
) -> ReferenceParameters:
    """Least-squares fit of FREE_PARAMETERS (each scaled by its start value) inside BOUNDS; knobs stay as in start."""
    typical = np.array([abs(getattr(start, name)) or 1.0 for name in FREE_PARAMETERS])
    low = np.array([BOUNDS[name][0] for name in FREE_PARAMETERS]) / typical
    high = np.array([BOUNDS[name][1] for name in FREE_PARAMETERS]) / typical

    def with_values(x: np.ndarray) -> ReferenceParameters:
        return dataclasses.replace(start, **{name: float(v) for name, v in zip(FREE_PARAMETERS, x * typical)})

    x0 = np.clip(np.array([getattr(start, name) for name in FREE_PARAMETERS]) / typical, low, high)
    solution = least_squares(
        lambda x: residuals(with_values(x), clubs), x0, bounds=(low, high), diff_step=1e-3, max_nfev=max_evaluations
    )
    return with_values(solution.x)


def parameters_literal(params: ReferenceParameters) -> str:
    """Source of `CALIBRATED = ReferenceParameters(...)` with the fitted values, to paste into
    flight/reference_aero.py."""
    lines = [f"    {name}={_round(getattr(params, name))!r}," for name in FREE_PARAMETERS]
    return "CALIBRATED = ReferenceParameters(\n" + "\n".join(lines) + "\n)"


def _round(value: float) -> float:
    return float(f"{value:.5g}")


def _signed(value: float) -> str:
    return f"{value:+.1f}"


def render_markdown(evaluation: Evaluation, params: ReferenceParameters, baseline: Evaluation | None = None) -> str:
    """Markdown: the parameters, the per-club table (model vs TrackMan, errors, MAE) and the spin-decay table."""
    out = ["### Parameters", "", "| parameter | value |", "|---|---|"]
    out += [f"| `{name}` | {_round(getattr(params, name)):g} |" for name in FREE_PARAMETERS]
    out += [
        "",
        "### PGA TOUR 2023 averages: model vs TrackMan",
        "",
        "| club | carry model | carry TM | err | max h model | max h TM | err | land model | land TM | err |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for club, model, target in zip(evaluation.clubs, evaluation.outcomes(), evaluation.targets()):
        cells = [f"{m:.1f} | {t:g} | {_signed(m - t)}" for m, t in zip(model, target)]
        out.append(f"| {club.club} | " + " | ".join(cells) + " |")
    mae = evaluation.mean_absolute_error()
    out.append(f"| **MAE** | | | **{mae[0]:.2f} yd** | | | **{mae[1]:.2f} yd** | | | **{mae[2]:.2f}°** |")
    if baseline is not None:
        ref = baseline.mean_absolute_error()
        bias = np.mean(baseline.outcomes() - baseline.targets(), axis=0)
        cells = [f"{error:.2f} ({_signed(b)})" for error, b in zip(ref, bias)]
        out.append("| Ferguson 2022 MAE (bias) | | | " + " | | | ".join(cells) + " |")
    header = " | ".join(f"{t:g} s model | {t:g} s TM" for t in DECAY_TIMES_S)
    out += ["", "### Spin lost (%) after 1 / 3 / 5 s: model vs TrackMan (Pro V1x)", "", f"| shot | {header} |"]
    out.append("|---|" + "---:|" * (2 * len(DECAY_TIMES_S)))
    for name, target in TRACKMAN_SPIN_LOSS_PCT.items():
        cells = [f"{m:.1f} | {t:g}" for m, t in zip(evaluation.spin_loss_pct[name], target)]
        out.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"
