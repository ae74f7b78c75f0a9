"""`golfflight sweep` on this machine: 1,000,000 launches with --engine local and --engine ray, side by side in one run
(round by round, the order alternating), each as its own `golfflight sweep` process: shots per second end to end
(process start to results written, Ray's start included), peak memory of the whole process tree (the sum of every
process's RSS, sampled, Ray's raylet, GCS and workers included; and the sum of PSS, which counts shared pages once),
and Ray's overhead (local shots/s over Ray's). Prints a table; --results FILE writes it.

With --validation instead (section sweep_validation): a chunk's rows checked against the request model one row at a
time (`contract.columns.check_cells` each row, as every sweep did before `sweep.rows`) against the columnar check
(`sweep.rows.check_rows`), rows/s in this process on three inputs (a 3-column grid, an 8-column grid with
conditions, a CSV's text cells of mixed launches), the two interleaved round by round; and, with --before a checkout of
an earlier commit, a whole `golfflight sweep --engine torch --device cpu --threads 1` of a grid of --grid-rows
launches run from that checkout and from this one, interleaved (ABBA): wall time, shots/s and the command's own
account of the time outside the flight and the ground phase.

python benchmarks/bench_sweep.py [--shots 1000000] [--rounds 1] [--workers 2]
python benchmarks/bench_sweep.py --validation [--grid-rows 200000] [--rounds 2] [--before CHECKOUT]
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import psutil
import pyarrow as pa
import pyarrow.parquet as pq
from common import REPO, add_results_flag, mixed_launches, write_results

ENGINES = ("local", "ray")
PEAK_MB_TARGET = 2048
RAY_OVERHEAD_TARGET = 1.3
SAMPLE_S = 0.2


def write_launches(path: Path, shots: int) -> None:
    """`shots` launches scattered around every club's tour average, as a Parquet file in the sweep's columns."""
    launches = np.array(mixed_launches(shots), dtype=float)
    names = ["ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm", "spin_axis_deg"]
    pq.write_table(pa.table({name: launches[:, i] for i, name in enumerate(names)}), path)


def machine_in_use() -> int:
    """Bytes of the machine's memory in use: total minus available."""
    memory = psutil.virtual_memory()
    return memory.total - memory.available


class TreeUsage(threading.Thread):
    """Peak sums of RSS and PSS over a process and all its descendants, sampled every SAMPLE_S seconds, and the CPU
    seconds they used (each process's last sample; a machine shared with other jobs stretches wall time, not CPU).
    Beside them the machine's memory in use (total - available, which also counts shared memory no process maps,
    such as objects left in Ray's store) above what it was at the start: on a quiet machine, what the run needs."""

    def __init__(self, pid: int):
        super().__init__(daemon=True)
        self.root = psutil.Process(pid)
        self.peak_rss = self.peak_pss = 0
        self.machine_start = self.machine_peak = machine_in_use()
        self.peak_processes = 0
        self.cpu_s: dict[int, float] = {}
        self.done = threading.Event()

    def run(self) -> None:
        while not self.done.is_set():
            rss = pss = 0
            try:
                tree = [self.root, *self.root.children(recursive=True)]
            except psutil.NoSuchProcess:
                return
            for process in tree:
                try:
                    with process.oneshot():
                        memory, cpu = process.memory_full_info(), process.cpu_times()
                except (psutil.NoSuchProcess, psutil.AccessDenied):
                    continue
                rss, pss = rss + memory.rss, pss + memory.pss
                self.cpu_s[process.pid] = cpu.user + cpu.system
            self.peak_rss, self.peak_pss = max(self.peak_rss, rss), max(self.peak_pss, pss)
            self.machine_peak = max(self.machine_peak, machine_in_use())
            self.peak_processes = max(self.peak_processes, len(tree))
            self.done.wait(SAMPLE_S)


