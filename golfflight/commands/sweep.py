"""`golfflight sweep`: fly a file of launches, or a grid of them, into a Parquet file of results (docs/sweep.md).

Input: a CSV or Parquet file with `golfflight simulate`'s CSV columns, or `--grid COLUMN=SPEC ...` (a cartesian
product: START:STOP:COUNT, V1,V2,... or V per column, `sweep.grid`). Output: one row per input row, its number
(`row`), its columns and its flight, the same numbers as `golfflight simulate`. `--engine local` flies on a pool of
processes here, `--engine ray` through Ray Data (a local Ray instance, or a cluster's with `--ray-address`).
Needs the `sweep` extra (pyarrow, tqdm), and the `ray` extra for `--engine ray`.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

EXTRAS = {"sweep": ("pyarrow", "tqdm"), "ray": ("ray.data",)}
"""The modules each extra brings: the serving install (`pip install .`, the Docker image) has none of them."""

CHUNK_ROWS = 8192
"""Shots a worker flies in one engine batch: large enough that the per-step ONNX call is spread over many shots."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("sweep", help="fly a file or grid of launches into a Parquet file (local or Ray)")
    parser.add_argument("launches", nargs="?", help="CSV or Parquet file of launches (simulate's CSV columns)")
    parser.add_argument(
        "--grid", nargs="+", metavar="COLUMN=SPEC",
        help="instead of a file: the cartesian product of COLUMN=START:STOP:COUNT, COLUMN=V1,V2,... or COLUMN=V",
    )
    parser.add_argument("--out", required=True, help="the results' Parquet file (written whole or not at all)")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.add_argument("--engine", choices=("local", "ray"), default="local", help="local processes or Ray Data")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="processes or Ray actors (default: "
                        "this machine's cores)")
    parser.add_argument("--chunk-rows", type=int, default=CHUNK_ROWS, help=f"shots a batch (default {CHUNK_ROWS})")
    parser.add_argument("--ray-address", help="an existing Ray cluster (e.g. ray://head:10001 or auto); default: a "
                        "local Ray instance, stopped after")
    parser.add_argument(
        "--skip-bad-rows", action="store_true", help="fly the valid rows and list each invalid one instead of refusing"
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on standard error")
    parser.set_defaults(run=run)


def require_extras(*extras: str) -> None:
    """Refuse in one line, naming the extra to install, unless every module of `extras` imports (a missing one would
    otherwise surface as a ModuleNotFoundError's traceback in the middle of the sweep)."""
    for extra in extras:
        for module in EXTRAS[extra]:
            try:
                importlib.import_module(module)
            except ImportError as missing:
                who = "--engine ray needs" if extra == "ray" else "needs"
                raise ValueError(
                    f"{who} the {extra} extra, which is not installed (no {missing.name or module}): "
                    f"pip install 'golfflight[{extra}]'"
                ) from None


def run(args: argparse.Namespace) -> int:
    try:
        from golfflight.sweep.run import run_sweep
        from golfflight.sweep.sources import open_source
    except ImportError as missing:  # an install without the sweep package
        raise ValueError(f"needs the sweep extra: pip install 'golfflight[sweep]' ({missing})") from None
    require_extras("sweep", *(["ray"] if args.engine == "ray" else []))

    if args.workers < 1 or args.chunk_rows < 1:
        raise ValueError("--workers and --chunk-rows take a whole number of at least 1")
    if args.ray_address and args.engine != "ray":
        raise ValueError("--ray-address goes with --engine ray")
    source = open_source(args.launches, args.grid, args.chunk_rows)
    summary = run_sweep(
        source,
        args.out,
        args.engine,
        args.workers,
        args.model,
        args.ray_address,
        args.skip_bad_rows,
        progress=not args.no_progress,
        skipped=lambda problem: print(f"golfflight sweep: skipped: {problem}", file=sys.stderr),
    )
    whole = (
        f", {summary.chunks_skipped:,} of {summary.chunks:,} chunks skipped whole for want of a valid row"
        if summary.chunks_skipped
        else ""
    )
    print(
        f"golfflight sweep: {summary.written:,} shots written to {args.out} ({summary.skipped:,} rows skipped{whole}, "
        f"{summary.failed:,} could not be flown) in {summary.seconds:.1f} s: {summary.shots_per_second:,.0f} shots/s "
        f"on {args.engine} with {args.workers} workers"
    )
    return 0
