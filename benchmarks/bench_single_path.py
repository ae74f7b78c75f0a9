"""The single shot's float loop (`FlightEngine.fly`) against the same shot through the one batch integrator
(`flight.integrator.integrate` on [1]-row arrays), interleaved in one process: issue 58 keeps the float loop beside
`integrate` only if flying one shot through `integrate` costs more than 5 %.

Three ways to fly one shot, each timed in blocks of `--shots` calls (the block's median), the ways in turn and their
order reversed every block, so each block of one way has a block of the others beside it in time:
- float loop: `FlightEngine.fly` of the launch's problem, the served single shot (floats, the graph bound once, one
  thread);
- integrate: `Flyer.flight` of the launch's [1]-row state, the integrator's Flight (landing, apex, times) alone;
- Flyer batch of one: `Flyer.fly_batch` of the launch's problem, `.shots()[0]`, what the engine would serve through
  the batch path.
The ratio of each block's median to the float loop's beside it is taken, and the median of the ratios reported.

python benchmarks/bench_single_path.py [--blocks 20] [--shots 200] [--results FILE]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np
from common import DRIVER, SEVEN_IRON, add_results_flag, write_results
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine, FlightProblem, Launch
from golfflight.flight.physics import initial_state

WAYS = ("float loop", "integrate", "Flyer batch of one")


def ways_to_fly(engine: FlightEngine, launch: Launch) -> dict:
    """Each way to fly `launch` as a call of no arguments."""
    start = initial_state(*(np.array([value], dtype=float) for value in launch))
    return {
        "float loop": lambda: engine.fly(FlightProblem.of([launch]))[0],
        "integrate": lambda: engine.flyer.flight(FlightProblem(start)),
        "Flyer batch of one": lambda: engine.flyer.fly_batch(FlightProblem.of([launch])).shots()[0],
    }


def block_ms(call, shots: int) -> float:
    """The median of `shots` timed calls (ms)."""
    times = []
    for _ in range(shots):
        started = time.perf_counter()
        call()
        times.append(time.perf_counter() - started)
    return statistics.median(times) * 1e3


def interleaved(calls: dict, blocks: int, shots: int) -> dict[str, list[float]]:
    """Each way's block medians (ms), the ways in turn, their order reversed every other block."""
    for call in calls.values():
        block_ms(call, 20)
    medians: dict[str, list[float]] = {way: [] for way in calls}
    for block in range(blocks):
        for way in (WAYS if block % 2 == 0 else WAYS[::-1]):
            medians[way].append(block_ms(calls[way], shots))
    return medians


def rows_of(name: str, medians: dict[str, list[float]]) -> list[dict]:
    """One row a way: its median block (ms) and its median ratio to the float loop's block beside it."""
    loop = medians["float loop"]
    return [{"shot": name, "way": way, "median_ms": statistics.median(values),
             "ratio_to_float_loop": statistics.median(v / f for v, f in zip(values, loop, strict=True)),
             "blocks": len(values)} for way, values in medians.items()]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=20, help="blocks of each way")
    parser.add_argument("--shots", type=int, default=200, help="timed calls a block (the block's median)")
    add_results_flag(parser)
    args = parser.parse_args()
    engine = FlightEngine(model_dir())
    load_before = os.getloadavg()
    rows = []
    for name, launch in (("7-iron", SEVEN_IRON), ("driver", DRIVER)):
        rows += rows_of(name, interleaved(ways_to_fly(engine, launch), args.blocks, args.shots))
    load_after = os.getloadavg()
    print(f"\nOne shot three ways, {args.blocks} blocks of {args.shots} (load average {load_before[0]:.1f} before, "
          f"{load_after[0]:.1f} after)\n")
    print("| shot | way | median of block medians | ratio to the float loop (median of blocks) |")
    print("|---|---|---:|---:|")
    for row in rows:
        print(f"| {row['shot']} | {row['way']} | {row['median_ms']:.3f} ms | {row['ratio_to_float_loop']:.2f} |")
    write_results("single_path", rows, args.results)


if __name__ == "__main__":
    main()
