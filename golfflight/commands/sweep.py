"""`golfflight sweep`: fly a file of launches, or a grid of them, into a Parquet file of results (docs/sweep.md).

Input: a CSV or Parquet file with `golfflight simulate`'s CSV columns, or `--grid COLUMN=SPEC ...` (a cartesian
product: START:STOP:COUNT, V1,V2,... or V per column, `sweep.grid`). Output: one row per input row, its number
(`row`), its columns and its flight, the same numbers as `golfflight simulate`. `--engine local` flies on a pool of
processes here, `--engine ray` through Ray Data (a local Ray instance, or a cluster's with `--ray-address`),
`--engine torch` in this process on `--device cpu` or `cuda` (the bundle rebuilt in torch,
`flight.torch_engine`), or with `--workers K` in K processes here, each with its own torch engine on the
device (sharing one GPU, so that one process's host work overlaps another's flight, as Ray's actors do). `--engine
ray --device cuda` flies the torch engine in each Ray actor on a GPU (one actor a GPU, or `--actors-per-gpu K`
sharing each, so that one actor's host work, checking rows, rolling to rest and writing, overlaps another's flight;
each engine sizes its batches to its share of the GPU's free memory; `--workers` left out is as many actors as the
cluster's GPUs hold); `--device cpu` there flies it on each actor's CPU, the numbers of `--engine torch`. Needs the
`sweep` extra (pyarrow, tqdm), the `ray` extra for `--engine ray` and the `train` extra (torch) for `--engine torch`
and `--device`.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from golfflight.commands import COMMANDS
from golfflight.errors import InputError

EXTRAS = {"sweep": ("pyarrow", "tqdm"), "ray": ("ray.data",), "train": ("torch",)}
"""The modules each extra brings: the serving install (`pip install .`, the Docker image) has none of them."""

CHUNK_ROWS = 8192
"""Shots a worker flies in one engine batch: large enough that the per-step ONNX call is spread over many shots."""

TORCH_CHUNK_ROWS = {"cpu": 65_536, "cuda": 1_048_576}
"""Shots the torch engine flies in one batch by default, by device: each step's kernel launches cost the same however
many shots they carry, so a GPU wants a million (issue 33 measured 105 us a shot at 1,024 shots and 0.49 us at 1-4
million); a CPU 65,536. The engine splits a batch further where the device's memory needs it."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "sweep",
        help=COMMANDS["sweep"].summary,
        description="Fly every row of a launches file (CSV or Parquet, simulate's columns) or of a grid into one Parquet "
        "file, the numbers simulate gives: on local processes (ONNX Runtime), Ray Data actors, or the model rebuilt in "
        "torch (--engine torch, on --device cpu or cuda). On a Ray cluster with GPUs, --engine ray --device cuda "
        "flies the torch engine in each actor on a GPU (--actors-per-gpu K sharing each), as many actors as the "
        "cluster's GPUs hold unless --workers says fewer (e.g. golfflight sweep --grid ball_speed_mps=30:80:1000 "
        "launch_angle_deg=6:30:100 spin_rpm=1500:9000:100 --out sweep.parquet --engine ray --device cuda "
        "--ray-address auto); it is refused in "
        "one line where the cluster lists no GPU or a GPU worker cannot build the engine (no torch, no CUDA).",
    )
    parser.add_argument("launches", nargs="?", help="CSV or Parquet file of launches (simulate's CSV columns)")
    parser.add_argument(
        "--grid", nargs="+", metavar="COLUMN=SPEC",
        help="instead of a file: the cartesian product of COLUMN=START:STOP:COUNT, COLUMN=V1,V2,... or COLUMN=V",
    )
    parser.add_argument("--out", required=True, help="the results' Parquet file (written whole or not at all)")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.add_argument("--engine", choices=("local", "ray", "torch"), default="local",
                        help="local processes, Ray Data, or the model in torch (--device) in this process")
    parser.add_argument("--workers", type=int, help="processes or Ray actors (default: this machine's cores; with "
                        "--engine ray --device cuda, one actor for each GPU of the Ray cluster; with --engine torch, "
                        "this process alone: K processes here, each with its own torch engine, sharing the device)")
    parser.add_argument("--chunk-rows", type=int, help=f"shots a batch (default {CHUNK_ROWS}; with the torch engine "
                        f"{TORCH_CHUNK_ROWS['cpu']} on a CPU, {TORCH_CHUNK_ROWS['cuda']} on a GPU)")
    parser.add_argument("--device", help="the torch engine's device: --engine torch: cpu (default), cuda or cuda:N; "
                        "--engine ray: cuda (each actor on a GPU, or a share of one, that Ray gives it) or cpu")
    parser.add_argument("--dtype", choices=("float32", "float64"),
                        help="the torch engine's physics' precision (default float32; the network is float32)")
    parser.add_argument("--threads", type=int, help="the torch engine on a CPU: torch's threads (default: torch's, "
                        "one a core, with --engine torch; 1 in each Ray actor; 1 where other work shares the cores)")
    parser.add_argument("--actors-per-gpu", type=int, help="--engine ray --device cuda: Ray actors sharing each GPU "
                        "(default 1), each asking Ray for 1/K of one and flying in 1/K of its memory")
    parser.add_argument("--compile", action="store_true", default=None,
                        help="the torch engine: fuse each Euler step's kernels with torch.compile (compiled once a "
                        "run, in seconds; on a CPU it needs a C compiler)")
    parser.add_argument("--ray-address", help="an existing Ray cluster (e.g. ray://head:10001 or auto); default: a "
                        "local Ray instance, stopped after")
    parser.add_argument(
        "--skip-bad-rows", action="store_true", help="fly the valid rows and list each invalid one instead of refusing"
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on standard error")
    parser.set_defaults(run=run)


def require_extras(*extras: str, who: str | None = None) -> None:
    """Refuse in one line, naming the extra to install (and `who` needs it, where given), unless every module of
    `extras` imports (a missing one would otherwise surface as a ModuleNotFoundError's traceback in the middle of the
    sweep)."""
    for extra in extras:
        for module in EXTRAS[extra]:
            try:
                importlib.import_module(module)
            except ImportError as missing:
                needs = who or {"ray": "--engine ray needs", "train": "--engine torch needs"}.get(extra, "needs")
                raise InputError(
                    f"{needs} the {extra} extra, which is not installed (no {missing.name or module}): "
                    f"pip install 'golfflight[{extra}]'"
                ) from None


def _torch_on_ray(args: argparse.Namespace) -> bool:
    """Whether each Ray actor flies the torch engine (`--engine ray --device ...`)."""
    return args.engine == "ray" and args.device is not None


def _check_options(args: argparse.Namespace) -> None:
    """Refuse options that do not go with the chosen engine, or numbers below 1."""
    if (args.workers is not None and args.workers < 1) or (args.chunk_rows is not None and args.chunk_rows < 1):
        raise InputError("--workers and --chunk-rows take a whole number of at least 1")
    if args.ray_address and args.engine != "ray":
        raise InputError("--ray-address goes with --engine ray")
    if args.threads is not None and args.threads < 1:
        raise InputError("--threads takes a whole number of at least 1")
    if args.actors_per_gpu is not None and (args.engine != "ray" or args.device != "cuda"):
        raise InputError("--actors-per-gpu goes with --engine ray --device cuda")
    if args.actors_per_gpu is not None and args.actors_per_gpu < 1:
        raise InputError("--actors-per-gpu takes a whole number of at least 1")
    torch_only = [name for name in ("device", "dtype", "threads", "compile") if getattr(args, name) is not None]
    if torch_only and args.engine == "local":
        also = "--engine ray" if torch_only[0] == "device" else "--engine ray with --device"
        raise InputError(f"--{torch_only[0]} goes with --engine torch, or {also}")
    if torch_only and args.engine == "ray" and args.device is None:
        raise InputError(f"--{torch_only[0]} goes with --engine ray only beside --device (cuda or cpu): the torch engine")
    if _torch_on_ray(args) and args.device not in ("cuda", "cpu"):
        raise InputError(f"--device {args.device}: with --engine ray, Ray gives each actor its own GPU; give --device "
                         "cuda (or cpu)")


def _torch_maker(args: argparse.Namespace, threads: int | None, parts_at_once: int = 1):
    """How the torch engine is built on the asked device (`flight.torch_engine.TorchEngineMaker`)."""
    from golfflight.flight.torch_engine import TorchEngineMaker

    return TorchEngineMaker(args.device or "cpu", args.dtype or "float32", threads, parts_at_once, bool(args.compile))


def _engines(args: argparse.Namespace):
    """The torch engine `--engine torch` flies in this process (the bundle rebuilt in torch), or None; and what each
    worker flies with (`sweep.run.WorkerEngine`): each Ray actor, the torch engine on a GPU, or 1/K of one, with
    `--device cuda`; each of `--engine torch --workers K`'s processes, the torch engine in 1/K of the device's
    memory (one torch thread each on a CPU unless `--threads`)."""
    from golfflight.flight.bundle_location import model_dir
    from golfflight.sweep.run import WorkerEngine

    if args.engine == "torch" and args.workers is not None:
        from golfflight.flight.devices import resolve_device

        resolve_device(args.device or "cpu")  # refused here in one line, not in each worker's start
        return None, WorkerEngine(_torch_maker(args, args.threads or 1, args.workers))
    if args.engine == "torch":
        from golfflight.sweep.engines import PIECES_IN_FLIGHT

        return _torch_maker(args, args.threads, PIECES_IN_FLIGHT)(model_dir(args.model).resolve()), WorkerEngine()
    if _torch_on_ray(args):
        sharing = args.actors_per_gpu or 1
        gpus = 1 / sharing if args.device == "cuda" else 0
        return None, WorkerEngine(_torch_maker(args, args.threads or 1, sharing), gpus)
    return None, WorkerEngine()


def run(args: argparse.Namespace) -> int:
    try:
        from golfflight.sweep.run import run_sweep
        from golfflight.sweep.sources import open_source
        from golfflight.sweep.stopping import Interrupted, stopped_by_signals
    except ImportError as missing:  # an install without the sweep package
        raise InputError(f"needs the sweep extra: pip install 'golfflight[sweep]' ({missing})") from None
    require_extras("sweep", *({"ray": ["ray"], "torch": ["train"]}.get(args.engine, [])))
    _check_options(args)
    if _torch_on_ray(args):
        require_extras("train", who="--engine ray --device needs")
    torch_anywhere = args.engine == "torch" or _torch_on_ray(args)
    on_gpu = (args.device or "cpu").startswith("cuda")
    chunk_rows = args.chunk_rows or (TORCH_CHUNK_ROWS["cuda" if on_gpu else "cpu"] if torch_anywhere else CHUNK_ROWS)
    source = open_source(args.launches, args.grid, chunk_rows)
    torch_engine, worker_engine = _engines(args)
    workers = 1 if torch_engine is not None else args.workers or (None if worker_engine.gpus else os.cpu_count() or 1)
    try:
        with stopped_by_signals():
            summary = run_sweep(
                source,
                args.out,
                args.engine,
                workers,
                args.model,
                args.ray_address,
                args.skip_bad_rows,
                progress=not args.no_progress,
                skipped=lambda problem: print(f"golfflight sweep: skipped: {problem}", file=sys.stderr),
                in_process=torch_engine,
                worker_engine=worker_engine,
                notice=lambda line: print(f"golfflight sweep: {line}", file=sys.stderr),
            )
    except Interrupted as stop:
        print(f"golfflight sweep: stopped by {stop.name}: nothing written to {args.out}, no temporary file or worker "
              "left", file=sys.stderr)
        return stop.status
    whole = (
        f", {summary.chunks_skipped:,} of {summary.chunks:,} chunks skipped whole for want of a valid row"
        if summary.chunks_skipped
        else ""
    )
    dtype = args.dtype or "float32"
    if torch_engine is not None:
        where = f"({torch_engine.device}, {dtype})"
    else:
        where = f"with {workers} workers" if workers else f"with {args.actors_per_gpu or 1} actors a GPU"
        where += f" (torch on {args.device or 'cpu'}, {dtype})" if worker_engine.make else ""
    print(
        f"golfflight sweep: {summary.written:,} shots written to {args.out} ({summary.skipped:,} rows skipped{whole}, "
        f"{summary.failed:,} could not be flown) in {summary.seconds:.1f} s: {summary.shots_per_second:,.0f} shots/s "
        f"on {args.engine} {where}"
    )
    if torch_engine is not None:
        spent = torch_engine.seconds
        ground = f"torch on {torch_engine.device}" if torch_engine.ground_on_device else "NumPy on the CPU"
        print(f"golfflight sweep: torch flight {spent['flight']:.2f} s on {torch_engine.device}; the launches and air "
              f"{spent['prepare']:.2f} s on the CPU and the ground phase {spent['ground']:.2f} s ({ground}); "
              f"seconds summed over the {torch_engine.parts_at_once} pieces flown at once, beside the driver reading, "
              "validating and writing rows")
    return 0
