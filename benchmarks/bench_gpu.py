"""The torch engine (`golfflight sweep --engine torch`, `flight.torch_engine`) on one device: shots per second
against batch size (the flight alone, eager and with its Euler step compiled, and with its launch states and ground
phase, the ground phase where the engine puts it and on the other side: the device or NumPy on the CPU; and eager
with every shot flown to its part's last step, the landed shots never set aside), peak memory,
carry parity with the ONNX Runtime engine on 10,000 mixed shots (float32 and float64 physics, float32
compiled), the CPU's share of a sweep in microseconds a row (what caps a sweep however fast the device flies), and
sweeps end to end through the command line. With --results FILE, writes the section `torch_engine_<cpu|cuda>` there
(other sections are kept) and prints a table for docs/benchmarks.md. The flight's time runs from the launch states to
the landings back in NumPy (the device's transfers included); around it are the batch's launch states and air before
it, and the figures and the bounce and roll of the landings after it (`torch_engine.STAGES`); the CPU's share of a
sweep is all but the flight, the driver's work included.

One command on a GPU machine (with the defaults estimated at 7-8 minutes on an H100, not yet run there: four engines
at five batch sizes, two compilations, and seven sweeps of 4,194,304 rows, two of them by 2 and 4 processes sharing
the GPU; each measurement is written to that file as soon as it is made, so a run cut short keeps what
it measured). `--engines` chooses the engines timed beside the eager one and `--sweep-timeout` stops a sweep that
runs too long: scripts/gpu_session.sh runs the script in parts that fit the project's lent machines (15 minutes of
device time a session, training's measurements included; their image lacks Ray). --ray-workers 1,2,4 also sweeps the
same grid through `--engine ray --device cuda` with that many actors sharing the GPU, `--actors-per-gpu`, Ray's
start included: about 2 minutes more, not yet run there either, and only where Ray is installed:
    python benchmarks/bench_gpu.py --device cuda [--ray-workers 1,2,4]
Here on the CPU, small sizes:
    python benchmarks/bench_gpu.py --device cpu --batches 1024,4096,16384 --parity-shots 3000 --share-rows 124032 \
        --sweep-rows 30000 --threads 2
"""

from __future__ import annotations

import argparse
import os
import resource
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import torch
from common import REPO, add_results_flag, write_results
from golfflight.flight.air import Air
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.flyer import load_flyer
from golfflight.flight.ground import SURFACES, GroundSpec
from golfflight.flight.problem import FlightProblem
from golfflight.flight.torch_engine import STAGES, TorchEngine
from golfflight.flight.wind import Wind
from golfflight.shots.clubs import CLUBS
from golfflight.sweep.engines import PIECES_IN_FLIGHT
from golfflight.sweep.grid import Grid
from golfflight.sweep.run import run_sweep
from golfflight.sweep.sources import GridSource

from golfflight.commands.sweep import TORCH_CHUNK_ROWS

DEFAULT_BATCHES = {"cuda": (1024, 16_384, 262_144, 1_048_576, 4_194_304), "cpu": (1024, 4096, 16_384)}
DEFAULT_SWEEP_ROWS = {"cuda": 4_194_304, "cpu": 8192}
"""Rows of the sweeps (the CPU's share, and end to end): on a GPU four of its million-row chunks."""
PARITY_SHOTS = 10_000
CARRY_TARGET_M = 1e-3
"""Issue 33: carries within 1 mm of the ONNX engine on 10,000 mixed shots in float32."""
FLIGHT_TARGET = {"cuda": 5_000_000.0}
"""Issue 33 on one H100: the flight alone at 5 M shots/s or more (with compilation, CUDA graphs or a fused step)."""
SWEEP_TARGET = {"cuda": 2_000_000.0}
"""Issue 33 on one H100: a sweep to Parquet at 2 M shots/s or more end to end."""
DEFAULT_TORCH_WORKERS = {"cuda": (2, 4), "cpu": ()}
"""Processes sharing the device in the `--engine torch --workers K` sweeps: on a GPU, so that one process's host work
overlaps another's flight (a CPU's cores are its flight: the sweep in one process is the faster there)."""


