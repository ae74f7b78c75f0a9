"""How much the models curve a drive per degree of spin axis, against TrackMan's outdoor drivers of the training lines
(never the held-out ones): the side error regressed on the recorded spin axis and launch direction, next to each
model's own side change per degree of axis, and what scaling a bundle's lift and drag would do. docs/training_real.md
("What limits it") quotes the tables.

    python3 scripts/side_curvature.py [--data DIR] [--model models/default] [--synthetic models/synthetic]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.contract.problems import launch_problem
from golfflight.evaluation.accuracy_flyers import ferguson_flyer, model_flyer
from golfflight.evaluation.accuracy_sets import outcome_errors
from golfflight.flight.flyer import Flyer
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.model_export.real_data import trackman_outdoor
from golfflight.shots.markdown import table
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import ShotSet

AXIS_STEP_DEG = 1.0
"""The axis step of each model's own side sensitivity (a central difference)."""


def axis_slope(errors: np.ndarray, launch: dict[str, np.ndarray],
               groups: np.ndarray | None = None) -> tuple[float, float]:
    """OLS slope (m per degree) and its standard error of the side error on the spin axis, with the launch
    direction beside it and a constant, or one constant per group (a range block's own crosswind) if given."""
    if groups is None:
        constants = np.ones((len(errors), 1))
    else:
        constants = (groups[:, None] == np.unique(groups)[None, :]).astype(float)
    design = np.column_stack([launch["spin_axis_deg"], launch["launch_direction_deg"], constants])
    coef, *_ = np.linalg.lstsq(design, errors, rcond=None)
    residual = errors - design @ coef
    sigma2 = residual @ residual / (len(errors) - design.shape[1])
    covariance = sigma2 * np.linalg.inv(design.T @ design)
    return float(coef[0]), float(np.sqrt(covariance[0, 0]))


def side_per_degree(flyer: Flyer, launch: dict[str, np.ndarray]) -> float:
    """The model's own mean change of the landing side (m) per degree of spin axis."""
    sides = []
    for step in (-AXIS_STEP_DEG, AXIS_STEP_DEG):
        tilted = dict(launch, spin_axis_deg=launch["spin_axis_deg"] + step)
        sides.append(flyer.flight(launch_problem(tilted)).lateral_m)
    return float(np.mean((sides[1] - sides[0]) / (2 * AXIS_STEP_DEG)))


def model_rows(flyers: list[Flyer], shots: ShotSet, groups: np.ndarray) -> list[list[str]]:
    """Per model: side MAE and bias, the side error's slope on the axis (over all shots, and within groups), the
    model's own slope, their ratio."""
    rows = []
    for flyer in flyers:
        errors = outcome_errors(flyer.flight(launch_problem(shots.launch())), shots)["side_m"]
        slope, se = axis_slope(errors, shots.launch())
        within, within_se = axis_slope(errors, shots.launch(), groups)
        own = side_per_degree(flyer, shots.launch())
        rows.append([flyer.label, f"{np.mean(np.abs(errors)):.2f}", f"{np.mean(errors):+.2f}",
                     f"{slope:+.3f} ± {se:.3f}", f"{within:+.3f} ± {within_se:.3f}", f"{own:.2f}",
                     f"{-slope / own:.0%}"])
    return rows


def scale_rows(flyer: Flyer, shots: ShotSet, lift_scales: tuple[float, ...],
               drag_scales: tuple[float, ...]) -> list[list[str]]:
    """The bundle with its C_L and C_D scaled: side, carry, apex and landing-angle errors."""
    rows = []
    launch = shots.launch()
    for lift in lift_scales:
        for drag in drag_scales:
            scale = np.tile([lift, drag, 1.0], (len(shots), 1))
            flight = flyer.flyer.flight(FlightProblem(initial_state(**launch), coefficient_scale=scale))
            errors = outcome_errors(flight, shots)
            slope, _ = axis_slope(errors["side_m"], launch)
            rows.append([f"{lift:.2f}", f"{drag:.2f}", f"{np.mean(errors['landing_m']):.2f}",
                         f"{np.mean(np.abs(errors['side_m'])):.2f}", f"{slope:+.3f}",
                         f"{np.mean(errors['carry_m']):+.2f}", f"{np.mean(errors['apex_m']):+.2f}",
                         f"{np.nanmean(errors['landing_angle_deg']):+.2f}"])
    return rows


def axis_scale_rows(flyers: list[Flyer], sets: dict[str, ShotSet], scales: tuple[float, ...]) -> list[list[str]]:
    """Landing error and side MAE with the recorded spin axis multiplied by each scale (a launch-monitor reading
    error, if that is what the missing curvature is)."""
    rows = []
    for name, shots in sets.items():
        for flyer in flyers:
            cells = []
            for scale in scales:
                launch = dict(shots.launch(), spin_axis_deg=shots.launch()["spin_axis_deg"] * scale)
                errors = outcome_errors(flyer.flight(launch_problem(launch)), shots)
                cells.append(f"{np.mean(errors['landing_m']):.2f} / {np.mean(np.abs(errors['side_m'])):.2f}")
            rows.append([name, flyer.label, *cells])
    return rows


PROFILE_SCALES_M = {"carry_m": 3.0, "side_m": 3.0, "apex_m": 1.5}
"""How the profile fit weighs each outcome's error (m): the landing point's two axes and the apex."""


AS_RECORDED = np.array([1.0, 0.0, 1.0, 0.0])
"""The profile that changes nothing: (axis scale, launch-angle bias deg, spin scale, launch-direction bias deg)."""
PROFILE_BOUNDS = (np.array([0.5, -5.0, 0.5, -5.0]), np.array([2.0, 5.0, 2.0, 5.0]))


