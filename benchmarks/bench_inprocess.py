"""In-process speed of the engine: one shot, a batch of 1024, model load. Prints a table; --results FILE writes it.

python benchmarks/bench_inprocess.py [--model DIR] [--rounds 5] [--shots 2000] [--results FILE]
(Benchmark with OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE unset where they are set: they slow NumPy.)
"""

from __future__ import annotations

import argparse
import statistics
import time

from common import (
    DRIVER,
    PAPER,
    SEVEN_IRON,
    add_results_flag,
    median_of_rounds,
    mixed_launches,
    percentiles_ms,
    print_table,
    write_results,
)
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import BATCH_THREADS, FlightEngine, FlightProblem


def timed(call, repeats: int, warmup: int = 1) -> list[float]:
    """Wall-clock seconds of `repeats` calls, after `warmup` untimed ones."""
    for _ in range(warmup):
        call()
    timings = []
    for _ in range(repeats):
        started = time.perf_counter()
        call()
        timings.append(time.perf_counter() - started)
    return timings


def time_single(engine: FlightEngine, launch, shots: int) -> dict:
    return percentiles_ms(timed(lambda: engine.fly(FlightProblem.of([launch])), shots, warmup=100))


def time_batch(engine: FlightEngine, launches, repeats: int) -> list[float]:
    return timed(lambda: engine.fly_batch(FlightProblem.of(launches)).shots(), repeats)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    parser.add_argument("--rounds", type=int, default=5, help="repeated rounds; the table shows their medians")
    parser.add_argument("--shots", type=int, default=2000, help="single shots timed per round and club")
    parser.add_argument("--batch-threads", type=int, default=BATCH_THREADS, help="ORT threads of a batch step")
    add_results_flag(parser)
    args = parser.parse_args()
    bundle = model_dir(args.model)

    loads = []
    for _ in range(args.rounds):
        started = time.perf_counter()
        engine = FlightEngine(bundle, args.batch_threads)
        loads.append(time.perf_counter() - started)

    seven = median_of_rounds([time_single(engine, SEVEN_IRON, args.shots) for _ in range(args.rounds)])
    drive = median_of_rounds([time_single(engine, DRIVER, args.shots) for _ in range(args.rounds)])
    launches = mixed_launches(1024)
    batch_rounds = [time_batch(engine, launches, 5) for _ in range(args.rounds)]
    per_shot_us = [statistics.median(r) / 1024 * 1e6 for r in batch_rounds]
    worst_us = [max(r) / 1024 * 1e6 for r in batch_rounds]

    rows = [
        {
            "name": "single shot, 7-iron (in process)",
            "unit": "ms",
            "p50": seven["p50_ms"],
            "p99": seven["p99_ms"],
            "target": "p50 <= 0.4 ms, p99 <= 1.5 ms",
            "paper": PAPER["single_ms"],
            "met": seven["p50_ms"] <= 0.4 and seven["p99_ms"] <= 1.5 and PAPER["single_ms"] / seven["p50_ms"] >= 85,
        },
        {
            "name": "single shot, driver (in process)",
            "unit": "ms",
            "p50": drive["p50_ms"],
            "p99": drive["p99_ms"],
            "target": "(context)",
            "paper": PAPER["single_ms"],
            "met": True,
        },
        {
            "name": f"batch of 1024, per shot (in process, {args.batch_threads} ORT thread(s))",
            "unit": "us",
            "p50": statistics.median(per_shot_us),
            "p99": statistics.median(worst_us),
            "target": "<= 40 us/shot",
            "paper": PAPER["batch_us_per_shot"],
            "met": statistics.median(per_shot_us) <= 40,
        },
        {
            "name": "model load (bundle check + 2 ORT sessions + warm-up)",
            "unit": "ms",
            "p50": statistics.median(loads) * 1e3,
            "p99": max(loads) * 1e3,
            "target": "<= 1000 ms",
            "met": max(loads) <= 1.0,
        },
    ]
    print_table(
        f"In process, {args.rounds} rounds (medians of the rounds' p50 and p99; batch p99 = slowest of 5 runs)", rows
    )
    write_results("in_process", rows, args.results)


if __name__ == "__main__":
    main()
