"""Load and soak test of `golfflight serve` on 127.0.0.1: many keep-alive clients, mixed single shots and batches.

python benchmarks/load_soak.py [--workers 2] [--clients 32] [--duration 60] [--load 0.3 0.5 0.7] [--batch-share 0.05]

Three phases, each bounded in time: (1) saturation, every client sending back to back, gives the throughput the
machine sustains; (2) the measured runs, an open-loop schedule at each --load fraction of that rate (or each
--rate), latency counted from each request's scheduled time (so queueing shows); memory of the supervisor and workers is taken
before and after, and sampled through the run; (3) graceful shutdown: batches in flight when SIGTERM arrives must
all complete. Prints the figures and, with --results FILE, writes the --section ("load" by default; "soak" for a long
run) there (benchmarks/results.json: the tracked figures).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import sys
import threading
import time

import numpy as np
import server as serving
from common import add_results_flag, machine, mixed_launches, read_results, save_results

MAX_DURATION_S = 3600
"""Longest measured run the script accepts (a soak); every loop below stops by itself."""

def request_bytes(path: str, body: dict) -> bytes:
    payload = json.dumps(body).encode()
    head = (
        f"POST {path} HTTP/1.1\r\nhost: 127.0.0.1\r\ncontent-type: application/json\r\n"
        f"content-length: {len(payload)}\r\n\r\n"
    )
    return head.encode() + payload


def request_pool(batch_size: int, seed: int) -> tuple[list[bytes], list[bytes]]:
    """Pre-encoded single-shot and batch requests from launches around every club's tour average."""
    launches = mixed_launches(2000 + 20 * batch_size, seed)
    shots = [launch._asdict() for launch in launches]
    singles = [request_bytes("/v1/shots", shot) for shot in shots[:2000]]
    batches = [
        request_bytes("/v1/shots/batch", {"shots": shots[2000 + i * batch_size : 2000 + (i + 1) * batch_size]})
        for i in range(20)
    ]
    return singles, batches


class Tally:
    """Latencies (s) per kind and every error seen."""

    def __init__(self):
        self.latency: dict[str, list[float]] = {"single": [], "batch": []}
        self.errors: list[str] = []

    def summary(self, seconds: float) -> dict:
        out = {"seconds": round(seconds, 1), "errors": len(self.errors), "error_examples": self.errors[:5]}
        for kind, values in self.latency.items():
            if values:
                p50, p99, p999 = (float(v) for v in np.percentile(np.array(values) * 1e3, [50, 99, 99.9]))
                out[kind] = {"requests": len(values), "per_s": round(len(values) / seconds, 1), "p50_ms": round(p50, 2),
                             "p99_ms": round(p99, 2), "p99_9_ms": round(p999, 2), "max_ms": round(max(values) * 1e3, 2)}
        return out


async def exchange(reader, writer, request: bytes) -> tuple[int, bytes]:
    writer.write(request)
    head = await reader.readuntil(b"\r\n\r\n")
    status = int(head[9:12])
    length = 0
    for line in head.split(b"\r\n")[1:]:
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"content-length":
            length = int(value)
    return status, await reader.readexactly(length)


def check(kind: str, status: int, body: bytes) -> str | None:
    """Why an answer is wrong, or None: a 200 whose numbers are all finite (single) or all flown (batch)."""
    if status != 200:
        return f"{kind}: HTTP {status} {body[:120]!r}"
    if b"NaN" in body or b"Infinity" in body or b"null" in body:
        return f"{kind}: non-finite number in {body[:120]!r}"
    if kind == "batch" and b'"error"' in body:
        return f"batch: a shot failed: {body[:160]!r}"
    return None


async def client(port: int, stop_at: float, tally: Tally, pool, share: float, rng: random.Random,
                 interval: float | None) -> None:
    """One keep-alive connection: back to back (interval None) or on its own fixed schedule (open loop)."""
    singles, batches = pool
    reader, writer = await asyncio.open_connection(serving.HOST, port)
    scheduled = time.perf_counter() + (rng.random() * interval if interval else 0.0)
    try:
        while True:
            if interval:
                delay = scheduled - time.perf_counter()
                if delay > 0:
                    await asyncio.sleep(delay)
            start = scheduled if interval else time.perf_counter()
            if time.monotonic() >= stop_at:
                break
            kind = "batch" if rng.random() < share else "single"
            request = rng.choice(batches if kind == "batch" else singles)
            try:
                status, body = await asyncio.wait_for(exchange(reader, writer, request), 60)
            except (TimeoutError, OSError, asyncio.IncompleteReadError, ValueError) as error:
                tally.errors.append(f"{kind}: {type(error).__name__}: {error}")
                writer.close()
                reader, writer = await asyncio.open_connection(serving.HOST, port)
                continue
            tally.latency[kind].append(time.perf_counter() - start)
            if problem := check(kind, status, body):
                tally.errors.append(problem)
            if interval:
                scheduled += interval
    finally:
        writer.close()