def monitor_profile(launch: dict[str, np.ndarray], profile: np.ndarray) -> dict[str, np.ndarray]:
    """Launches as a monitor profile reads them: spin axis x profile[0], launch angle + profile[1] deg, spin x
    profile[2], launch direction + profile[3] deg."""
    return dict(launch, spin_axis_deg=launch["spin_axis_deg"] * profile[0],
                launch_angle_deg=launch["launch_angle_deg"] + profile[1], spin_rpm=launch["spin_rpm"] * profile[2],
                launch_direction_deg=launch["launch_direction_deg"] + profile[3])


def fit_monitor_profile(flyer: Flyer, shots: ShotSet, free: list[int]) -> np.ndarray:
    """The profile whose `free` entries (the others as recorded) bring the flyer's carry, side and apex closest to
    the recordings (bounded least squares)."""

    def profile_of(values: np.ndarray) -> np.ndarray:
        profile = AS_RECORDED.copy()
        profile[free] = values
        return profile

    def residuals(values: np.ndarray) -> np.ndarray:
        profiled = monitor_profile(shots.launch(), profile_of(values))
        errors = outcome_errors(flyer.flight(launch_problem(profiled)), shots)
        return np.concatenate([errors[k] / scale for k, scale in PROFILE_SCALES_M.items()])

    fit = least_squares(residuals, AS_RECORDED[free], diff_step=1e-2,
                        bounds=(PROFILE_BOUNDS[0][free], PROFILE_BOUNDS[1][free]))
    return profile_of(fit.x)


PROFILES = ([0, 1, 2], [0, 1, 2, 3])
"""The profiles fitted: which entries of (axis scale, launch-angle bias, spin scale, direction bias) are free (the
first three, then all four)."""


def profile_rows(flyers: list[Flyer], fit_on: ShotSet, check_on: ShotSet) -> list[list[str]]:
    """Per flyer and profile: the profile fitted on `fit_on`, and the landing error / side MAE without and with it
    on both sets."""
    rows = []
    for flyer in flyers:
        for free in PROFILES:
            rows.append(_profile_row(flyer, fit_monitor_profile(flyer, fit_on, free), fit_on, check_on))
    return rows


def _profile_row(flyer: Flyer, profile: np.ndarray, fit_on: ShotSet, check_on: ShotSet) -> list[str]:
    """One flyer and profile: the profile, and the landing error / side MAE without and with it on both sets."""
    cells = []
    for shots in (fit_on, check_on):
        for p in (AS_RECORDED, profile):
            errors = outcome_errors(flyer.flight(launch_problem(monitor_profile(shots.launch(), p))), shots)
            cells.append(f"{np.mean(errors['landing_m']):.2f} / {np.mean(np.abs(errors['side_m'])):.2f}")
    named = f"axis x {profile[0]:.2f}, launch {profile[1]:+.2f}°, spin x {profile[2]:.2f}, direction {profile[3]:+.2f}°"
    return [flyer.label, named, *cells]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=shared_data_dir(), help="the shared data folder")
    parser.add_argument("--model", default="models/default", help="the bundle to scale")
    parser.add_argument("--synthetic", default="models/synthetic", help="a second bundle to compare")
    args = parser.parse_args()
    records = trackman_outdoor(args.data).records
    premium = ShotSet([r for r in records if r.ball == "Premium"])
    range_balls = ShotSet([r for r in records if r.ball != "Premium"])
    model = model_flyer(args.model)
    flyers = [model, model_flyer(args.synthetic), ferguson_flyer(model.dt_s, model.max_flight_time_s)]
    print(f"TrackMan outdoor drivers, training lines, Premium balls: {len(premium)} shots (train and validation "
          "splits; every model calm, in its own air)\n")
    blocks = np.array([r.group for r in records if r.ball == "Premium"])
    print("\n".join(table(["model", "side MAE, m", "side bias, m", "side error per deg of axis, m",
                           "same, within range blocks, m", "model's side per deg of axis, m", "missing curvature"],
                          model_rows(flyers, premium, blocks))))
    print(f"\n{model.label} with C_L and C_D scaled:\n")
    print("\n".join(table(["C_L x", "C_D x", "landing error, m", "side MAE, m", "side error per deg, m",
                           "carry bias, m", "apex bias, m", "land angle bias, deg"],
                          scale_rows(model, premium, (1.0, 1.05, 1.10, 1.15), (1.0, 1.06)))))
    scales = (1.0, 1.1, 1.2, 1.3)
    print("\nThe recorded spin axis multiplied by a scale: landing error / side MAE, m\n")
    print("\n".join(table(["balls", "model", *(f"axis x {k:.1f}" for k in scales)],
                          axis_scale_rows([model, flyers[2]], {"Premium": premium, "other": range_balls}, scales))))
    train = ShotSet([r for r in records if r.ball == "Premium" and r.split == "train"])
    validation = ShotSet([r for r in records if r.ball == "Premium" and r.split == "val"])
    print(f"\nA monitor profile (spin axis scale, launch angle bias, spin scale; then with a launch direction bias "
          f"beside them) fitted on the training split's "
          f"{len(train)} Premium drives, checked on the validation split's {len(validation)} (other range blocks): "
          "landing error / side MAE, m\n")
    print("\n".join(table(["model", "profile", "train, as recorded", "train, profile", "validation, as recorded",
                           "validation, profile"], profile_rows([model, flyers[2]], train, validation))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
