"""`golfflight sweep` on this machine: 1,000,000 launches with --engine local and --engine ray, side by side in one run
(round by round, the order alternating), each as its own `golfflight sweep` process: shots per second end to end
(process start to results written, Ray's start included), peak memory of the whole process tree (the sum of every
process's RSS, sampled, Ray's raylet, GCS and workers included; and the sum of PSS, which counts shared pages once),
and Ray's overhead (local shots/s over Ray's). Prints a table, writes results.json.

python benchmarks/bench_sweep.py [--shots 1000000] [--rounds 1] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
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
from common import REPO, mixed_launches, write_results

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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=1, help="rounds of both engines, the order alternating")
    parser.add_argument("--workers", type=int, default=2, help="processes or Ray actors (this machine has 2 cores)")
    args = parser.parse_args()
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
    write_results("sweep", [*rows, {"name": "runs", "runs": runs}])


if __name__ == "__main__":
    main()
