"""Shared pieces of the benchmark scripts: the shots, percentiles, machine info, the table, and the results file a
run names (`--results FILE`; none named: printed only, nothing written)."""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import os
import platform
import statistics
import sys
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from golfflight.flight.engine import Launch
from golfflight.shots.clubs import CLUBS

TRACKED_RESULTS = REPO / "benchmarks" / "results.json"
"""The figures the docs quote, tracked in git: a run writes them only when it names this file (`--results`)."""

SEVEN_IRON = Launch(55.0, 16.0, 0.0, 7100.0, 0.0)
"""The single shot timed: a tour-average 7-iron (the shipped model lands it after 6.2 s, 62 Euler steps)."""

DRIVER = Launch(76.5, 10.5, 0.0, 2550.0, 0.0)
"""A tour-average drive (the shipped model lands it after 6.8 s, 69 steps): the longest common single shot."""

PAPER = {
    "single_ms": 34.9,
    "batch_us_per_shot": 348.0,
    "machine": "Intel i7-11850H (8 cores), the paper's Table 2, Phys-NN+ on the CPU",
}


def mixed_launches(n: int, seed: int = 0) -> list[Launch]:
    """n launches scattered around every club's tour average (the batch a range session would send)."""
    rng = np.random.default_rng(seed)
    clubs = rng.integers(0, len(CLUBS), n)
    return [
        Launch(
            CLUBS[c].ball_speed_mps * rng.normal(1.0, 0.04),
            CLUBS[c].launch_angle_deg + rng.normal(0.0, 1.5),
            rng.normal(0.0, 2.0),
            CLUBS[c].spin_rpm * rng.normal(1.0, 0.1),
            rng.normal(0.0, 8.0),
        )
        for c in clubs
    ]


def percentiles_ms(seconds: list[float]) -> dict[str, float]:
    p50, p95, p99 = np.percentile(np.asarray(seconds) * 1e3, [50, 95, 99])
    return {"p50_ms": float(p50), "p95_ms": float(p95), "p99_ms": float(p99), "n": len(seconds)}


def median_of_rounds(rounds: list[dict[str, float]]) -> dict[str, float]:
    """Each figure's median over repeated rounds (the machine is shared: single rounds are noisy)."""
    keys = [k for k in rounds[0] if k != "n"]
    summary = {k: statistics.median(r[k] for r in rounds) for k in keys}
    summary["rounds"] = len(rounds)
    summary["n_per_round"] = rounds[0].get("n")
    return summary


def _version(distribution: str) -> str | None:
    """An installed distribution's version, None where it is missing (a lent GPU machine has no fastapi or uvicorn,
    and the benchmarks that run there do not need them)."""
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return None


def machine() -> dict:
    cpu = platform.processor()
    try:
        with open("/proc/cpuinfo") as info:
            cpu = next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average_1_5_15": list(os.getloadavg()),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        **{name: _version(name) for name in ("onnxruntime", "fastapi", "uvicorn")},
        "openblas_env": {k: v for k, v in os.environ.items() if k.startswith("OPENBLAS_")},
        "measured_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def add_results_flag(parser: argparse.ArgumentParser, tracked: Path | None = TRACKED_RESULTS) -> None:
    """`--results FILE`: where the run is written; without it the run prints its table and writes nothing, so a
    tracked file of figures (`tracked`: TRACKED_RESULTS, or a script's own file) changes only when a run names it."""
    quoted = f" ({tracked.relative_to(REPO)}: the tracked figures the docs quote)" if tracked is not None else ""
    parser.add_argument(
        "--results", type=Path, metavar="FILE",
        help=f"write this run's figures to FILE{quoted}; default: print only, write nothing",
    )


def read_results(path: Path | None) -> dict:
    """The sections a results file holds (none: no file named, or none there yet)."""
    return json.loads(path.read_text()) if path is not None and path.is_file() else {}


def save_results(path: Path | None, data: dict) -> None:
    """Write every section to the results file named, or say that nothing was written when none is."""
    if path is None:
        print("results not written (--results FILE writes them)", flush=True)
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=2) + "\n")


def write_results(section: str, rows: list[dict], path: Path | None) -> None:
    """Merge one script's rows into the results file named (each script owns its section); none named: nothing."""
    data = read_results(path)
    data[section] = {"machine": machine(), "paper": PAPER, "rows": rows}
    save_results(path, data)


def print_table(title: str, rows: list[dict]) -> None:
    """| measurement | p50 | p99 | target | paper | ratio | met |, as in docs/service.md."""
    print(f"\n{title}\n")
    print("| measurement | p50 | p99 | target | paper (Table 2) | paper / p50 | met |")
    print("|---|---:|---:|---|---:|---:|---|")
    for row in rows:
        paper = f"{row['paper']:g} {row['unit']}" if row.get("paper") else ""
        ratio = f"{row['paper'] / row['p50']:.0f}x" if row.get("paper") else ""
        p99 = f"{row['p99']:.3g} {row['unit']}" if row.get("p99") is not None else ""
        met = "yes" if row["met"] else "NO"
        print(
            f"| {row['name']} | {row['p50']:.3g} {row['unit']} | {p99} | {row['target']} | {paper} | {ratio} | {met} |"
        )
