"""This checkout against an earlier one, interleaved in one sitting (the machines drift by tens of per cent from minute
to minute): the single shot in process (`FlightEngine.fly`, the tour 7-iron and driver rolled to rest on the
fairway), the engine's batch of 1,024 and of 16 mixed launches to rest as one ShotFlight a shot (what the HTTP batch
reads), the ground phase alone (one driver landing on floats, 1,024 landings on NumPy, level and on a slope), the
torch engine's batch in process on the CPU (8,192 mixed launches, one thread), training's rollout (256 mixed
launches through a phys-nn+ network (32, 32) in float32, one thread: the soft landing's whole horizon forward and
backward, and validation's, stopped once every shot is down) and whole `golfflight sweep` runs of
one grid, `--engine local --workers 1` and `--engine torch --device cpu --threads 1` (rows/s, process
start to file written).

The in-process figures come from one worker process per checkout, both alive throughout, timing short blocks in turn
(A B, then B A, ...), so that each block of one checkout has a block of the other beside it in time; the ratio of
each pair is taken and the median of the pairs reported. The sweeps are whole processes, one of each checkout per
round, the order alternating (ABBA), ratios per round. Prints a table; --results FILE gets its `versus` section.
HTTP single shots and batches have their own A/B (`bench_wire.py --versus`).

python benchmarks/bench_versus.py --before ../wt-before [--blocks 40] [--rounds 3] [--grid-rows 50000]
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

from common import REPO, add_results_flag, write_results

WORKER = r"""
import json, sys, time
import numpy as np
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.ground import GroundSpec
from golfflight.contract.flying import fly_request
from golfflight.contract.requests import ShotRequest

try:
    from golfflight.flight.problem import FlightProblem
except ImportError:  # before issue 58's one flight problem: launches, conditions and grounds apart
    FlightProblem = None

engine, fairway = FlightEngine(model_dir()), GroundSpec()
shots = {"7-iron": Launch(55.0, 16.0, 0.0, 7100.0, 0.0), "driver": Launch(76.5, 10.5, 0.0, 2550.0, 0.0)}
torch_fly = launches = None
requests = {
    "plain": ShotRequest(ball_speed_mph=150.0, launch_angle_deg=10.4, back_spin_rpm=2545.0),
    "full": ShotRequest(ball_speed_mph=150.0, launch_angle_deg=10.4, back_spin_rpm=2545.0, normalized=True,
                        trajectory={"rate_hz": 30}, wind={"speed_mps": 4.0, "from_deg": 200.0, "profile": "log"},
                        ground={"surface": "green", "elevation_m": 3.0, "slope_deg": 2.0, "slope_dir_deg": 45.0}),
}


def fly_one(launch):  # one shot to rest on the fairway on the engine's single-shot path
    if FlightProblem is None:
        return engine.fly(launch, ground=fairway)
    return engine.fly(FlightProblem.of([launch], grounds=fairway))[0]


def fly_many(launches, **given):  # the engine's batch path
    return engine.fly_batch(*([FlightProblem.of(launches, **given)] if FlightProblem else [launches]),
                            **({} if FlightProblem else given))


