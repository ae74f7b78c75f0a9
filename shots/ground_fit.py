"""Fit the fairway's ground parameters on real rest positions and check them on held-out ones (docs/ground.md).

Each radar-measured tee shot of a PGA TOUR pbp file that ShotLink puts at rest on the fairway (lie ELF or ERF) is
flown from its launch (spin axis 0: none recorded; calm ICAO air: no weather recorded) through a model bundle down
to a ground plane at its rest elevation, then bounced and rolled to rest by `flight.ground` on the fairway. The
fairway's restitution scale, critical angle, rolling resistance and grass drag are fitted (scipy.optimize,
Nelder-Mead from several starts) to the mean absolute error of the tee-to-rest distance on THE PLAYERS 2020 (with a
weak pull towards physical anchors, PRIOR_WEIGHT_M), and
checked on the TOUR Championship 2020 (held out from training, used here to check only) against the best
constant-roll baseline: carry plus the median roll of the same PLAYERS shots.
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np
from golfflight.flight.constants import YARD_M
from golfflight.flight.flyer import Flyer
from golfflight.flight.ground import SURFACES, Surface, ground_phase
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import LAUNCH_WIDTH, FlightProblem
from golfflight.shots.markdown import table
from golfflight.shots.pbp import load_pbp, recorded_apex, rest_positions
from golfflight.shots.progress import progress_bar, progress_step
from scipy.optimize import minimize

PBP_DIR = Path("real/pga_tourcast_trackman/pbp")
FIT_EVENT = ("THE PLAYERS 2020", PBP_DIR / "pbp_2020_011_011.csv")
CHECK_EVENT = ("TOUR Championship 2020", PBP_DIR / "pbp_2020_060_688.csv")
FAIRWAY_LIES = ("ELF", "ERF")
"""ShotLink's codes for a ball at rest on the fairway, left and right of centre."""

FITTED = ("restitution_scale", "critical_angle_deg", "rolling_resistance", "grass_drag_per_s")
BOUNDS = ((0.2, 1.5), (0.0, 30.0), (0.08, 1.0), (0.0, 5.0))
"""Search bounds (FITTED order). The rest positions cannot tell rolling resistance from grass drag (the error moves
by 0.01 m between c_r = 0.02 and 0.12, docs/ground.md); c_r >= 0.08 keeps a ball at rest on fairway slopes up to
6.4 degrees (`flight.ground.holding_slope_deg`)."""
STARTS = ((1.0, 15.0, 0.12, 1.0), (0.5, 5.0, 0.1, 1.0), (1.0, 0.0, 0.2, 2.0), (0.3, 10.0, 0.3, 0.3))
"""Nelder-Mead starts (in the order of FITTED): the objective is piecewise (bounce counts are whole numbers)."""

ANCHOR = (1.0, 15.0, 0.12, 1.0)
ANCHOR_SCALE = (0.5, 10.0, 0.1, 1.0)
PRIOR_WEIGHT_M = 0.03
"""The rest positions leave the parameters nearly free (many sets fit within 0.02 m, docs/ground.md), so the fit
adds PRIOR_WEIGHT_M metres per squared ANCHOR_SCALE away from ANCHOR (Penner's fairway: restitution 1 and
theta_c 15 degrees; rolling resistance 0.12 g, grass drag 1/s): of the sets that fit equally well, the nearest."""

SWEPT_RESISTANCE = (0.02, 0.05, 0.08, 0.12, 0.2)
"""Rolling resistances held in `resistance_sweep`."""


@dataclass(frozen=True)
class RestShots:
    """Fairway tee shots of one event: launches [N,5] (speed m/s, launch and direction deg, spin rpm, axis 0), the
    tee-to-rest distance and rest elevation relative to the tee [N] (m), and apexRange [N] (m; the carry at THE
    PLAYERS 2020 only, docs/real_data.md)."""

    event: str
    launches: np.ndarray
    distance_m: np.ndarray
    rest_dz_m: np.ndarray
    apex_range_m: np.ndarray


def fairway_shots(event: str, path: str | os.PathLike) -> RestShots:
    """The radar tee shots of a pbp file that came to rest on the fairway, with distance and elevation recorded."""
    records = load_pbp(path, apex=False).records
    rests, apexes = rest_positions(path), recorded_apex(path)
    kept = [
        r for r in records
        if rests[r.shot_id].lie in FAIRWAY_LIES and rests[r.shot_id].distance_m and rests[r.shot_id].dz_m is not None
    ]
    launches = [(r.ball_speed_mps, r.launch_angle_deg, r.launch_direction_deg, r.spin_rpm, 0.0) for r in kept]
    return RestShots(
        event,
        np.array(launches, dtype=float).reshape(-1, LAUNCH_WIDTH),
        np.array([rests[r.shot_id].distance_m for r in kept]),
        np.array([rests[r.shot_id].dz_m for r in kept]),
        np.array([apexes[r.shot_id].range_m if apexes[r.shot_id].range_m else np.nan for r in kept]),
    )


