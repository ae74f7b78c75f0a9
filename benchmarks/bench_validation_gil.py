"""Where a 10,000-shot batch body can be validated without stalling the event loop (issue 55): on the loop itself, or
in a thread beside it (pydantic-core holds the GIL while it validates, so a thread may stall the loop as well). The
batch process, the third place, is measured by `bench_batch_load.py` and `tests/test_batch_off_loop.py`.

python benchmarks/bench_validation_gil.py [--rounds 3] [--results FILE]

An asyncio ticker sleeps 1 ms at a time and records how late each wake-up is, while `contract.batch_body.read_batch`
reads an invalid body (`{"ball_speed_mps": 500, ...}` x 10,000: json.loads, the model and 20 problems described)
or a valid one, `--rounds` times, on the loop or in `asyncio.to_thread`, the two alternating. Prints the worst
lateness and the time per body; with --results FILE, writes them to FILE, and without it writes nothing. The tracked
figures the docs quote are benchmarks/validation_gil.json; a run of record names it:
`--results benchmarks/validation_gil.json`.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import time

from common import REPO, add_results_flag, machine, save_results
from golfflight.contract.batch_body import read_batch
from golfflight.contract.refusals import RequestRefused

TRACKED_FILE = REPO / "benchmarks" / "validation_gil.json"
"""This script's figures that docs/reliability.md quotes: written only by a run that names it (--results)."""
SHOT = {"launch_angle_deg": 12.0, "spin_rpm": 3000.0}
BODIES = {
    "invalid": json.dumps({"shots": [{**SHOT, "ball_speed_mps": 500.0}] * 10_000}).encode(),
    "valid": json.dumps({"shots": [{**SHOT, "ball_speed_mps": 50.0}] * 10_000}).encode(),
}


def read(body: bytes) -> None:
    try:
        read_batch(body)
    except RequestRefused:
        pass


async def ticker(stop: asyncio.Event, lateness: list[float]) -> None:
    while not stop.is_set():
        started = time.perf_counter()
        await asyncio.sleep(0.001)
        lateness.append(time.perf_counter() - started - 0.001)


async def trial(where: str, body: bytes, rounds: int) -> dict:
    """The ticker's worst lateness while `body` is read `rounds` times `where` ("loop" or "thread")."""
    stop, lateness = asyncio.Event(), []
    ticking = asyncio.create_task(ticker(stop, lateness))
    await asyncio.sleep(0.05)
    started = time.perf_counter()
    for _ in range(rounds):
        if where == "loop":
            read(body)
            await asyncio.sleep(0.002)  # the ticker runs between two bodies: the stall is one body's
        else:
            await asyncio.to_thread(read, body)
    each_ms = (time.perf_counter() - started) / rounds * 1e3
    stop.set()
    await ticking
    return {"worst_stall_ms": round(max(lateness) * 1e3, 1), "ms_per_body": round(each_ms, 1)}


async def run(rounds: int) -> list[dict]:
    rows = []
    for kind, body in BODIES.items():
        for repeat in range(2):
            for where in ("loop", "thread"):
                rows.append({"body": kind, "where": where, "repeat": repeat, **await trial(where, body, rounds)})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    add_results_flag(parser, TRACKED_FILE)
    args = parser.parse_args()
    rows = asyncio.run(run(args.rounds))
    print(f"{'body':8} {'where':7} {'worst loop stall ms':>20} {'ms per body':>12}")
    for row in rows:
        print(f"{row['body']:8} {row['where']:7} {row['worst_stall_ms']:>20.1f} {row['ms_per_body']:>12.1f}")
    save_results(args.results, {"script": "benchmarks/bench_validation_gil.py", "machine": machine(), "rows": rows})


if __name__ == "__main__":
    main()