def sweep_once(engine: str, launches: Path, out: Path, workers: int) -> dict:
    """One `golfflight sweep` process: wall seconds, peak tree memory, its own summary line."""
    command = [sys.executable, "-m", "golfflight", "sweep", str(launches), "--out", str(out), "--engine", engine,
               "--workers", str(workers), "--no-progress"]
    load_before = os.getloadavg()[0]
    started = time.perf_counter()
    process = subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    usage = TreeUsage(process.pid)
    usage.start()
    stdout, stderr = process.communicate()
    seconds = time.perf_counter() - started
    usage.done.set()
    usage.join()
    if process.returncode != 0:
        raise RuntimeError(f"golfflight sweep --engine {engine} failed:\n{stderr[-3000:]}")
    return {
        "engine": engine,
        "seconds": seconds,
        "cpu_s": sum(usage.cpu_s.values()),
        "peak_rss_mb": usage.peak_rss / 2**20,
        "peak_pss_mb": usage.peak_pss / 2**20,
        "machine_mb": (usage.machine_peak - usage.machine_start) / 2**20,
        "processes": usage.peak_processes,
        "load_before": load_before,
        "load_after": os.getloadavg()[0],
        "summary": stdout.strip().splitlines()[-1],
    }


VALIDATION_CHUNK = 65_536
"""Rows checked at once in --validation: the torch engine's chunk."""

CSV_ROWS = 20_000
"""Mixed launches of the CSV input in --validation (every cell text, random winds: conditions vary row by row)."""

GRID_AXES = {
    "3-column grid": ["ball_speed_mps=30:80:164", "launch_angle_deg=6:30:20", "spin_rpm=1500:9000:20"],
    "8-column grid with conditions": ["ball_speed_mps=30:80:16", "launch_angle_deg=6:30:10", "spin_rpm=1500:9000:10",
                                      "wind_speed_mps=0,5", "wind_from_deg=0,90,180", "altitude_m=0,1600",
                                      "ground_surface=fairway,green", "ground_elevation_m=0,-3"],
}


def validation_inputs() -> dict:
    """The --validation inputs as Arrow tables of at most VALIDATION_CHUNK rows."""
    sys.path.insert(0, str(REPO / "tests"))
    from golfflight.sweep.grid import Grid
    from test_sweep import launch_rows

    tables = {}
    for name, axes in GRID_AXES.items():
        grid = Grid.parse(axes)
        tables[name] = pa.table(grid.rows(0, min(len(grid), VALIDATION_CHUNK)))
    rows = launch_rows(CSV_ROWS, seed=2)
    tables["CSV text, mixed launches"] = pa.table({k: [None if r[k] == "" else str(r[k]) for r in rows] for k in rows[0]})
    return tables


def per_row_check(table) -> int:
    """Every row through the request model on its own, as a sweep checked rows before `sweep.rows`: rows valid."""
    from golfflight.contract.columns import cell_value
    from golfflight.contract.columns import check_cells

    columns, names = table.to_pydict(), table.column_names
    return sum(not isinstance(check_cells(dict(zip(names, map(cell_value, values), strict=True))), list)
               for values in zip(*columns.values(), strict=True))


def validation_rates(rounds: int) -> list[dict]:
    """Rows/s of the per-row check and the columnar one on each input, interleaved (medians of the rounds)."""
    from golfflight.sweep.rows import check_rows

    rows = []
    for name, table in validation_inputs().items():
        seconds = {"per_row": [], "columnar": []}
        for _ in range(rounds):
            for way, check in (("per_row", per_row_check), ("columnar", lambda t: int(check_rows(t).valid.sum()))):
                started = time.perf_counter()
                valid = check(table)
                seconds[way].append(time.perf_counter() - started)
                assert valid == table.num_rows, (name, way, valid)
        ratios = [a / b for a, b in zip(seconds["per_row"], seconds["columnar"], strict=True)]
        row = {"name": f"validation alone: {name}", "rows": table.num_rows,
               **{f"{way}_rows_per_s": table.num_rows / statistics.median(s) for way, s in seconds.items()},
               "ratio": statistics.median(ratios), "per_round": ratios}
        print(f"{row['name']} ({row['rows']:,} rows): per row {row['per_row_rows_per_s']:,.0f} rows/s, columnar "
              f"{row['columnar_rows_per_s']:,.0f} rows/s ({row['ratio']:.1f}x)", flush=True)
        rows.append(row)
    return rows