def launches_array(n: int, seed: int = 0) -> np.ndarray:
    """[n, 5] launches scattered around every club's tour average (`common.mixed_launches`' spread), without a
    Python step a shot (millions of shots a batch on a GPU)."""
    rng = np.random.default_rng(seed)
    clubs = rng.integers(0, len(CLUBS), n)
    speed, angle, spin = (np.array([getattr(c, name) for c in CLUBS])[clubs]
                          for name in ("ball_speed_mps", "launch_angle_deg", "spin_rpm"))
    return np.stack([speed * rng.normal(1.0, 0.04, n), angle + rng.normal(0.0, 1.5, n), rng.normal(0.0, 2.0, n),
                     spin * rng.normal(1.0, 0.1, n), rng.normal(0.0, 8.0, n)], axis=-1)


def mixed_conditions(n: int, seed: int = 1) -> tuple[list[Conditions], list[GroundSpec | None]]:
    """Air from sea level to 2,000 m and -5 to 40 degC, calm, uniform and log-profile winds, grounds 4 m below to
    6 m above the tee on four surfaces (a fifth of the shots the flight alone)."""
    rng = np.random.default_rng(seed)
    conditions, grounds = [], []
    for i in range(n):
        air = Air.from_conditions(float(rng.uniform(-5, 40)), float(rng.choice([0.0, 800.0, 2000.0])))
        wind = Wind(float(rng.uniform(0, 12)), float(rng.uniform(0, 360)), str(rng.choice(["uniform", "log"])))
        conditions.append(Conditions(air, wind if i % 4 else Wind()))
        surface = SURFACES[str(rng.choice(["fairway", "green", "rough", "firm_fairway"]))]
        ground = GroundSpec(surface, float(rng.choice([-4.0, 0.0, 6.0])), float(rng.choice([0.0, 2.0])),
                            float(rng.uniform(0, 360)))
        grounds.append(None if i % 5 == 0 else ground)
    return conditions, grounds


def peak_memory_mb(device: torch.device) -> float:
    """The device's peak allocated memory since the last reset (CUDA), or this process's peak RSS (CPU)."""
    if device.type == "cuda":
        return torch.cuda.max_memory_allocated(device) / 2**20
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def timed(engine: TorchEngine, launches: np.ndarray, rounds: int) -> dict[str, float]:
    """Median seconds of `rounds` batches (standard air, calm, a level fairway) in each of the engine's stages."""
    spent = {stage: [] for stage in STAGES}
    for _ in range(rounds):
        engine.seconds = dict.fromkeys(STAGES, 0.0)
        engine.fly_batch(FlightProblem.of(launches, STANDARD, GroundSpec(SURFACES["fairway"])))
        for stage in STAGES:
            spent[stage].append(engine.seconds[stage])
    return {stage: statistics.median(values) for stage, values in spent.items()}