def landings(shots: RestShots, flyer: Flyer) -> Flight:
    """The shots flown by the bundle's Flyer (its step, maximum flight time and air) down to planes at their rest
    elevations."""
    return flyer.flight(FlightProblem(initial_state(*shots.launches.T), grounds=shots.rest_dz_m))


def totals(flight: Flight, surface: Surface) -> np.ndarray:
    """Tee-to-rest horizontal distance [N] of landed flights bounced and rolled on `surface`."""
    phase = ground_phase(flight.landing_position, flight.landing_velocity, flight.landing_spin, surface)
    return np.hypot(phase.rest_position[:, 0], phase.rest_position[:, 1])


def _with(values: np.ndarray) -> Surface:
    return replace(SURFACES["fairway"], **dict(zip(FITTED, (float(v) for v in values), strict=True)))


def fit_fairway(flight: Flight, distance_m: np.ndarray, bounds=BOUNDS) -> tuple[Surface, float]:
    """The fairway parameters (FITTED, within `bounds`; the rest as in the table) with the least mean absolute
    distance error plus the anchors' pull, and that error."""
    def loss(values: np.ndarray) -> float:
        prior = PRIOR_WEIGHT_M * np.sum(((values - np.array(ANCHOR)) / np.array(ANCHOR_SCALE)) ** 2)
        return float(np.mean(np.abs(totals(flight, _with(values)) - distance_m)) + prior)

    starts = (np.clip(start, *np.array(bounds).T) for start in STARTS)
    best = min(
        (minimize(loss, start, method="Nelder-Mead", bounds=bounds,
                  options={"xatol": 1e-3, "fatol": 1e-4, "maxiter": 600}) for start in starts),
        key=lambda result: result.fun,
    )
    return _with(best.x), float(np.mean(np.abs(totals(flight, _with(best.x)) - distance_m)))


def resistance_sweep(
    flight: Flight, distance_m: np.ndarray, progress: bool = False
) -> list[tuple[float, float, float]]:
    """(rolling resistance held, grass drag refitted, fit error) over SWEPT_RESISTANCE: how well the rest positions
    pin the rolling resistance down (a bar over the fits on standard error with `progress`)."""
    rows = []
    index = FITTED.index("rolling_resistance")
    for value in progress_bar(SWEPT_RESISTANCE, "rolling resistance held", unit="fit", shown=progress):
        bounds = tuple((value, value) if i == index else b for i, b in enumerate(BOUNDS))
        fitted, error = fit_fairway(flight, distance_m, bounds)
        rows.append((value, float(fitted.grass_drag_per_s), error))
    return rows


@dataclass(frozen=True)
class Score:
    """Total-distance errors (predicted - ShotLink) of one method on one event, metres."""

    event: str
    method: str
    shots: int
    bias_m: float
    mae_m: float
    rmse_m: float
    median_roll_m: float
    recorded_roll_m: float


def score(event: str, method: str, predicted: np.ndarray, carry: np.ndarray, distance: np.ndarray) -> Score:
    error = predicted - distance
    return Score(
        event, method, len(error), float(np.median(error)), float(np.mean(np.abs(error))),
        float(np.sqrt(np.mean(error**2))), float(np.median(predicted - carry)), float(np.median(distance - carry)),
    )


@dataclass(frozen=True)
class GroundFit:
    """What `golfflight ground-fit` reports: the fitted fairway, the constant roll, the scores and the model."""

    model_sha256: str
    fairway: dict
    fit_mae_m: float
    constant_roll_m: float
    scores: list[Score]
    carry_check: dict
    roll_correlations: dict
    sweep: list[tuple[float, float, float]]

    def as_dict(self) -> dict:
        return {**asdict(self), "scores": [asdict(s) for s in self.scores]}


