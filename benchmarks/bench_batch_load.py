"""A connector's Open Connect shots and HTTP single shots while other clients loop 10,000-shot batches (issue 55,
item 3): do large batch bodies, valid or not, hold up the event loop everyone else is served by?

python benchmarks/bench_batch_load.py [--seconds 15] [--label after] [--tree DIR] [--results FILE]

Starts `golfflight serve --port P --connect-port Q` in a subprocess (of this checkout, or of --tree DIR: e.g.
`git archive main | tar -x -C DIR` for a before run), waits for GET /healthz, then for each scenario starts its batch
clients, each in a process of its own looping one body on a keep-alive connection (reading each answer whole), and
times, each in its own process too, for --seconds: a connector on one Open Connect connection sending a shot every
50 ms and waiting for its reply, and an HTTP client sending single shots (POST /v1/shots) every 10 ms. Scenarios:
quiet; 2 and 6 clients looping invalid batches (`{"ball_speed_mps": 500, ...}` x 10,000, 670 KB, the issue's); 2
clients looping `{"shots": [1, 1, ...]}` (10,000 entries, 20 KB); 1 client looping valid batches of 10,000 shots.

Prints a table (p50, p99, max per timed client, each p99 as a multiple of the quiet one, the batch answers' count
and size); with --results FILE, writes its rows into FILE, replacing only the rows of its --label, so the file can
hold a before and an after run; without it writes nothing. The tracked figures the docs quote are
benchmarks/batch_load.json; a run of record names it: `--results benchmarks/batch_load.json`.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import socket
import time
from pathlib import Path

import numpy as np
from bench_hostile import CONNECT_SHOT, SHOT, start_service
from common import REPO, add_results_flag, machine, read_results, save_results
from server import HOST

TRACKED_FILE = REPO / "benchmarks" / "batch_load.json"
"""This script's figures that docs/reliability.md quotes: written only by a run that names it (--results)."""
TARGET_MULTIPLE = 3.0
"""Issue 55: under each load, the connector's and the HTTP client's p99 within 3x their quiet p99."""
CONNECTOR_GAP_S = 0.05
HTTP_GAP_S = 0.01
SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
BODIES = {
    "invalid": json.dumps({"shots": [{**SEVEN_IRON, "ball_speed_mps": 500.0}] * 10_000}).encode(),
    "ones": json.dumps({"shots": [1] * 10_000}).encode(),
    "valid": json.dumps({"shots": [SEVEN_IRON] * 10_000}).encode(),
}
SCENARIOS = [("quiet", None, 0), ("invalid x2", "invalid", 2), ("invalid x6", "invalid", 6),
             ("ones x2", "ones", 2), ("valid x1", "valid", 1)]


def _read_answer(sock: socket.socket) -> tuple[int, int]:
    """One HTTP answer read whole from a keep-alive socket: (status, body bytes)."""
    data = b""
    while True:
        received = sock.recv(1 << 20)
        if not received:
            raise EOFError("the server closed the connection")
        data += received
        head, blank, rest = data.partition(b"\r\n\r\n")
        if blank:
            length = next(int(line.split(b":")[1]) for line in head.split(b"\r\n")
                          if line.lower().startswith(b"content-length:"))
            if len(rest) >= length:
                return int(head.split(b" ")[1]), length


def _post_bytes(path: str, body: bytes) -> bytes:
    return (f"POST {path} HTTP/1.1\r\nhost: 127.0.0.1\r\ncontent-type: application/json\r\n"
            f"content-length: {len(body)}\r\n\r\n").encode() + body


def batch_client(port: int, body: bytes, stop, started, out) -> None:
    """Process: POST `body` to /v1/shots/batch back to back until `stop`; sends (answers, statuses, largest answer)."""
    request, statuses, largest = _post_bytes("/v1/shots/batch", body), {}, 0
    with socket.create_connection((HOST, port), timeout=300) as sock:
        started.set()
        while not stop.is_set():
            sock.sendall(request)
            status, size = _read_answer(sock)
            statuses[status] = statuses.get(status, 0) + 1
            largest = max(largest, size)
    out.send((sum(statuses.values()), statuses, largest))


def http_client(port: int, stop, out) -> None:
    """Process: timed single shots, HTTP_GAP_S apart, until `stop`; sends their seconds."""
    request, seconds = _post_bytes("/v1/shots", json.dumps(SHOT).encode()), []
    with socket.create_connection((HOST, port), timeout=120) as sock:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        while not stop.is_set():
            started = time.perf_counter()
            sock.sendall(request)
            status, _ = _read_answer(sock)
            assert status == 200, status
            seconds.append(time.perf_counter() - started)
            time.sleep(HTTP_GAP_S)
    out.send(seconds)