def request(name, count):  # one request through contract.flying.fly_request (ms, median of count)
    times = []
    for _ in range(count):
        started = time.perf_counter()
        fly_request(engine, requests[name])
        times.append(time.perf_counter() - started)
    return sorted(times)[len(times) // 2] * 1e3


def single(name, count):
    times = []
    for _ in range(count):
        started = time.perf_counter()
        fly_one(shots[name])
        times.append(time.perf_counter() - started)
    return sorted(times)[len(times) // 2] * 1e3


def torch_problem(launches):  # what the torch engine takes, before and after issue 58
    return [FlightProblem.of(launches)] if FlightProblem else [launches]


def torch_batch(n):
    global torch_fly, launches
    if torch_fly is None:
        import torch
        try:
            from golfflight.flight.torch_engine import TorchEngine
        except ImportError:  # before issue 44 the torch engine was training's
            from golfflight.model_export.torch_engine import TorchEngine
        torch.set_num_threads(1)
        rng = np.random.default_rng(0)
        launches = np.stack([rng.uniform(30, 80, n), rng.uniform(6, 24, n), rng.normal(0, 2, n),
                             rng.uniform(2000, 8000, n), rng.normal(0, 5, n)], -1)
        backend = TorchEngine(model_dir())
        torch_fly = getattr(backend, "fly_columns", None) or backend.fly_batch  # its name before one batch method
        torch_fly(*torch_problem(launches[:512]))
    started = time.perf_counter()
    torch_fly(*torch_problem(launches))
    return n / (time.perf_counter() - started)


rng = np.random.default_rng(1)
mixed = [Launch(*row) for row in np.stack([rng.uniform(30, 80, 1024), rng.uniform(6, 24, 1024),
                                           rng.normal(0, 2, 1024), rng.uniform(2000, 8000, 1024),
                                           rng.normal(0, 5, 1024)], -1).tolist()]


def objects_batch(n=1024):
    started = time.perf_counter()
    flown = fly_many(mixed[:n], grounds=fairway)
    if hasattr(flown, "shots"):  # one batch method, columns, since issue 44's; a list of ShotFlight before
        flown.shots()
    return (time.perf_counter() - started) * 1e3


from golfflight.flight.ground import ground_phase, ground_phase_one

landing = ((0.0, 200.0, 0.0), (1.0, 30.0, -20.0), (200.0, 0.0, 0.0))  # a driver's, on the ground at 30 m/s
landings = [np.stack([rng.normal(0, 3, 1024), rng.uniform(10, 40, 1024), -rng.uniform(10, 30, 1024)], -1),
            rng.normal(0, 300, (1024, 3))]


def ground_one(slope_deg, count):  # the ground phase alone of one driver landing on floats (us, median of count)
    times = []
    for _ in range(count):
        started = time.perf_counter()
        ground_phase_one(*landing, fairway.surface, slope_deg, 40.0)
        times.append(time.perf_counter() - started)
    return sorted(times)[len(times) // 2] * 1e6


def ground_batch(slope_deg):  # the ground phase alone of 1,024 landings on NumPy (ms)
    started = time.perf_counter()
    ground_phase(np.zeros((1024, 3)), *landings, fairway.surface, slope_deg, 40.0)
    return (time.perf_counter() - started) * 1e3


rollout_inputs = None


def rollout(training):  # training's rollout of 256 mixed launches, float32, one thread (ms)
    global rollout_inputs
    import torch
    from golfflight.flight.rollout import apex, euler_rollout, hard_landing, soft_landing
    if rollout_inputs is None:
        from golfflight.flight.physics import initial_state
        from golfflight.model_export.variants import build_model
        torch.set_num_threads(1)
        torch.manual_seed(0)
        start = initial_state(*(np.array(column) for column in zip(*mixed[:256])))
        rollout_inputs = [torch.tensor(v, dtype=torch.float32) for v in (start.position, start.velocity, start.spin)]
        rollout_inputs.append(build_model("phys-nn+", (32, 32)))
    started = time.perf_counter()
    if training:  # the soft landing's whole horizon, forward and backward
        trajectory = euler_rollout(*rollout_inputs, 1.2, 0.1, 10.0)
        (soft_landing(trajectory).sum() + apex(trajectory).height_m.sum()).backward()
    else:  # validation's: no gradient, stopped once every shot is down
        with torch.no_grad():
            hard_landing(euler_rollout(*rollout_inputs, 1.2, 0.1, 10.0, stop_after_s=0.0))
    return (time.perf_counter() - started) * 1e3


for name in shots:
    single(name, 100)
for name in requests:
    request(name, 100)
objects_batch()
print("ready", flush=True)
for line in sys.stdin:
    kind, *args = line.split()
    runs = {"single": lambda: single(args[0], int(args[1])), "torch": lambda: torch_batch(int(args[0])),
            "objects": lambda: objects_batch(int(args[0])), "request": lambda: request(args[0], int(args[1])),
            "ground-one": lambda: ground_one(float(args[0]), int(args[1])),
            "ground-batch": lambda: ground_batch(float(args[0])), "rollout": lambda: rollout(args[0] == "training")}
    print(json.dumps(runs[kind]()), flush=True)
"""

BLOCKS = {
    "single shot, 7-iron (ms, median of 50)": "single 7-iron 50",
    "single shot, driver (ms, median of 50)": "single driver 50",
    "one request, driver, plain (fly_request, ms, median of 50)": "request plain 50",
    "one request, normalized, sloped green, trajectory, log wind (fly_request, ms, median of 50)": "request full 50",
    "torch engine in process, 8,192 mixed shots (shots/s)": "torch 8192",
    "engine batch of 1,024 mixed shots to rest, one ShotFlight a shot (ms)": "objects 1024",
    "engine batch of 16 mixed shots to rest, one ShotFlight a shot (ms)": "objects 16",
    "ground phase alone, one driver landing on floats, level fairway (us, median of 50)": "ground-one 0 50",
    "ground phase alone, one driver landing on floats, 3 deg slope (us, median of 50)": "ground-one 3 50",
    "ground phase alone, 1,024 landings on NumPy, level fairway (ms)": "ground-batch 0",
    "ground phase alone, 1,024 landings on NumPy, 3 deg slope (ms)": "ground-batch 3",
    "training's rollout, 256 launches, soft landing and backward (ms)": "rollout training",
    "validation's rollout, 256 launches, stopped once down (ms)": "rollout validation",
}


class Worker:
    """A process of one checkout that times blocks on request (WORKER)."""

    def __init__(self, tree: Path) -> None:
        self.process = subprocess.Popen([sys.executable, "-c", WORKER], cwd=tree, stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True)
        assert self.process.stdout.readline().strip() == "ready"

    def time(self, command: str) -> float:
        self.process.stdin.write(command + "\n")
        self.process.stdin.flush()
        return json.loads(self.process.stdout.readline())

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait(timeout=60)


def grid_axes(rows: int) -> list[str]:
    """A grid of about `rows` launches: speeds x 50 angles x 10 spins."""
    return ["--grid", f"ball_speed_mps=30:80:{max(rows // 500, 1)}", "launch_angle_deg=6:24:50",
            "spin_rpm=2000:8000:10"]


SWEEPS = {
    "sweep --engine local --workers 1 (rows/s)": ["--engine", "local", "--workers", "1"],
    "sweep --engine torch --device cpu --threads 1 (rows/s)": ["--engine", "torch", "--device", "cpu", "--threads", "1"],
}


def sweep_rate(tree: Path, engine: list[str], rows: int, folder: Path) -> float:
    """Rows per second of one `golfflight sweep` of the grid from `tree`, process start to file written."""
    out = folder / "out.parquet"
    command = [sys.executable, "-m", "golfflight", "sweep", *grid_axes(rows), *engine, "--out", str(out)]
    started = time.perf_counter()
    subprocess.run(command, cwd=tree, capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - started
    out.unlink()
    return (max(rows // 500, 1) * 500) / seconds


def interleaved(trees: dict[str, Path], blocks: int) -> dict[str, dict[str, list[float]]]:
    """Each in-process measurement, block by block, the two checkouts' workers in turn (A B, B A, ...)."""
    workers = {side: Worker(tree) for side, tree in trees.items()}
    figures: dict[str, dict[str, list[float]]] = {name: {side: [] for side in trees} for name in BLOCKS}
    try:
        for block in range(blocks):
            order = list(trees) if block % 2 == 0 else list(trees)[::-1]
            for name, command in BLOCKS.items():
                for side in order:
                    figures[name][side].append(workers[side].time(command))
    finally:
        for worker in workers.values():
            worker.close()
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", required=True, help="a checkout of the earlier commit (e.g. a git worktree)")
    parser.add_argument("--blocks", type=int, default=40, help="in-process blocks of each checkout")
    parser.add_argument("--rounds", type=int, default=3, help="whole sweeps of each checkout")
    parser.add_argument("--grid-rows", type=int, default=50_000)
    add_results_flag(parser)
    args = parser.parse_args()
    trees = {"before": Path(args.before).resolve(), "after": REPO}
    figures = interleaved(trees, args.blocks)
    with tempfile.TemporaryDirectory(prefix="bench_versus_") as folder:
        for name in SWEEPS:
            figures[name] = {side: [] for side in trees}
        for round_number in range(args.rounds):
            order = list(trees) if round_number % 2 == 0 else list(trees)[::-1]
            for name, engine in SWEEPS.items():
                for side in order:
                    figures[name][side].append(sweep_rate(trees[side], engine, args.grid_rows, Path(folder)))
            print(f"round {round_number} of the sweeps done", flush=True)
    rows = []
    print(f"\nbefore: {trees['before']}; {args.blocks} in-process blocks each, {args.rounds} sweeps each\n")
    print("| measurement | before, median (range) | after, median (range) | after / before, median of the pairs |")
    print("|---|---|---|---:|")
    for name, sides in figures.items():
        before, after = sides["before"], sides["after"]
        ratio = statistics.median(a / b for a, b in zip(after, before, strict=True))
        rows.append({"name": name, "before": before, "after": after, "paired_ratio": ratio})
        shown = [f"{statistics.median(v):,.4g} ({min(v):,.4g}-{max(v):,.4g})" for v in (before, after)]
        print(f"| {name} | {shown[0]} | {shown[1]} | {ratio:.3f} |")
    write_results("versus", rows, args.results)


if __name__ == "__main__":
    main()
