"""Are the pbp apex fields TrackMan's apex? Per event, the recorded apexHeight against the apex physics predicts
for the same launch (ball speed, launch angle, spin; calm, rho = 1.225 kg/m^3) with Ferguson et al. 2022's
coefficients and with the reference world; apexRange against the predicted apex range and carry; how strongly the
recorded and predicted apex grow with spin; apexRange against ShotLink's tee-to-rest distance (a carry stops
short of the rest point by the roll); and, for the 2022 Sentry, pbp apexHeight against the apex of the event's
TOURCAST polynomials. Prints markdown tables (docs/real_data.md quotes them); writes nothing.

    python3 scripts/check_pbp_apex.py [--data DIR]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.flight.air import Air  # noqa: E402
from golfflight.flight.coefficients import FERGUSON_2022, QuadraticSpinRatio  # noqa: E402
from golfflight.flight.constants import FOOT_M  # noqa: E402
from golfflight.flight.flyer import FixedCoefficients, Flyer  # noqa: E402
from golfflight.flight.integrator import RUNGE_KUTTA_4  # noqa: E402
from golfflight.flight.outcomes import Flight  # noqa: E402
from golfflight.flight.physics import initial_state  # noqa: E402
from golfflight.flight.problem import FlightProblem  # noqa: E402
from golfflight.flight.reference_aero import REFERENCE_DT_S, REFERENCE_T_MAX_S  # noqa: E402
from golfflight.shots.markdown import table  # noqa: E402
from golfflight.shots.paths import shared_data_dir  # noqa: E402
from golfflight.shots.pbp import load_pbp, recorded_apex, rest_positions  # noqa: E402
from golfflight.shots.records import ShotSet  # noqa: E402
from golfflight.shots.reference_world import fly_reference  # noqa: E402
from golfflight.shots.tourcast import load_tourcast  # noqa: E402

TOURCAST = Path("real/pga_tourcast_trackman")
EVENTS = {
    "THE PLAYERS 2020": TOURCAST / "pbp/pbp_2020_011_011.csv",
    "TOUR Championship 2020": TOURCAST / "pbp/pbp_2020_060_688.csv",
    "Sentry 2022": TOURCAST / "pbp/pbp_2021_016_656.csv",
}
SENTRY_TRAJECTORIES = TOURCAST / "shot_trajectory/shot_trajectory_2021_016_656.csv"
DENSITY_KG_M3 = 1.225
CHUNK = 500
"""Shots flown at once (every state is kept to find the range at the apex)."""


@dataclass
class ApexPrediction:
    """Per shot: apex height, horizontal distance at the apex and carry (m)."""

    apex_m: np.ndarray
    apex_range_m: np.ndarray
    carry_m: np.ndarray


def ferguson(state) -> Flight:
    """Ferguson 2022's quadratic C_L, C_D, C_M in the spin ratio, RK4 at the reference world's step."""
    standard = Air.standard()
    flyer = Flyer(FixedCoefficients(QuadraticSpinRatio(FERGUSON_2022)), REFERENCE_DT_S, REFERENCE_T_MAX_S,
                  DENSITY_KG_M3, standard.kinematic_viscosity_m2_s, RUNGE_KUTTA_4)
    return flyer.flight(FlightProblem(state, keep_states=True))


def reference(state) -> Flight:
    """The reference world in ICAO standard air (rho = 1.225 kg/m^3)."""
    return fly_reference(state, Air.standard(), keep_states=True)


FLYERS = {"Ferguson 2022": ferguson, "reference world": reference}


def predict(fly, launch: dict[str, np.ndarray]) -> ApexPrediction:
    """Fly the launches calm in chunks; the apex range is the horizontal distance at the step of the apex."""
    parts = []
    for start in range(0, len(launch["spin_rpm"]), CHUNK):
        flight = fly(initial_state(**{k: v[start:start + CHUNK] for k, v in launch.items()}))
        step = np.rint(flight.apex_time_s / (flight.times_s[1] - flight.times_s[0])).astype(int)
        at_apex = np.stack([s.position for s in flight.states])[step, np.arange(len(step))]
        parts.append((flight.apex_m, np.hypot(at_apex[:, 0], at_apex[:, 1]), flight.carry_m))
    return ApexPrediction(*(np.concatenate(column) for column in zip(*parts)))


def ratio_stats(recorded: np.ndarray, predicted: np.ndarray) -> tuple[str, str, str]:
    """Median and interquartile range of recorded / predicted, and their correlation."""
    q1, median, q3 = np.percentile(recorded / predicted, [25, 50, 75])
    return f"{median:.3f}", f"{q3 - q1:.3f}", f"{np.corrcoef(recorded, predicted)[0, 1]:.3f}"


def spin_exponent(launch: dict[str, np.ndarray], apex_m: np.ndarray) -> tuple[float, float]:
    """Least squares of log apex on log ball speed, log sin(launch angle), log spin: the spin exponent and the
    residual standard deviation (a measured apex scatters with the weather; a computed one barely)."""
    features = np.column_stack([np.ones_like(apex_m), np.log(launch["ball_speed_mps"]),
                                np.log(np.sin(np.radians(launch["launch_angle_deg"]))), np.log(launch["spin_rpm"])])
    fit = np.linalg.lstsq(features, np.log(apex_m), rcond=None)[0]
    return float(fit[3]), float(np.std(np.log(apex_m) - features @ fit))


def event_data(path: Path) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Launches (spin > 0) and the recorded apex height and range (m) of the same shots."""
    records = load_pbp(path, apex=False).records
    fields = recorded_apex(path)
    height = np.array([fields[r.shot_id].height_m for r in records])
    span = np.array([fields[r.shot_id].range_m for r in records])
    return ShotSet(records).launch(), height, span


