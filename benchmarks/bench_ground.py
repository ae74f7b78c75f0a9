"""What the ground phase (bounce and roll to rest, flight.ground) adds to the engine: one shot and a batch of 1024,
flight alone against flight plus ground, and the ground phase alone on a driver's landing, interleaved round by
round. Times are CPU time per call (time.process_time), which a busy machine inflates far less than wall-clock time.
Prints a table; --results FILE writes it there.

python benchmarks/bench_ground.py [--model DIR] [--rounds 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

from common import (
    DRIVER,
    SEVEN_IRON,
    add_results_flag,
    median_of_rounds,
    mixed_launches,
    percentiles_ms,
    print_table,
    write_results,
)
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.constants import RPM_TO_RADPS
from golfflight.flight.engine import BATCH_THREADS, FlightEngine, FlightProblem
from golfflight.flight.ground import LEVEL_FAIRWAY, GroundSpec, ground_phase_one, surface

SLOPED_GREEN = GroundSpec(surface("green", 11.0), elevation_m=-2.0, slope_deg=1.5, slope_dir_deg=30.0)
"""A sloped ground: its roll is stepped (0.25 s midpoint steps) rather than solved in closed form."""

GROUNDS = {"flight alone": None, "level fairway": LEVEL_FAIRWAY, "sloped green": SLOPED_GREEN}


def cpu_timed(call, repeats: int, warmup: int = 1) -> list[float]:
    """CPU seconds of `repeats` calls, after `warmup` untimed ones."""
    for _ in range(warmup):
        call()
    timings = []
    for _ in range(repeats):
        started = time.process_time()
        call()
        timings.append(time.process_time() - started)
    return timings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds; the table shows their medians")
    add_results_flag(parser)
    args = parser.parse_args()
    engine = FlightEngine(model_dir(args.model), BATCH_THREADS)
    launches = mixed_launches(1024)
    landed = engine.fly_batch(FlightProblem.of([DRIVER], keep_states=True)).shots()[0]
    states, spin = landed.states, landed.landing_spin_rpm * RPM_TO_RADPS
    landing = (tuple(states.positions[-1]), tuple(states.velocities[-1]), (spin, 0.0, 0.0))
    single = {(shot, name): [] for shot in ("7-iron", "driver") for name in GROUNDS}
    alone = {name: [] for name in GROUNDS if name != "flight alone"}
    batch = {name: [] for name in ("flight alone", "level fairway")}
    for _ in range(args.rounds):
        for shot, launch in (("7-iron", SEVEN_IRON), ("driver", DRIVER)):
            for name, ground in GROUNDS.items():
                call = lambda: engine.fly(FlightProblem.of([launch], grounds=ground))  # noqa: E731
                single[shot, name].append(percentiles_ms(cpu_timed(call, 500, warmup=50)))
        for name in alone:
            g = GROUNDS[name]
            call = lambda: ground_phase_one(*landing, g.surface, g.slope_deg, g.slope_dir_deg)  # noqa: E731
            alone[name].append(percentiles_ms(cpu_timed(call, 500, warmup=50)))
        for name in batch:
            ground = GROUNDS[name]
            call = lambda: engine.fly_batch(FlightProblem.of(launches, grounds=ground)).shots()  # noqa: E731
            batch[name].append(statistics.median(cpu_timed(call, 5)))
    rows = []
    for shot in ("7-iron", "driver"):
        flight_only = median_of_rounds(single[shot, "flight alone"])
        for name in GROUNDS:
            figures = median_of_rounds(single[shot, name])
            extra = (figures["p50_ms"] - flight_only["p50_ms"]) * 1e3
            added = "" if name == "flight alone" else f", {extra:+.0f} us"
            rows.append({"name": f"single shot, {shot}, {name}{added}", "unit": "ms", "p50": figures["p50_ms"],
                         "p99": figures["p99_ms"], "target": "(context)", "met": True})
    for name, rounds in alone.items():
        figures = median_of_rounds(rounds)
        rows.append({"name": f"ground phase alone, one driver landing, {name}", "unit": "ms", "p50": figures["p50_ms"],
                     "p99": figures["p99_ms"], "target": "(context)", "met": True})
    alone_us = statistics.median(batch["flight alone"]) / 1024 * 1e6
    rolled_us = statistics.median(batch["level fairway"]) / 1024 * 1e6
    rows.append({"name": "batch of 1024, per shot, flight alone", "unit": "us", "p50": alone_us, "p99": None,
                 "target": "(context)", "met": True})
    rows.append({"name": f"batch of 1024, per shot, level fairway, {rolled_us - alone_us:+.1f} us", "unit": "us",
                 "p50": rolled_us, "p99": None, "target": "(context)", "met": True})
    print_table(f"The ground phase's cost, CPU time, {args.rounds} interleaved rounds (medians of the rounds)", rows)
    write_results("ground", rows, args.results)


if __name__ == "__main__":
    main()
