"""How much of a calm model's landing error on TrackMan's outdoor drivers is the range block's weather: each shot is
flown calm, and with a uniform wind fitted to the OTHER Premium shots of its range block (leave one out, so the
wind is what a user could have known from the session, not fitted to the shot itself). Training lines only (the
split's validation blocks are the out-of-sample row), and how much the calm error differs from block to block;
docs/training_real.md ("What limits it") quotes the tables.

    python3 scripts/weather_floor.py [--data DIR] [--model models/default] [--synthetic models/synthetic]
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
from golfflight.flight.flyer import Flyer
from golfflight.flight.wind import Wind
from golfflight.model_export.real_data import trackman_outdoor
from golfflight.shots.markdown import table
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import ShotSet

MIN_OTHERS = 3
"""A shot counts only where its block has at least this many other Premium shots to fit the wind on."""
ROBUST_SCALE_M = 3.0
"""The wind fit is robust (soft L1 beyond 3 m of landing error): a mishit or a gust does not set the block's wind."""
WIND_STEP_MPS = 0.05
"""The finite-difference step of the wind fit (m/s): the ONNX graph computes in float32."""


def landing_errors(flyer: Flyer, shots: ShotSet, wind_xy: np.ndarray) -> np.ndarray:
    """Per-shot (x, y) landing-point error (model - recorded, m) with one uniform wind (x, y m/s) for all."""
    n = len(shots)
    wind = Wind.from_components(np.full(n, wind_xy[0]), np.full(n, wind_xy[1]))
    flight = flyer.flight(launch_problem(shots.launch(), wind=wind))
    return flight.landing_position[:, :2] - np.column_stack([shots.column("carry_x_m"), shots.column("carry_y_m")])


def fitted_wind(flyer: Flyer, shots: ShotSet) -> np.ndarray:
    """The uniform wind (x, y m/s) that lands these shots closest to their recorded landing points."""
    def residuals(wind_xy: np.ndarray) -> np.ndarray:
        return landing_errors(flyer, shots, wind_xy).ravel()

    return least_squares(residuals, np.zeros(2), loss="soft_l1", f_scale=ROBUST_SCALE_M,
                         diff_step=WIND_STEP_MPS).x


def calm_errors(flyer: Flyer, shots: ShotSet) -> np.ndarray:
    """Per-shot landing error (m) flown calm."""
    return np.linalg.norm(landing_errors(flyer, shots, np.zeros(2)), axis=1)


def leave_one_out(flyer: Flyer, shots: ShotSet, blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per shot with enough block neighbours: its landing error with the wind of the other shots of its block, and
    that wind; NaN for a shot whose block is too small."""
    windy = np.full(len(shots), np.nan)
    winds = np.full((len(shots), 2), np.nan)
    for block in np.unique(blocks):
        members = np.flatnonzero(blocks == block)
        if len(members) <= MIN_OTHERS:
            continue
        for i in members:
            others = ShotSet([shots.records[j] for j in members if j != i])
            wind = fitted_wind(flyer, others)
            windy[i] = np.linalg.norm(landing_errors(flyer, ShotSet([shots.records[i]]), wind)[0])
            winds[i] = wind
    return windy, winds


def block_spread_rows(flyers: list[Flyer], shots: ShotSet) -> list[list[str]]:
    """Per model: the calm landing error of each range block (mean over its Premium shots, blocks of at least
    MIN_OTHERS + 1 shots), summarised as median and 10th-90th percentile: how much a held-out set of a few blocks
    can differ from another by its sessions alone."""
    blocks = np.array([r.group for r in shots.records])
    names, counts = np.unique(blocks, return_counts=True)
    big = names[counts > MIN_OTHERS]
    out = []
    for flyer in flyers:
        errors = calm_errors(flyer, shots)
        means = np.array([np.mean(errors[blocks == b]) for b in big])
        low, median, high = np.percentile(means, [10, 50, 90])
        out.append([flyer.label, str(len(big)), f"{median:.2f}", f"{low:.2f} - {high:.2f}",
                    f"{means.min():.2f} - {means.max():.2f}"])
    return out


def rows(flyers: list[Flyer], splits: dict[str, ShotSet]) -> list[list[str]]:
    """Per split and model: shots counted, landing error calm and with the block's leave-one-out wind, the share of
    the calm error that wind takes away, and the median fitted wind speed."""
    out = []
    for name, shots in splits.items():
        blocks = np.array([r.group for r in shots.records])
        for flyer in flyers:
            calm = calm_errors(flyer, shots)
            windy, winds = leave_one_out(flyer, shots, blocks)
            kept = np.isfinite(windy)
            calm_m, windy_m = float(np.mean(calm[kept])), float(np.mean(windy[kept]))
            out.append([name, flyer.label, str(int(kept.sum())), f"{calm_m:.2f}", f"{windy_m:.2f}",
                        f"{1 - windy_m / calm_m:.0%}", f"{np.median(np.hypot(*winds[kept].T)):.1f}"])
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=shared_data_dir(), help="the shared data folder")
    parser.add_argument("--model", default="models/default", help="the bundle to measure")
    parser.add_argument("--synthetic", default="models/synthetic", help="a second bundle to compare")
    args = parser.parse_args()
    records = [r for r in trackman_outdoor(args.data).records if r.ball == "Premium"]
    splits = {split: ShotSet([r for r in records if r.split == split]) for split in ("train", "val")}
    model = model_flyer(args.model)
    flyers = [model, model_flyer(args.synthetic), ferguson_flyer(model.dt_s, model.max_flight_time_s)]
    print(f"TrackMan outdoor drivers, training lines, Premium balls, by range block; a shot counts where its block "
          f"has at least {MIN_OTHERS} other Premium shots\n")
    columns = ["split", "model", "shots", "landing error calm, m", "with the block's wind (leave one out), m",
               "taken away", "median fitted wind, m/s"]
    print("\n".join(table(columns, rows(flyers, splits))))
    print("\nThe calm landing error of each range block (both splits), m\n")
    print("\n".join(table(["model", "blocks", "median", "10th - 90th percentile", "range"],
                          block_spread_rows(flyers, ShotSet(records)))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