def run_fit(flyer: Flyer, data_dir: str | os.PathLike, progress: bool = True) -> GroundFit:
    """Fit on THE PLAYERS 2020, check on the TOUR Championship 2020 (files under `data_dir`), flying a bundle's
    Flyer (`flight.flyer.load_flyer`); with `progress`, each step goes to standard error."""
    fit_name, fit_path = FIT_EVENT
    check_name, check_path = CHECK_EVENT
    progress_step(f"flying the fairway tee shots of {fit_name} and {check_name}...", progress)
    fit_shots = fairway_shots(fit_name, Path(data_dir) / fit_path)
    check_shots = fairway_shots(check_name, Path(data_dir) / check_path)
    fit_flight, check_flight = landings(fit_shots, flyer), landings(check_shots, flyer)
    progress_step(f"fitting the fairway on {len(fit_shots.distance_m)} rest positions ({len(STARTS)} starts)...",
                  progress)
    fairway, fit_mae = fit_fairway(fit_flight, fit_shots.distance_m)
    fit_carry, check_carry = fit_flight.carry_m, check_flight.carry_m
    constant = float(np.median(fit_shots.distance_m - fit_carry))
    scores = []
    for shots, flight, carry in ((fit_shots, fit_flight, fit_carry), (check_shots, check_flight, check_carry)):
        scores.append(score(shots.event, f"carry + constant roll ({constant:.1f} m)", carry + constant, carry,
                            shots.distance_m))
        scores.append(score(shots.event, "ground phase, fitted fairway", totals(flight, fairway), carry,
                            shots.distance_m))
        scores.append(score(shots.event, "ground phase, firm_fairway preset", totals(flight, SURFACES["firm_fairway"]),
                            carry, shots.distance_m))
    carry_error = fit_carry - fit_shots.apex_range_m
    carry_check = {
        "event": fit_name,
        "shots": int(np.isfinite(carry_error).sum()),
        "median_m": float(np.nanmedian(carry_error)),
        "iqr_m": float(np.subtract(*np.nanpercentile(carry_error, [75, 25]))),
    }
    correlations = {}
    for shots, flight in ((fit_shots, fit_flight), (check_shots, check_flight)):
        roll = shots.distance_m - flight.carry_m
        correlations[shots.event] = {
            name: float(np.corrcoef(roll, value)[0, 1])
            for name, value in (
                ("landing angle", flight.landing_angle_deg),
                ("landing speed", flight.landing_speed_mps),
                ("landing spin", flight.landing_spin_rpm),
            )
        }
    sweep = resistance_sweep(fit_flight, fit_shots.distance_m, progress)
    return GroundFit(flyer.card.onnx.sha256, asdict(fairway), fit_mae, constant, scores, carry_check, correlations,
                     sweep)


def verdict(fit: GroundFit, event: str) -> str:
    """One line: the fitted ground phase against the constant roll on `event`."""
    constant, ground = (next(s for s in fit.scores if s.event == event and s.method.startswith(start))
                        for start in ("carry + constant", "ground phase, fitted"))
    difference = ground.mae_m - constant.mae_m
    word = "better" if difference < 0 else "worse"
    return (f"- {event}: the ground phase's MAE {ground.mae_m:.2f} m against the constant roll's "
            f"{constant.mae_m:.2f} m ({word} by {abs(difference):.2f} m); recorded median roll "
            f"{constant.recorded_roll_m:.1f} m.")


def markdown(fit: GroundFit, model_dir: str) -> str:
    """The generated section of docs/ground.md."""
    yd = YARD_M
    lines = [f"Model: `{model_dir}`, ONNX SHA-256 `{fit.model_sha256}`.", "",
             "Fitted fairway (`flight.ground.SURFACES['fairway']`; friction held at "
             f"{fit.fairway['friction']:g}):", ""]
    lines += table(["parameter", "value"], [(name, f"{fit.fairway[name]:.4g}") for name in FITTED])
    lines += ["", f"Fit error (mean absolute, THE PLAYERS 2020): {fit.fit_mae_m:.2f} m. Constant roll chosen on the "
              f"same shots (their median): {fit.constant_roll_m:.2f} m.", "",
              "Tee-to-rest distance, predicted minus ShotLink, fairway rests only (bias = median error):", ""]
    rows = [(s.event, s.method, s.shots, f"{s.bias_m:+.1f}", f"{s.mae_m:.2f}", f"{s.mae_m / yd:.2f}",
             f"{s.rmse_m:.2f}", f"{s.median_roll_m:.1f}", f"{s.recorded_roll_m:.1f}") for s in fit.scores]
    lines += table(["event", "method", "shots", "bias m", "MAE m", "MAE yd", "RMSE m", "median roll m",
                    "recorded roll m"], rows, "llrrrrrrr")
    lines += [""] + [verdict(fit, event) for event in dict.fromkeys(score.event for score in fit.scores)]
    check = fit.carry_check
    lines += ["", f"The flight part alone: the model's carry minus apexRange (THE PLAYERS 2020 records the carry "
              f"there, docs/real_data.md), {check['shots']} shots: median {check['median_m']:+.2f} m, IQR "
              f"{check['iqr_m']:.1f} m.", "",
              "Correlation of the recorded roll (ShotLink distance minus the model's carry) with the modelled landing:",
              ""]
    names = list(next(iter(fit.roll_correlations.values())))
    lines += table(["event", *names], [(event, *(f"{r[n]:+.3f}" for n in names))
                                        for event, r in fit.roll_correlations.items()])
    lines += ["", "Rolling resistance held, the other parameters refitted (THE PLAYERS 2020):", ""]
    lines += table(["rolling resistance (g)", "grass drag 1/s", "fit MAE m"],
                   [(f"{c:g}", f"{k:.3f}", f"{e:.3f}") for c, k, e in fit.sweep])
    return "\n".join(lines) + "\n"
