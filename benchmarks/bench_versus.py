"""This checkout against an earlier one, interleaved in one sitting (the machines drift within a session): the single
shot in process (`FlightEngine.fly`, the tour 7-iron and driver rolled to rest on the fairway, median of 300 shots)
and whole `golfflight sweep` runs of one grid, `--engine local --workers 1` and `--engine torch --device cpu
--threads 1` (rows/s, process start to file written). Each measurement runs in a fresh process started in its
checkout, the order alternating round by round (ABBA). Prints a table with each round's figures and the median
ratio after / before; writes the `versus` section of results.json. HTTP single shots and batches have their own A/B
(`bench_wire.py --versus`).

python benchmarks/bench_versus.py --before ../wt-before [--rounds 3] [--grid-rows 50000]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import REPO, write_results

SINGLE_SHOT = """
import json, statistics, time
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.ground import GroundSpec
engine = FlightEngine(model_dir())
fairway = GroundSpec()
out = {}
for name, launch in (("7-iron", Launch(55.0, 16.0, 0.0, 7100.0, 0.0)), ("driver", Launch(76.5, 10.5, 0.0, 2550.0, 0.0))):
    for _ in range(100):
        engine.fly(launch, ground=fairway)
    times = []
    for _ in range(300):
        started = time.perf_counter()
        engine.fly(launch, ground=fairway)
        times.append(time.perf_counter() - started)
    out[name] = statistics.median(times) * 1e3
print(json.dumps(out))
"""


def single_shot(tree: Path) -> dict[str, float]:
    """Median ms of one shot (7-iron, driver) in a fresh process of `tree`."""
    done = subprocess.run([sys.executable, "-c", SINGLE_SHOT], cwd=tree, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.splitlines()[-1])


def grid_axes(rows: int) -> list[str]:
    """A grid of about `rows` launches: speeds x angles x 10 spins."""
    speeds = max(rows // 500, 1)
    return ["--grid", f"ball_speed_mps=30:80:{speeds}", "launch_angle_deg=6:24:50", "spin_rpm=2000:8000:10"]


SWEEPS = {
    "sweep local": ["--engine", "local", "--workers", "1"],
    "sweep torch cpu": ["--engine", "torch", "--device", "cpu", "--threads", "1"],
}


def sweep_rate(tree: Path, engine: list[str], rows: int, folder: Path) -> float:
    """Rows per second of one `golfflight sweep` of the grid from `tree`, process start to file written."""
    out = folder / "out.parquet"
    command = [sys.executable, "-m", "golfflight", "sweep", *grid_axes(rows), *engine, "--out", str(out)]
    started = time.perf_counter()
    subprocess.run(command, cwd=tree, capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - started
    out.unlink()
    return (rows // 500 * 500) / seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", required=True, help="a checkout of the earlier commit (e.g. a git worktree)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--grid-rows", type=int, default=50_000)
    args = parser.parse_args()
    trees = {"before": Path(args.before).resolve(), "after": REPO}
    figures: dict[str, dict[str, list[float]]] = {side: {} for side in trees}
    with tempfile.TemporaryDirectory(prefix="bench_versus_") as folder:
        for round_number in range(args.rounds):
            order = ["before", "after"] if round_number % 2 == 0 else ["after", "before"]
            for side in order:
                tree, mine = trees[side], figures[side]
                for name, ms in single_shot(tree).items():
                    mine.setdefault(f"single shot, {name} (ms)", []).append(ms)
                for name, engine in SWEEPS.items():
                    rate = sweep_rate(tree, engine, args.grid_rows, Path(folder))
                    mine.setdefault(f"{name} (rows/s)", []).append(rate)
                print(f"round {round_number} {side}: " + ", ".join(f"{k} {v[-1]:,.3g}" for k, v in mine.items()),
                      flush=True)
    rows = []
    print(f"\n{args.rounds} rounds, ABBA; before {trees['before']}\n")
    print("| measurement | before (rounds) | after (rounds) | median after / before |")
    print("|---|---|---|---:|")
    for name in figures["after"]:
        before, after = figures["before"][name], figures["after"][name]
        ratio = statistics.median(after) / statistics.median(before)
        rows.append({"name": name, "before": before, "after": after, "ratio": ratio})
        shown = [", ".join(f"{v:,.3g}" for v in side) for side in (before, after)]
        print(f"| {name} | {shown[0]} | {shown[1]} | {ratio:.3f} |")
    write_results("versus", rows)


if __name__ == "__main__":
    main()