def against_rest(root: Path) -> list[str]:
    """Per event, apexRange against ShotLink's horizontal tee-to-rest distance of the same shots: a carry is a
    little shorter than the rest distance (by the roll), a range at the apex about two thirds of it."""
    rows = []
    for event, path in EVENTS.items():
        fields, rest = recorded_apex(root / path), rest_positions(root / path)
        pairs = np.array([(fields[k].range_m, rest[k].distance_m) for k in fields
                          if fields[k].range_m and rest.get(k) and rest[k].distance_m])
        span, distance = pairs[:, 0], pairs[:, 1]
        q1, median, q3 = np.percentile(distance - span, [25, 50, 75]) / 0.9144
        rows.append([event, len(pairs), f"{np.median(span / distance):.3f}", f"{np.mean(span <= distance):.0%}",
                     f"{median:.1f} ({q1:.1f} to {q3:.1f})"])
    return table(["event", "shots", "median apexRange / rest distance", "apexRange <= rest distance",
                  "rest distance - apexRange, yd: median (IQR)"], rows)


def sentry_polynomials(root: Path) -> list[str]:
    """pbp apexHeight against the apex of the same shots' TOURCAST polynomials (shots with a measured spin)."""
    fields = recorded_apex(root / EVENTS["Sentry 2022"])
    pairs = np.array([(fields[r.shot_id].height_m, r.apex_m) for r in
                      load_tourcast(root / SENTRY_TRAJECTORIES, root / EVENTS["Sentry 2022"]).records
                      if r.apex_m is not None and fields.get(r.shot_id) and fields[r.shot_id].height_m])
    recorded, polynomial = pairs[:, 0], pairs[:, 1]
    diff_ft = np.abs(recorded - polynomial) / FOOT_M
    return table(["Sentry 2022", "shots", "median pbp ft", "median polynomial ft", "median ratio", "IQR",
                  "correlation", "median abs diff ft"],
                 [["pbp apexHeight vs polynomial apex", len(pairs), f"{np.median(recorded) / FOOT_M:.0f}",
                   f"{np.median(polynomial) / FOOT_M:.0f}", *ratio_stats(recorded, polynomial),
                   f"{np.median(diff_ft):.2f}"]])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=shared_data_dir(), help="the shared data folder")
    root = parser.parse_args().data
    heights, ranges, exponents = [], [], []
    for event, path in EVENTS.items():
        launch, height, span = event_data(root / path)
        recorded_ft = f"{np.median(height) / FOOT_M:.0f}"
        exponents.append([event, "recorded", *(f"{v:.3f}" for v in spin_exponent(launch, height))])
        for flyer, fly in FLYERS.items():
            predicted = predict(fly, launch)
            heights.append([event, flyer, len(height), recorded_ft, f"{np.median(predicted.apex_m) / FOOT_M:.0f}",
                            *ratio_stats(height, predicted.apex_m)])
            ranges.append([event, flyer, f"{np.median(span) / FOOT_M:.0f}",
                           *ratio_stats(span, predicted.apex_range_m), *ratio_stats(span, predicted.carry_m)])
            exponents.append([event, flyer, *(f"{v:.3f}" for v in spin_exponent(launch, predicted.apex_m))])
    sections = [
        ["apexHeight against the predicted apex (ratio = recorded / predicted)"],
        table(["event", "physics", "shots", "median recorded ft", "median predicted ft", "median ratio",
               "IQR of ratio", "correlation"], heights),
        ["apexRange against the predicted range at the apex and the predicted carry"],
        table(["event", "physics", "median apexRange ft", "/ apex range: median", "IQR", "correlation",
               "/ carry: median", "IQR", "correlation"], ranges),
        ["How the apex grows with spin: log apex fitted on log ball speed, log sin(launch angle), log spin"],
        table(["event", "apex", "spin exponent", "residual sd of log apex"], exponents),
        ["apexRange against ShotLink's horizontal tee-to-rest distance"],
        against_rest(root),
        ["The 2022 Sentry's pbp apexHeight against its TOURCAST trajectory polynomials"],
        sentry_polynomials(root),
    ]
    print("\n\n".join("\n".join(lines) for lines in sections))
    return 0


if __name__ == "__main__":
    sys.exit(main())