def throughput(engines: dict[str, TorchEngine], batches: list[int], rounds: int) -> list[dict]:
    """Shots/s of the flight (each engine of `warmed_engines`) and of the whole batch with its launch states and ground
    phase, and peak memory, at each batch size; the engines interleaved at each size."""
    rows = []
    for n in batches:
        launches = launches_array(n)
        row = {"batch": n}
        for name, engine in engines.items():
            if engine.device.type == "cuda":
                torch.cuda.reset_peak_memory_stats(engine.device)
            seconds = timed(engine, launches, rounds)
            around = seconds["prepare"] + seconds["ground"]
            row[name] = {"shots_per_s": n / seconds["flight"], "us_per_shot": seconds["flight"] / n * 1e6,
                         "whole_shots_per_s": n / (seconds["flight"] + around),
                         "prepare_us_per_shot": seconds["prepare"] / n * 1e6,
                         "ground_us_per_shot": seconds["ground"] / n * 1e6,
                         "peak_memory_mb": peak_memory_mb(engine.device), "parts": -(-n // engine.part_shots())}
            r = row[name]
            print(f"batch {n:>9,} {name:>8}: {r['shots_per_s']:>12,.0f} shots/s ({r['us_per_shot']:.2f} us a shot), "
                  f"whole {r['whole_shots_per_s']:>12,.0f} shots/s (launch states {r['prepare_us_per_shot']:.2f}, "
                  f"figures and ground phase {r['ground_us_per_shot']:.2f} us a shot), "
                  f"peak {r['peak_memory_mb']:,.0f} MB",
                  flush=True)
        rows.append(row)
    return rows


def parity(bundle: Path, device: str, shots: int, engines: dict[str, TorchEngine]) -> list[dict]:
    """Carry (and rest) max |difference| from the ONNX engine's batch path on `shots` mixed shots, per precision:
    float32 by the warmed eager engine (and the compiled one, if `engines` has it: no second compilation), float64 by
    one built here."""
    launches = launches_array(shots, seed=7)
    conditions, grounds = mixed_conditions(shots)
    started = time.perf_counter()
    reference = load_flyer(bundle).fly_batch(FlightProblem.of(launches, conditions, grounds))
    print(f"ONNX reference: {shots:,} mixed shots in {time.perf_counter() - started:.1f} s", flush=True)
    cases = [("float32", False, engines["eager"]), ("float64", False, TorchEngine(bundle, device, "float64"))]
    if "compiled" in engines:
        cases.append(("float32", True, engines["compiled"]))
    rows = []
    for dtype, compile_step, engine in cases:
        got = engine.fly_batch(FlightProblem.of(launches, conditions, grounds))
        landed = np.array([i not in reference.errors for i in range(shots)])
        rolled = got.rolled & reference.rolled
        row = {"dtype": dtype, "compiled": compile_step, "shots": shots, "errors_equal": got.errors == reference.errors,
               "carry_max_abs_m": float(np.max(np.abs(got.carry_m[landed] - reference.carry_m[landed]))),
               "apex_max_abs_m": float(np.max(np.abs(got.apex_m[landed] - reference.apex_m[landed]))),
               "total_max_abs_m": float(np.max(np.abs(got.rest.total_m[rolled] - reference.rest.total_m[rolled])))}
        if dtype == "float32":
            row |= {"target": f"carry within {CARRY_TARGET_M * 1e3:g} mm",
                    "met": row["errors_equal"] and row["carry_max_abs_m"] < CARRY_TARGET_M}
        rows.append(row)
        label = f"{dtype}{' compiled' if compile_step else ''}"
        print(f"parity {label}: carry max |d| {row['carry_max_abs_m'] * 1e3:.4f} mm, apex "
              f"{row['apex_max_abs_m'] * 1e3:.4f} mm, total {row['total_max_abs_m'] * 1e3:.4f} mm, errors equal "
              f"{row['errors_equal']}", flush=True)
    return rows


SHARE_GRID = ["launch_angle_deg=6:24:19", "spin_rpm=1500:9000:4", "wind_from_deg=0,90,180,270", "wind_speed_mps=5",
              "altitude_m=0,1600", "ground_surface=fairway,green"]
"""The grid whose CPU share is measured, beside its ball speeds: 1,216 launches a speed, in two airs, four winds and
on two surfaces (a sweep's usual mix of a few shared conditions)."""


def cpu_share(bundle: Path, device: str, rows: int, rounds: int = 2) -> dict:
    """A sweep of a grid of about `rows` launches through `run_sweep` in this process, in the command line's chunks
    for the device, one piece at a time, `PIECES_IN_FLIGHT` (the command line's) and twice that at once (does the
    overlap grow with more threads on a machine of many cores?), interleaved for `rounds`: wall seconds of
    each, and, from the one-at-a-time runs (no overlap), each stage's microseconds a row and the CPU's (all but the
    device's flight; on a GPU the ground phase's time on the device with it), whose inverse caps the sweep's rows/s
    however fast the device flies. An untimed sweep of one
    ball speed first: the driver's first sweep in a process pays its imports and caches (about 4 us a row more
    here)."""
    speeds = max(rows // 1216, 1)
    grid = Grid.parse([f"ball_speed_mps=30:80:{speeds}", *SHARE_GRID])
    walls: dict[int, list[float]] = {1: [], PIECES_IN_FLIGHT: [], 2 * PIECES_IN_FLIGHT: []}
    stages = []
    with tempfile.TemporaryDirectory() as folder:
        run_sweep(GridSource(Grid.parse(["ball_speed_mps=50", *SHARE_GRID]), 65_536), f"{folder}/out.parquet",
                  engine="torch", in_process=TorchEngine(bundle, device), progress=False)
        for _ in range(rounds):
            for in_flight, wall in walls.items():
                engine = TorchEngine(bundle, device, parts_at_once=in_flight)
                done = run_sweep(GridSource(grid, TORCH_CHUNK_ROWS[engine.device.type]), f"{folder}/out.parquet",
                                 engine="torch", in_process=engine, progress=False, in_flight=in_flight)
                wall.append(done.seconds)
                if in_flight == 1:
                    stages.append({**engine.seconds, "rest": done.seconds - sum(engine.seconds.values())})
    shots = len(grid)
    per_row = {f"{stage}_us_per_row": statistics.median(s[stage] for s in stages) / shots * 1e6
               for stage in (*STAGES, "rest")}
    cpu = sum(value for key, value in per_row.items() if not key.startswith("flight"))
    row = {"shots": shots, **per_row, "cpu_us_per_row": cpu, "cpu_ceiling_rows_per_s": 1e6 / cpu,
           **{f"wall_s_{n}_in_flight": statistics.median(w) for n, w in walls.items()}}
    print(f"CPU share of a {shots:,}-row sweep: " + ", ".join(f"{k} {v:.2f}" for k, v in per_row.items())
          + f" (us a row); the CPU's {cpu:.2f} us a row caps a sweep at {1e6 / cpu:,.0f} rows/s; wall "
          + ", ".join(f"{statistics.median(w):.2f} s with {n} in flight" for n, w in walls.items()), flush=True)
    return row


def engine_options(device: str, compiled: bool = False, ray_workers: int | None = None,
                   torch_workers: int | None = None) -> list[str]:
    """The sweep's engine options: `--engine torch` in its process (`--compile` if `compiled`), or in a pool of
    `torch_workers` processes sharing the device (`--workers`), or, with `ray_workers`, `--engine ray --device` on
    that many actors, all on the one GPU with `--actors-per-gpu` where the device is cuda."""
    if ray_workers is not None:
        return ["--engine", "ray", "--actors-per-gpu" if device == "cuda" else "--workers", str(ray_workers)]
    pool = [] if torch_workers is None else ["--workers", str(torch_workers)]
    return ["--engine", "torch", *pool, *(["--compile"] if compiled else [])]


def sweep_end_to_end(device: str, rows: int, threads: int | None, engine: list[str], timeout_s: float) -> dict:
    """`golfflight sweep` with `engine` (`engine_options`) on a grid of `rows` launches to Parquet, as its own
    process: wall seconds from start to file written (loading and compiling included), and the command's own account
    of where the time went; a sweep still running after `timeout_s` is stopped and said to be (a lent machine's
    minutes are few)."""
    speeds = max(rows // 400, 1)
    grid = [f"ball_speed_mps=30:80:{speeds}", "launch_angle_deg=6:30:20", "spin_rpm=1500:9000:20"]
    shots = speeds * 400
    with tempfile.TemporaryDirectory() as folder:
        command = [sys.executable, "-m", "golfflight", "sweep", "--grid", *grid, "--out", f"{folder}/out.parquet",
                   *engine, "--device", device, "--no-progress", *(["--threads", str(threads)] if threads else [])]
        started = time.perf_counter()
        with subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              start_new_session=True) as process:  # its own group: a pool's workers stop with it
            try:
                stdout, stderr = process.communicate(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.communicate()
                print(f"{' '.join(engine)}: stopped after {timeout_s:g} s", flush=True)
                return {"shots": shots, "engine": " ".join(engine), "error": f"stopped after {timeout_s:g} s"}
        seconds = time.perf_counter() - started
    if process.returncode:
        print(f"{' '.join(engine)}: failed ({stderr.strip()[-500:]})", flush=True)
        return {"shots": shots, "engine": " ".join(engine), "error": stderr.strip()[-2000:]}
    print(stdout.strip(), flush=True)
    return {"shots": shots, "seconds": seconds, "shots_per_s": shots / seconds, "summary": stdout.strip(),
            "engine": " ".join(engine)}


def counts(text: str) -> list[int]:
    """Comma-separated whole numbers (an empty text: none)."""
    return [int(k) for k in text.split(",") if k]


def machine_of(device: torch.device) -> dict:
    gpu = {"gpu": torch.cuda.get_device_name(device), "cuda": torch.version.cuda} if device.type == "cuda" else {}
    return {"torch": torch.__version__, "torch_threads": torch.get_num_threads(), **gpu}


def print_table(section: dict) -> None:
    names = [name for name in section["throughput"][0] if name != "batch"]
    print("\n| batch | engine | flight shots/s | flight us a shot | launch states us a shot | figures and ground phase "
          "us a shot | whole shots/s | peak memory |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    for row in section["throughput"]:
        for name in names:
            r = row[name]
            print(f"| {row['batch']:,} | {name} | {r['shots_per_s']:,.0f} | {r['us_per_shot']:.2f} | "
                  f"{r['prepare_us_per_shot']:.2f} | {r['ground_us_per_shot']:.2f} | {r['whole_shots_per_s']:,.0f} | "
                  f"{r['peak_memory_mb']:,.0f} MB |")


OTHER_ENGINES = ("compiled", "ground-elsewhere", "none-set-aside")
"""The engines timed beside the eager one (`--engines`): its step compiled, its ground phase on the other side (the
CPU's NumPy on a GPU, the device's torch on a CPU), and every shot flown to its part's last step (landed shots never
set aside)."""


def warmed_engines(bundle: Path, device: str, others: list[str]) -> tuple[dict[str, TorchEngine], dict[str, str]]:
    """The eager engine and the `others` (OTHER_ENGINES) to time, each flown once (the first kernels, allocations and
    compilation), and why any could not be (a device's compiler missing, say): on a lent machine's few minutes, one
    engine that fails must not lose the others' numbers."""
    eager = TorchEngine(bundle, device)
    elsewhere = "cpu" if eager.ground_on_device else "device"
    makers = {"compiled": ("compiled", lambda: TorchEngine(bundle, device, compile_step=True)),
              "ground-elsewhere": (f"ground on {elsewhere}",
                                   lambda: TorchEngine(bundle, device, ground_on_device=not eager.ground_on_device)),
              "none-set-aside": ("none set aside", lambda: TorchEngine(bundle, device, set_aside_share=1.0))}
    engines, failed = {"eager": eager}, {}
    eager.fly_batch(FlightProblem.of(launches_array(1024), STANDARD, GroundSpec(SURFACES["fairway"])))
    for name, make in (makers[other] for other in others):
        try:
            engine = make()
            engine.fly_batch(FlightProblem.of(launches_array(1024), STANDARD, GroundSpec(SURFACES["fairway"])))
            engines[name] = engine
        except Exception as error:  # noqa: BLE001 - recorded in the results, the other engines still timed
            failed[name] = f"{type(error).__name__}: {error}"
            print(f"{name}: could not fly ({failed[name]})", flush=True)
    return engines, failed


def engine_names(text: str) -> list[str]:
    """Comma-separated names of OTHER_ENGINES (an empty text: none)."""
    names = [name for name in text.split(",") if name]
    unknown = sorted(set(names) - set(OTHER_ENGINES))
    if unknown:
        raise argparse.ArgumentTypeError(f"{', '.join(unknown)}: choose from {', '.join(OTHER_ENGINES)}")
    return names


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    parser.add_argument("--batches", help="comma-separated batch sizes (default: by device)")
    parser.add_argument("--rounds", type=int, default=3, help="batches timed at each size (the median is kept)")
    parser.add_argument("--parity-shots", type=int, default=PARITY_SHOTS)
    parser.add_argument("--sweep-rows", type=int, help="launches of the end-to-end sweep (0: none; default: by device)")
    parser.add_argument("--threads", type=int, help="torch CPU threads (default: torch's)")
    parser.add_argument("--model", help="bundle (default: the shipped models/default)")
    parser.add_argument("--ray-workers", type=counts, default=[],
                        help="also sweep through --engine ray --device on this many actors (comma-separated counts; "
                        "on cuda, all sharing its one GPU)")
    parser.add_argument("--torch-workers", type=counts,
                        help="also sweep through --engine torch --workers K, K processes sharing the device "
                        "(comma-separated counts; default 2,4 on cuda, none on a CPU)")
    parser.add_argument("--engines", type=engine_names, default=list(OTHER_ENGINES),
                        help=f"engines timed beside the eager one, comma-separated (default all: "
                        f"{','.join(OTHER_ENGINES)}; the compiled one also flies the parity and the compiled sweep)")
    parser.add_argument("--sweep-timeout", type=float, default=300.0,
                        help="seconds an end-to-end sweep may run before it is stopped (default 300)")
    parser.add_argument("--share-rows", type=int, help="launches of the CPU-share sweeps (0: none; default: by device)")
    add_results_flag(parser)
    args = parser.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    bundle = load_flyer(args.model).bundle_dir
    engines, failed = warmed_engines(bundle, args.device, args.engines)
    engine = engines["eager"]
    kind = engine.device.type
    batches = [int(b) for b in args.batches.split(",")] if args.batches else list(DEFAULT_BATCHES[kind])
    section = {"device": str(engine.device), **machine_of(engine.device), "part_shots": engine.part_shots(),
               "could_not_fly": failed}

    def measured(name: str, value) -> None:
        """Keep a measurement in the section and write the section now (a run cut short keeps what it measured)."""
        section[name] = value
        write_results(f"torch_engine_{kind}", [section], args.results)

    measured("throughput", throughput(engines, batches, args.rounds))
    measured("parity", parity(bundle, args.device, args.parity_shots, engines))
    best = max(row[name]["shots_per_s"] for row in section["throughput"] for name in engines)
    measured("flight_best_shots_per_s", best)
    if kind in FLIGHT_TARGET:
        measured("flight_target", {"target": f">= {FLIGHT_TARGET[kind]:,.0f} shots/s",
                                   "met": best >= FLIGHT_TARGET[kind]})
    share_rows = DEFAULT_SWEEP_ROWS[kind] if args.share_rows is None else args.share_rows
    if share_rows:
        measured("cpu_share", cpu_share(bundle, args.device, share_rows))
    rows = DEFAULT_SWEEP_ROWS[kind] if args.sweep_rows is None else args.sweep_rows
    torch_workers = DEFAULT_TORCH_WORKERS[kind] if args.torch_workers is None else args.torch_workers
    for name, compiled, options in (
        ("sweep", False, engine_options(args.device)),
        ("sweep_compiled", True, engine_options(args.device, compiled=True)),
        *((f"torch_workers_sweep_{k}", False, engine_options(args.device, torch_workers=k)) for k in torch_workers),
        *((f"ray_sweep_{k}", False, engine_options(args.device, ray_workers=k)) for k in args.ray_workers),
    ):
        if not rows or (compiled and "compiled" not in engines):
            continue
        result = sweep_end_to_end(args.device, rows, args.threads, options, args.sweep_timeout)
        if kind in SWEEP_TARGET and "error" not in result:
            result |= {"target": f">= {SWEEP_TARGET[kind]:,.0f} shots/s",
                       "met": result["shots_per_s"] >= SWEEP_TARGET[kind]}
        measured(name, result)
    print_table(section)


if __name__ == "__main__":
    main()