def connector(port: int, stop, out) -> None:
    """Process: a connector's shots on one Open Connect connection, CONNECTOR_GAP_S apart, each timed to its reply
    (Code 200 asserted), until `stop`; sends their seconds."""
    seconds, decoder = [], json.JSONDecoder()
    with socket.create_connection((HOST, port), timeout=120) as sock:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        pending = ""
        while not stop.is_set():
            started = time.perf_counter()
            sock.sendall(CONNECT_SHOT)
            while True:
                try:
                    reply, end = decoder.raw_decode(pending.lstrip())
                    pending = pending.lstrip()[end:]
                    break
                except ValueError:
                    pending += sock.recv(65536).decode()
            assert reply["Code"] == 200, reply
            seconds.append(time.perf_counter() - started)
            time.sleep(CONNECTOR_GAP_S)
    out.send(seconds)


def _stats(seconds: list[float]) -> dict:
    ms = np.asarray(seconds) * 1e3
    p50, p99 = np.percentile(ms, [50, 99])
    return {"n": len(ms), "p50_ms": round(float(p50), 2), "p99_ms": round(float(p99), 2),
            "max_ms": round(float(ms.max()), 2)}


def scenario(port: int, connect: int, body: bytes | None, clients: int, seconds: float) -> dict:
    """The timed clients' figures while `clients` batch clients loop `body`, and the batch clients' answers."""
    context = multiprocessing.get_context("spawn")
    stop = context.Event()
    loaders, pipes = [], []
    for _ in range(clients if body else 0):
        receive, send = context.Pipe(duplex=False)
        started = context.Event()
        process = context.Process(target=batch_client, args=(port, body, stop, started, send))
        process.start()
        started.wait(60)
        loaders.append(process)
        pipes.append(receive)
    time.sleep(1.0 if body else 0.0)  # every batch client has its first batch in
    load_before = os.getloadavg()[0]
    timed = {}
    for name, target, where in (("connector", connector, connect), ("http", http_client, port)):
        receive, send = context.Pipe(duplex=False)
        process = context.Process(target=target, args=(where, stop, send))
        process.start()
        timed[name] = (process, receive)
    time.sleep(seconds)
    stop.set()
    row = {name: _stats(receive.recv()) for name, (_, receive) in timed.items()}
    answers = [receive.recv() for receive in pipes]
    for process in [*loaders, *(p for p, _ in timed.values())]:
        process.join(120)
    statuses: dict[str, int] = {}
    for _, got, _ in answers:
        for status, count in got.items():
            statuses[str(status)] = statuses.get(str(status), 0) + count
    return {**row, "batch_answers": statuses, "largest_answer_bytes": max((a[2] for a in answers), default=0),
            "load_average_1m": round(load_before, 2)}


def run(tree: Path, seconds: float, label: str) -> list[dict]:
    process, base_url, connect = start_service(tree)
    port = int(base_url.rsplit(":", 1)[1])
    rows = []
    try:
        for name, kind, clients in SCENARIOS:
            figures = scenario(port, connect, BODIES[kind] if kind else None, clients, seconds)
            rows.append({"name": f"{name} [{label}]", "scenario": name, "label": label, **figures})
    finally:
        process.terminate()
        process.wait(60)
    quiet = rows[0]
    for row in rows:
        for client in ("connector", "http"):
            row[client]["p99_x_quiet"] = round(row[client]["p99_ms"] / quiet[client]["p99_ms"], 2)
    return rows


def print_rows(rows: list[dict]) -> None:
    print(f"{'scenario':24} {'connector p50/p99/max ms':>28} {'x quiet':>8} {'http p50/p99/max ms':>26} "
          f"{'x quiet':>8} {'batch answers':>18} {'largest':>10} {'load':>5}")
    for row in rows:
        c, h = row["connector"], row["http"]
        print(f"{row['name']:24} {c['p50_ms']:>8.1f} {c['p99_ms']:>8.1f} {c['max_ms']:>9.1f} {c['p99_x_quiet']:>8.2f} "
              f"{h['p50_ms']:>7.1f} {h['p99_ms']:>8.1f} {h['max_ms']:>9.1f} {h['p99_x_quiet']:>8.2f} "
              f"{json.dumps(row['batch_answers']):>18} {row['largest_answer_bytes']:>10,} "
              f"{row['load_average_1m']:>5.2f}")


def write_rows(rows: list[dict], label: str, path: Path | None) -> None:
    """The results file named (none: nothing written): this run's rows in place of the earlier rows of its label."""
    kept = [row for row in read_results(path).get("rows", []) if row["label"] != label] + rows
    save_results(path, {"script": "benchmarks/bench_batch_load.py", "machine": machine(), "rows": kept})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=15.0, help="timed seconds per scenario")
    parser.add_argument("--label", default="after", help="this run's rows replace only that label's in --results FILE")
    parser.add_argument("--tree", type=Path, default=REPO, help="the checkout to serve (default: this one)")
    add_results_flag(parser, TRACKED_FILE)
    args = parser.parse_args()
    rows = run(args.tree, args.seconds, args.label)
    print_rows(rows)
    write_rows(rows, args.label, args.results)


if __name__ == "__main__":
    main()
