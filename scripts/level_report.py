"""Does the level of a real-data model follow the range sessions? For a bundle trained by `golfflight train-real`
(its `training_conditions.json` beside the card): the fitted air factor of each range-session block and of the range
source as a whole, the fitted scales of each range-ball type, and the carry the bundle gives the range sessions' median
Premium drive in ICAO standard air, in the range source's fitted air, and the carry the sessions recorded (training
lines only). Held-out lines are never read. docs/training_real.md quotes the output.

    python3 scripts/level_report.py [models/real] [--data DIR]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.contract.problems import launch_problem
from golfflight.evaluation.accuracy_flyers import model_flyer
from golfflight.flight.air import Air
from golfflight.flight.constants import YARD_M
from golfflight.model_export.real_data import trackman_outdoor
from golfflight.model_export.real_training import CONDITIONS_FILE
from golfflight.shots.markdown import table
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import ShotSet

RANGE_SOURCE = "trackman-outdoor"


def range_air(conditions: dict) -> tuple[list[float], float]:
    """The density factors of the range blocks and their mean in log (the source's fitted air)."""
    factors = [a["density_ratio"] for a in conditions["air"] if a["group"].startswith("tm-")]
    return factors, float(np.exp(np.mean(np.log(factors))))


def median_premium_drive(root: Path) -> tuple[dict[str, np.ndarray], float, int]:
    """The median launch of the range sessions' Premium drives (training lines, straight) and their median carry."""
    records = [r for r in trackman_outdoor(root).records if r.ball == "Premium" and r.carry_y_m is not None]
    shots = ShotSet(records)
    launch = {k: np.array([float(np.median(v))]) for k, v in shots.launch().items()}
    launch["launch_direction_deg"] = launch["spin_axis_deg"] = np.zeros(1)
    return launch, float(np.median(shots.column("carry_y_m"))), len(records)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("bundle", nargs="?", type=Path, default=Path("models/real"))
    parser.add_argument("--data", type=Path, default=shared_data_dir())
    args = parser.parse_args()
    conditions = json.loads((args.bundle / CONDITIONS_FILE).read_text())
    factors, mean = range_air(conditions)
    print(f"Range blocks' fitted air density factors ({len(factors)} blocks): median {np.median(factors):.3f}, "
          f"10-90 % {np.percentile(factors, 10):.3f}-{np.percentile(factors, 90):.3f}; the source's mean "
          f"(geometric) {mean:.3f}\n")
    print("\n".join(table(["ball", "shots", "lift scale", "drag scale"],
                          [[b["ball"], str(b["n_shots"]), f"{b['lift_scale']:.3f}", f"{b['drag_scale']:.3f}"]
                           for b in conditions["ball"]])))
    launch, recorded, n = median_premium_drive(args.data)
    flyer, standard = model_flyer(args.bundle), Air.standard()
    fitted = Air(standard.density_kg_m3 * mean, standard.kinematic_viscosity_m2_s / mean)
    rows = [[name, f"{float(flyer.flight(launch_problem(launch, air)).carry_m[0]) / YARD_M:.1f}"]
            for name, air in (("ICAO standard air", standard), (f"the range source's fitted air (x {mean:.3f})", fitted))]
    rows.append([f"recorded: the median carry of the {n} Premium drives", f"{recorded / YARD_M:.1f}"])
    speed, angle, spin = (float(launch[k][0]) for k in ("ball_speed_mps", "launch_angle_deg", "spin_rpm"))
    print(f"\nThe median Premium range drive ({speed:.1f} m/s, {angle:.1f} deg, {spin:.0f} rpm), straight:\n")
    print("\n".join(table(["flown in", "carry (yd)"], rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
