"""HTTP speed over loopback: `golfflight serve` in a subprocess, a keep-alive httpx client. Table; --results FILE.

python benchmarks/bench_http.py [--model DIR] [--rounds 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

import httpx
from common import (
    PAPER,
    SEVEN_IRON,
    add_results_flag,
    median_of_rounds,
    mixed_launches,
    percentiles_ms,
    print_table,
    write_results,
)
from server import start

SHOT = {
    "ball_speed_mps": SEVEN_IRON.ball_speed_mps,
    "launch_angle_deg": SEVEN_IRON.launch_angle_deg,
    "spin_rpm": SEVEN_IRON.spin_rpm,
}


def time_requests(client: httpx.Client, path: str, body: dict, n: int) -> list[float]:
    timings = []
    for _ in range(n):
        started = time.perf_counter()
        response = client.post(path, json=body)
        response.json()
        timings.append(time.perf_counter() - started)
        assert response.status_code == 200, response.text
    return timings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    parser.add_argument("--rounds", type=int, default=5)
    add_results_flag(parser)
    args = parser.parse_args()
    server = start(1, args.model)
    batch = {"shots": [launch._asdict() for launch in mixed_launches(1024)]}
    try:
        with httpx.Client(base_url=server.base_url, timeout=60) as client:
            time_requests(client, "/v1/shots", SHOT, 300)
            single = median_of_rounds(
                [percentiles_ms(time_requests(client, "/v1/shots", SHOT, 2000)) for _ in range(args.rounds)]
            )
            time_requests(client, "/v1/shots/batch", batch, 2)
            batch_rounds = [time_requests(client, "/v1/shots/batch", batch, 5) for _ in range(args.rounds)]
            server_side = client.get("/v1/latency").json()
    finally:
        server.stop()
    batch_ms = statistics.median(statistics.median(r) for r in batch_rounds) * 1e3
    batch_worst = statistics.median(max(r) for r in batch_rounds) * 1e3
    rows = [
        {
            "name": "single shot over HTTP, keep-alive (7-iron)",
            "unit": "ms",
            "p50": single["p50_ms"],
            "p99": single["p99_ms"],
            "target": "p50 <= 1.5 ms, p99 <= 4 ms",
            "paper": PAPER["single_ms"],
            "met": single["p50_ms"] <= 1.5 and single["p99_ms"] <= 4,
        },
        {
            "name": "batch of 1024 over HTTP, end to end",
            "unit": "ms",
            "p50": batch_ms,
            "p99": batch_worst,
            "target": "<= 100 ms",
            "paper": PAPER["batch_us_per_shot"] * 1024 / 1000,
            "met": batch_ms <= 100,
        },
    ]
    print_table(f"HTTP over loopback, {args.rounds} rounds (batch p99 = slowest of 5 runs, median over rounds)", rows)
    print(
        "\nserver side (GET /v1/latency, whole window):"
        f" simulation {server_side['simulation']}, request {server_side['request']}"
    )
    write_results("http", rows, args.results)


if __name__ == "__main__":
    main()
