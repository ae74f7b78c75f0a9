"""What moving batch validation into the batch process costs a batch (issue 55): two `golfflight serve`s, one of
--before DIR (e.g. `git archive main | tar -x -C DIR`) and one of this checkout, each sent the same valid batches in
turn, interleaved (before, after, before, ...), so that the machine's load falls on both alike.

python benchmarks/bench_batch_ab.py --before DIR [--rounds 20] [--results FILE]

Prints each batch size's median seconds on each server and their ratio (after / before); with --results FILE, writes
them, with the machine and its load, to FILE, and without it writes nothing. The tracked figures the docs quote are
benchmarks/batch_ab.json; a run of record names it: `--results benchmarks/batch_ab.json`.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

import httpx
from bench_hostile import start_service
from common import REPO, add_results_flag, machine, save_results

TRACKED_FILE = REPO / "benchmarks" / "batch_ab.json"
"""This script's figures that docs/reliability.md quotes: written only by a run that names it (--results)."""
SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
SIZES = (100, 1_000, 10_000)


def timed_post(http: httpx.Client, body: bytes) -> float:
    started = time.perf_counter()
    answer = http.post("/v1/shots/batch", content=body, headers={"content-type": "application/json"})
    assert answer.status_code == 200, answer.text[:200]
    return time.perf_counter() - started


def run(before: Path, rounds: int) -> list[dict]:
    servers = {"before": start_service(before), "after": start_service(REPO)}
    bodies = {size: json.dumps({"shots": [SEVEN_IRON] * size}).encode() for size in SIZES}
    seconds = {(label, size): [] for label in servers for size in SIZES}
    load_before = os.getloadavg()[0]
    try:
        clients = {label: httpx.Client(base_url=url, timeout=300) for label, (_, url, _) in servers.items()}
        for label, client in clients.items():  # warm-up: each size once
            for body in bodies.values():
                timed_post(client, body)
        for _ in range(rounds):
            for size, body in bodies.items():
                for label, client in clients.items():
                    seconds[(label, size)].append(timed_post(client, body))
    finally:
        for process, _, _ in servers.values():
            process.terminate()
            process.wait(60)
    rows = []
    for size in SIZES:
        before_s, after_s = (statistics.median(seconds[(label, size)]) for label in ("before", "after"))
        rows.append({"shots": size, "rounds": rounds, "before_median_ms": round(before_s * 1e3, 2),
                     "after_median_ms": round(after_s * 1e3, 2), "after_over_before": round(after_s / before_s, 3),
                     "load_average_1m_at_start": round(load_before, 2)})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", type=Path, required=True, help="the checkout to compare with")
    parser.add_argument("--rounds", type=int, default=20)
    add_results_flag(parser, TRACKED_FILE)
    args = parser.parse_args()
    rows = run(args.before, args.rounds)
    print(f"{'shots':>7} {'before ms':>10} {'after ms':>10} {'after/before':>13}")
    for row in rows:
        print(f"{row['shots']:>7,} {row['before_median_ms']:>10.1f} {row['after_median_ms']:>10.1f} "
              f"{row['after_over_before']:>13.3f}")
    save_results(args.results, {"script": "benchmarks/bench_batch_ab.py", "machine": machine(), "rows": rows})


if __name__ == "__main__":
    main()