async def drive(port: int, clients: int, seconds: float, pool, share: float, seed: int,
                rate: float | None) -> Tally:
    tally = Tally()
    stop_at = time.monotonic() + seconds
    interval = clients / rate if rate else None
    await asyncio.gather(*(client(port, stop_at, tally, pool, share, random.Random(seed + i), interval)
                           for i in range(clients)))
    return tally


def sample_memory(running: serving.Server, every_s: float, stop: threading.Event, samples: list) -> None:
    started = time.monotonic()
    while not stop.wait(every_s):
        samples.append((round(time.monotonic() - started, 1), round(running.rss_mib()["total"], 1)))


def shutdown_with_batches_in_flight(running: serving.Server, pool, in_flight: int) -> dict:
    """Start `in_flight` batch requests, SIGTERM the server while they run: every one must still get its 200."""
    _, batches = pool
    outcomes: list[str | None] = []

    async def one(request: bytes) -> None:
        reader, writer = await asyncio.open_connection(serving.HOST, running.port)
        try:
            outcomes.append(check("batch", *await asyncio.wait_for(exchange(reader, writer, request), 120)))
        except (TimeoutError, OSError, asyncio.IncompleteReadError) as error:
            outcomes.append(f"{type(error).__name__}: {error}")
        finally:
            writer.close()

    async def scenario() -> tuple[int | None, float]:
        tasks = [asyncio.create_task(one(batches[i % len(batches)])) for i in range(in_flight)]
        await asyncio.sleep(0.2)  # requests sent and being served
        stopped = await asyncio.to_thread(running.stop)
        await asyncio.gather(*tasks)
        return stopped

    code, seconds = asyncio.run(scenario())
    failed = [o for o in outcomes if o]
    return {"in_flight": in_flight, "completed": len(outcomes) - len(failed), "failed": failed[:5],
            "exit_code": code, "seconds": round(seconds, 2), "clean": code in (0, -15) and not failed}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--clients", type=int, default=32, help="concurrent keep-alive connections")
    parser.add_argument("--duration", type=float, default=60.0, help="seconds of the measured run")
    parser.add_argument("--saturation", type=float, default=15.0, help="seconds of the saturation phase")
    parser.add_argument("--load", type=float, nargs="+", default=[0.3, 0.5, 0.7],
                        help="measured rates as fractions of the saturated one, one run of --duration each")
    parser.add_argument("--rate", type=float, nargs="+", help="measured rates in requests/s (instead of --load)")
    parser.add_argument("--batch-share", type=float, default=0.05, help="fraction of requests that are batches")
    parser.add_argument("--batch-size", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    parser.add_argument("--section", default="load", help="section of the --results file to write")
    add_results_flag(parser)
    args = parser.parse_args()
    if not 0 < args.duration <= MAX_DURATION_S or not 0 < args.saturation <= 600 or not 0 < args.clients <= 512:
        parser.error(f"--duration 0..{MAX_DURATION_S} s, --saturation 0..600 s, --clients 1..512: the test is bounded")
    pool = request_pool(args.batch_size, args.seed)
    running = serving.start(args.workers, args.model)
    try:
        asyncio.run(drive(running.port, args.clients, 3.0, pool, args.batch_share, args.seed, None))  # warm-up
        memory_before = running.rss_mib()
        saturated = asyncio.run(drive(running.port, args.clients, args.saturation, pool, args.batch_share,
                                      args.seed + 1000, None)).summary(args.saturation)
        total_rate = sum(saturated[k]["per_s"] for k in ("single", "batch") if k in saturated)
        rates = args.rate or [load * total_rate for load in args.load]
        samples: list = []
        stop = threading.Event()
        sampler = threading.Thread(
            target=sample_memory, args=(running, max(1.0, len(rates) * args.duration / 30), stop, samples)
        )
        sampler.start()
        measured = []
        for i, rate in enumerate(rates):
            tally = asyncio.run(drive(running.port, args.clients, args.duration, pool, args.batch_share,
                                      args.seed + 2000 + i, rate))
            measured.append({"rate_per_s": round(rate, 1), "load": round(rate / total_rate, 2),
                             **tally.summary(args.duration)})
        stop.set()
        sampler.join()
        memory_after = running.rss_mib()
    except BaseException:
        running.stop()
        raise
    shutdown = shutdown_with_batches_in_flight(running, pool, in_flight=2 * args.workers + 2)
    growth = memory_after["total"] - memory_before["total"]
    result = {
        "settings": vars(args),
        "saturated": saturated,
        "measured": measured,
        "memory_mib": {"before": round(memory_before["total"], 1), "after": round(memory_after["total"], 1),
                       "growth": round(growth, 1), "samples": samples},
        "shutdown": shutdown,
        "single_p99_under_10_ms_at_load": {
            str(run["load"]): run.get("single", {}).get("p99_ms", float("inf")) < 10.0 for run in measured
        },
    }
    print(json.dumps(result, indent=1))
    data = read_results(args.results)
    data[args.section] = {"machine": machine(), **result}
    save_results(args.results, data)
    ok = saturated["errors"] == 0 and all(run["errors"] == 0 for run in measured) and shutdown["clean"]
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
