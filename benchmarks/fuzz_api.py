"""Fuzzing campaign against the service's own OpenAPI schema: schemathesis (every route, valid and invalid data,
every check but one) plus raw malformed bodies, against `golfflight serve` on 127.0.0.1. Bounded in cases and time.

python benchmarks/fuzz_api.py [--examples 250] [--max-time 300] [--raw 2000] [--seed 1] [--workers 1]

Prints the figures and with --results FILE writes its "fuzz" section
there (benchmarks/results.json: the tracked figures docs/reliability.md quotes).
"""

from __future__ import annotations

import argparse
import json
import random
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import httpx
import server as serving
from common import add_results_flag, machine, read_results, save_results

EXCLUDED_CHECKS = ["positive_data_acceptance"]
"""Two cross-field rules cannot be written in JSON Schema (back and side spin together within 15,000 rpm; a GSPro
shot needs Speed, VLA and a spin): schema-valid requests breaking them are rightly refused."""

POST_ROUTES = ("/v1/shots", "/v1/shots/batch", "/v1/gspro")
SHOT = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}


def run_schemathesis(base_url: str, examples: int, max_time: int, seed: int, report: Path) -> dict:
    """One `schemathesis run` over every operation; its JSON report."""
    command = [
        sys.executable, "-m", "schemathesis.cli", "run", f"{base_url}/openapi.json",
        "--checks", "all", "--exclude-checks", ",".join(EXCLUDED_CHECKS),
        "--max-examples", str(examples), "--max-time", str(max_time), "--seed", str(seed),
        "--workers", "1", "--generation-database", "none", "--no-color",
        "--request-timeout", "30", "--report", "json", "--report-json-path", str(report),
    ]  # fmt: skip
    finished = subprocess.run(command, capture_output=True, text=True, timeout=max_time + 120)
    print(finished.stdout[-4000:])
    return json.loads(report.read_text())


def raw_bodies(rng: random.Random, n: int) -> list[tuple[str, bytes, str]]:
    """(route, body, content type) of malformed requests a flaky network or a broken client sends."""
    valid = json.dumps(SHOT).encode()
    makers = [
        lambda: bytes(rng.randrange(256) for _ in range(rng.randrange(1, 300))),
        lambda: valid[: rng.randrange(len(valid))],
        lambda: b"[" * rng.choice([100, 10_000, 100_000]) + b"]" * rng.choice([0, 100]),
        lambda: b'{"ball_speed_mps": 1' + b"0" * rng.choice([400, 5000]) + b', "launch_angle_deg": 10, "spin_rpm": 1}',
        lambda: b'{"ball_speed_mps": 55, "ball_speed_mps": "x", "launch_angle_deg": 16, "spin_rpm": 7100}',
        lambda: json.dumps({**SHOT, "launch_angle_deg": rng.choice(["NaN", "Infinity", "55"])}).encode(),
        lambda: valid.replace(b"16.0", rng.choice([b"NaN", b"Infinity", b"-Infinity", b"1e999", b"\x00"])),
        lambda: json.dumps({"shots": [SHOT] * rng.randrange(0, 3) + [rng.choice([None, 1, "x", [], {}])]}).encode(),
        lambda: json.dumps({"x" * rng.randrange(1, 5000): SHOT}).encode(),
        lambda: "é€😀\u0000".encode() * rng.randrange(1, 50),
    ]
    json_type = "application/json"
    types = [json_type, json_type, json_type, "text/plain", "application/x-www-form-urlencoded", ""]
    return [(rng.choice(POST_ROUTES), rng.choice(makers)(), rng.choice(types)) for _ in range(n)]


def run_raw(base_url: str, n: int, seed: int, max_time: float) -> dict:
    """Send `n` malformed bodies (bounded by `max_time`); status counts and every 5xx or non-JSON answer."""
    statuses: Counter[int] = Counter()
    problems: list[str] = []
    deadline = time.monotonic() + max_time
    with httpx.Client(base_url=base_url, timeout=30) as client:
        for route, body, content_type in raw_bodies(random.Random(seed), n):
            if time.monotonic() > deadline:
                break
            headers = {"content-type": content_type} if content_type else {}
            response = client.post(route, content=body, headers=headers)
            statuses[response.status_code] += 1
            if response.status_code >= 500 or "json" not in response.headers.get("content-type", ""):
                problems.append(f"{route} {response.status_code} for {body[:80]!r}")
        alive = client.post("/v1/shots", json=SHOT).status_code == 200
    return {"sent": sum(statuses.values()), "statuses": dict(sorted(statuses.items())), "problems": problems[:20],
            "server_fine_afterwards": alive}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=250, help="schemathesis examples per operation and phase")
    parser.add_argument("--max-time", type=int, default=300, help="seconds for the schemathesis run at most")
    parser.add_argument("--raw", type=int, default=2000, help="malformed raw bodies to send")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    add_results_flag(parser)
    args = parser.parse_args()
    if not 0 < args.max_time <= 3600 or not 0 <= args.raw <= 100_000:
        parser.error("--max-time must be 1..3600 s and --raw 0..100000: the campaign is bounded")
    running = serving.start(args.workers, args.model)
    try:
        memory_before = running.rss_mib()
        with tempfile.TemporaryDirectory() as scratch:
            report = run_schemathesis(running.base_url, args.examples, args.max_time, args.seed,
                                      Path(scratch) / "schemathesis.json")
        raw = run_raw(running.base_url, args.raw, args.seed, max_time=300)
        memory_after = running.rss_mib()
    finally:
        code, seconds = running.stop()
    result = {
        "machine": machine(),
        "settings": vars(args) | {"excluded_checks": EXCLUDED_CHECKS},
        "schemathesis": {
            "version": report["schemathesis_version"],
            "seed": report["seed"],
            "seconds": round(report["running_time"], 1),
            "stop_reason": report["stop_reason"],
            "operations_tested": report["operations"]["tested"],
            "cases": report["test_cases"]["generated"],
            "cases_with_failures": report["test_cases"]["with_failures"],
            "failures": report["failures"],
            "errors": report["errors"],
            "valid_rates": report["valid_rates"],
        },
        "raw": raw,
        "server_rss_mib": {"before": round(memory_before["total"], 1), "after": round(memory_after["total"], 1)},
        "shutdown": {"exit_code": code, "seconds": round(seconds, 2)},
    }
    print(json.dumps({k: v for k, v in result.items() if k not in ("machine",)}, indent=1)[:6000])
    data = read_results(args.results)
    data["fuzz"] = result
    save_results(args.results, data)
    sys.exit(0 if not report["failures"] and not raw["problems"] and raw["server_fine_afterwards"] else 1)


if __name__ == "__main__":
    main()