def torch_sweep(checkout: Path, rows: int, folder: str) -> dict:
    """`golfflight sweep --engine torch --device cpu --threads 1` of a grid of `rows` launches, run from `checkout`
    (its own package: the current folder comes first on the path): wall seconds and the command's account."""
    speeds = max(rows // 400, 1)
    command = [sys.executable, "-m", "golfflight", "sweep", "--grid", f"ball_speed_mps=30:80:{speeds}",
               "launch_angle_deg=6:30:20", "spin_rpm=1500:9000:20", "--out", f"{folder}/out.parquet",
               "--engine", "torch", "--device", "cpu", "--threads", "1", "--no-progress"]
    load_before = os.getloadavg()[0]
    started = time.perf_counter()
    done = subprocess.run(command, cwd=checkout, capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - started
    rest = re.search(r"the rest \(([\d.]+) s\)", done.stdout)
    return {"shots": speeds * 400, "seconds": seconds, "shots_per_s": speeds * 400 / seconds,
            "rest_s": float(rest[1]) if rest else None, "load_before": load_before,
            "summary": done.stdout.strip().replace("\n", " | ")}


def whole_sweeps(before: Path, rows: int, rounds: int) -> list[dict]:
    """The torch grid sweep from `before` and from this checkout, ABBA round by round."""
    runs = []
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as folder:
        for round_number in range(rounds):
            order = (("before", before), ("after", REPO))
            for label, checkout in order if round_number % 2 == 0 else order[::-1]:
                run = {"round": round_number, "code": label, **torch_sweep(checkout, rows, folder)}
                print(f"round {round_number} {label}: {run['seconds']:.1f} s, {run['shots_per_s']:,.0f} shots/s, rest "
                      f"{run['rest_s']} s (load {run['load_before']:.1f}); {run['summary']}", flush=True)
                runs.append(run)
    result = []
    for label in ("before", "after"):
        mine = [r for r in runs if r["code"] == label]
        result.append({"name": f"golfflight sweep --engine torch --device cpu --threads 1, {mine[0]['shots']:,}-row grid,"
                       f" {label}", "seconds": statistics.median(r["seconds"] for r in mine),
                       "shots_per_s": statistics.median(r["shots_per_s"] for r in mine),
                       "rest_s": statistics.median(r["rest_s"] for r in mine)})
    pairs = zip([r for r in runs if r["code"] == "before"], [r for r in runs if r["code"] == "after"], strict=True)
    ratios = [(a["seconds"] / b["seconds"], a["rest_s"] / b["rest_s"]) for a, b in pairs]
    result.append({"name": "whole sweep: after shots/s over before's, and before's rest (reading, validating, writing) "
                   "over after's", "ratio": statistics.median(r[0] for r in ratios),
                   "rest_ratio": statistics.median(r[1] for r in ratios), "per_round": ratios})
    return [*result, {"name": "runs", "runs": runs}]


def validation_main(args: argparse.Namespace) -> None:
    rows = validation_rates(args.rounds)
    if args.before:
        rows += whole_sweeps(Path(args.before).resolve(), args.grid_rows, args.rounds)
        print(f"whole sweep: {rows[-2]['ratio']:.2f}x shots/s, the rest {rows[-2]['rest_ratio']:.1f}x faster")
    write_results("sweep_validation", rows, args.results)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=1, help="rounds of both engines, the order alternating")
    parser.add_argument("--workers", type=int, default=2, help="processes or Ray actors (this machine has 2 cores)")
    parser.add_argument("--validation", action="store_true", help="the row check's speed instead (module docstring)")
    parser.add_argument("--grid-rows", type=int, default=200_000, help="--validation: the whole torch sweep's grid")
    parser.add_argument("--before", help="--validation: a checkout of an earlier commit to sweep from, interleaved")
    add_results_flag(parser)
    args = parser.parse_args()
    if args.validation:
        validation_main(args)
        return
    runs = []
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as folder:
        launches = Path(folder) / "launches.parquet"
        write_launches(launches, args.shots)
        for round_number in range(args.rounds):
            order = ENGINES if round_number % 2 == 0 else ENGINES[::-1]
            for engine in order:
                out = Path(folder) / f"{engine}.parquet"
                run = sweep_once(engine, launches, out, args.workers)
                assert pq.read_metadata(out).num_rows == args.shots
                out.unlink()
                runs.append({"round": round_number, **run})
                print(f"round {round_number} {engine}: {run['seconds']:.1f} s, peak RSS {run['peak_rss_mb']:.0f} MB, "
                      f"PSS {run['peak_pss_mb']:.0f} MB, machine +{run['machine_mb']:.0f} MB "
                      f"(load {run['load_before']:.1f} -> {run['load_after']:.1f}); {run['summary']}", flush=True)
    rows = []
    for engine in ENGINES:
        mine = [r for r in runs if r["engine"] == engine]
        peak = max(r["peak_rss_mb"] for r in mine)
        rows.append({"name": f"--engine {engine}, {args.workers} workers",
                     "seconds": statistics.median(r["seconds"] for r in mine),
                     "shots_per_s": statistics.median(args.shots / r["seconds"] for r in mine),
                     "cpu_s": statistics.median(r["cpu_s"] for r in mine),
                     "peak_rss_mb": peak, "peak_pss_mb": max(r["peak_pss_mb"] for r in mine),
                     "machine_mb": max(r["machine_mb"] for r in mine),
                     "processes": max(r["processes"] for r in mine),
                     "target": f"finishes, peak RSS < {PEAK_MB_TARGET} MB", "met": peak < PEAK_MB_TARGET})
    ray_runs, local_runs = ([r for r in runs if r["engine"] == e] for e in ("ray", "local"))
    wall = [a["seconds"] / b["seconds"] for a, b in zip(ray_runs, local_runs, strict=True)]
    cpu = [a["cpu_s"] / b["cpu_s"] for a, b in zip(ray_runs, local_runs, strict=True)]
    ratio = statistics.median(wall)
    rows.append({"name": "Ray overhead: local shots/s over Ray's (wall time, median of the rounds' ratios)",
                 "ratio": ratio, "per_round": wall, "target": f"<= {RAY_OVERHEAD_TARGET}",
                 "met": ratio <= RAY_OVERHEAD_TARGET})
    rows.append({"name": "Ray's CPU seconds over local's (median of the rounds' ratios)", "ratio": statistics.median(cpu),
                 "per_round": cpu, "target": "(context)", "met": True})
    print(f"\n{args.shots:,} launches, {args.rounds} round(s), order alternating (medians of the rounds)\n")
    print("| engine | wall time | shots/s | CPU time, process tree | peak RSS, process tree | peak PSS | "
          "machine memory, peak rise | processes | target | met |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for row in rows[:2]:
        print(f"| {row['name']} | {row['seconds']:.1f} s | {row['shots_per_s']:,.0f} | {row['cpu_s']:.0f} s | "
              f"{row['peak_rss_mb']:,.0f} MB | {row['peak_pss_mb']:,.0f} MB | {row['machine_mb']:,.0f} MB | "
              f"{row['processes']} | {row['target']} | "
              f"{'yes' if row['met'] else 'NO'} |")
    for row in rows[2:]:
        rounds = ", ".join(f"{r:.2f}" for r in row["per_round"])
        print(f"| {row['name']} | | {row['ratio']:.2f}x ({rounds}) | | | | | | {row['target']} | "
              f"{'yes' if row['met'] else 'NO'} |")
    write_results("sweep", [*rows, {"name": "runs", "runs": runs}], args.results)


if __name__ == "__main__":
    main()
