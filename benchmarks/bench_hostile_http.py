"""One hostile HTTP client on the bay's network (issue 55 items 1, 5 and 7): do a connector's shots and HTTP single
shots keep their pace, and does the server's memory stay bounded?

python benchmarks/bench_hostile_http.py [--before-tree DIR] [--seconds 8] [--shots 10000] [--results FILE]

Starts `golfflight serve --connect-port Q` of this checkout ("after") and, with --before-tree DIR (e.g. `git archive
main | tar -x -C DIR`), of that checkout too ("before"), both at once, so that every scenario runs on each in turn
in one sitting (interleaved A/B). Without a key, each fills its session with --shots shots (shown batches of 50),
then, per scenario, times HTTP single shots back to back (one keep-alive raw socket client) and a connector's Open
Connect shots (one every 50 ms, each reply read before the next) for --seconds, sampling the server's resident
memory (the server and its batch process) every 0.1 s: (quiet); (1) three clients looping 8 MiB request headers,
each keeping its last 40 connections open; (5) 50 clients that GET /v1/session.csv and never read, each replaced
when the server closes it. Then the CSV's cost: a --shots download timed on each tree in turn, three times. With
an API key ($GOLFFLIGHT_API_KEY, the timed clients sending it): (quiet); (7) 30 clients sending 7.9 MiB of a
chunked body without the key and never finishing it, each replaced when closed. The attackers run in processes of
their own. Between scenarios the script waits for the server to go idle.

Prints a table; with --results FILE, writes it to FILE, and without it writes nothing. The tracked figures the docs
quote are benchmarks/hostile_http.json; a run of record names it: `--results benchmarks/hostile_http.json`.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import select
import socket
import statistics
import threading
import time
from collections import deque
from pathlib import Path

import httpx
import psutil
from bench_session_download import connector_shots, figures
from common import REPO, add_results_flag, machine, save_results
from server import HOST, RawHttp, Server, free_port, start

TRACKED_FILE = REPO / "benchmarks" / "hostile_http.json"
"""This script's figures that docs/reliability.md quotes: written only by a run that names it (--results)."""
KEY = "bench-hostile-http"
SHOT = {"ball_speed_mph": 150, "launch_angle_deg": 12, "spin_rpm": 3000}
HEAD_BYTES = 8 * 2**20
HEADS_HELD = 40
BODY_BYTES = int(7.9 * 2**20)
PIECE = b"a" * 256 * 1024


def looping_heads(port: int, stop) -> None:
    """Connect, send a request line and an 8 MiB header as fast as the server takes it, keep the last HEADS_HELD
    connections open, again until `stop`."""
    opened: deque[socket.socket] = deque()
    while not stop.is_set():
        sock = socket.create_connection((HOST, port), timeout=10)
        try:
            sock.sendall(b"GET /healthz HTTP/1.1\r\nhost: 127.0.0.1\r\nx-pad: ")
            for _ in range(HEAD_BYTES // len(PIECE)):
                sock.sendall(PIECE)
        except OSError:
            pass
        opened.append(sock)
        if len(opened) > HEADS_HELD:
            opened.popleft().close()
    for sock in opened:
        sock.close()


def _closed(sock: socket.socket) -> bool:
    """Whether the server closed `sock`, found without taking any of what waits to be read."""
    if not select.select([sock], [], [], 0)[0]:
        return False
    try:
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True


def holders(port: int, stop, count: int, opening) -> None:
    """`count` connections made by `opening(port)`, never read, each replaced once the server closes it."""
    held = [opening(port) for _ in range(count)]
    while not stop.is_set():
        for index, sock in enumerate(held):
            if _closed(sock):
                sock.close()
                held[index] = opening(port)
        time.sleep(0.2)
    for sock in held:
        sock.close()


def unread_download(port: int) -> socket.socket:
    sock = socket.create_connection((HOST, port), timeout=10)
    sock.sendall(b"GET /v1/session.csv HTTP/1.1\r\nhost: 127.0.0.1\r\n\r\n")
    return sock


def unfinished_body(port: int) -> socket.socket:
    """A chunked POST without the key: 7.9 MiB of its body sent (as far as the server takes it), never finished."""
    sock = socket.create_connection((HOST, port), timeout=10)
    try:
        sock.sendall(b"POST /v1/shots/batch HTTP/1.1\r\nhost: 127.0.0.1\r\ncontent-type: application/json\r\n"
                     b"transfer-encoding: chunked\r\n\r\n")
        for _ in range(BODY_BYTES // len(PIECE)):
            sock.sendall(b"%x\r\n" % len(PIECE) + PIECE + b"\r\n")
    except OSError:
        pass
    return sock


def _unread_downloads(port: int, stop) -> None:
    holders(port, stop, 50, unread_download)


def _unfinished_bodies(port: int, stop) -> None:
    holders(port, stop, 30, unfinished_body)


ATTACKS = {"(1) 3 clients looping 8 MiB headers": [looping_heads] * 3,
           "(5) 50 unread GET /v1/session.csv": [_unread_downloads],
           "(7) 30 unfinished 7.9 MiB chunked bodies, no key": [_unfinished_bodies]}


def _idle(server: Server, limit_s: float = 120.0) -> None:
    """Wait until the server has used under a tenth of a core for a second (what an attack left is done)."""
    process, quiet, deadline = psutil.Process(server.process.pid), 0, time.monotonic() + limit_s
    while quiet < 2 and time.monotonic() < deadline:
        quiet = quiet + 1 if process.cpu_percent(interval=0.5) < 10.0 else 0


def _timed(server: Server, connect_port: int, key: str | None, seconds: float) -> tuple[dict, dict, list[float]]:
    """HTTP single shots back to back and connector shots beside them for `seconds`, the RSS sampled meanwhile."""
    http = RawHttp(server.port, "/v1/shots", json.dumps(SHOT).encode())
    if key:
        keyed = b"host: 127.0.0.1\r\nx-api-key: %s\r\n" % key.encode()
        http.request = http.request.replace(b"host: 127.0.0.1\r\n", keyed)
    until = time.monotonic() + seconds
    connector: list[float] = []
    rss: list[float] = []
    thread = threading.Thread(target=connector_shots, args=(connect_port, until, connector))
    thread.start()
    shots, next_sample = [], 0.0
    while time.monotonic() < until:
        started = time.perf_counter()
        http.post()
        shots.append(time.perf_counter() - started)
        if started >= next_sample:
            rss.append(server.rss_mib()["total"])
            next_sample = started + 0.1
    thread.join()
    http.close()
    return figures(shots), figures(connector), rss


def scenario(name: str, label: str, bay: dict, seconds: float) -> dict:
    """One scenario on one tree's server (`bay`: server, connect port, key): its row."""
    server, connect_port, key = bay["server"], bay["connect_port"], bay["key"]
    _idle(server)
    before = server.rss_mib()["total"]
    context = multiprocessing.get_context("spawn")
    stop = context.Event()
    attackers = [context.Process(target=attack, args=(server.port, stop)) for attack in ATTACKS.get(name, [])]
    for attacker in attackers:
        attacker.start()
    time.sleep(2.0 if attackers else 0.0)  # the attack under way
    shot, connector, rss = _timed(server, connect_port, key, seconds)
    stop.set()
    for attacker in attackers:
        attacker.join(60)
    time.sleep(1.0)
    return {"label": label, "scenario": name, "key": bool(key), "http_single": shot, "connector": connector,
            "rss_before_mib": before, "rss_peak_mib": max(rss), "rss_after_mib": server.rss_mib()["total"]}


def _fill(server: Server, shots: int) -> None:
    with httpx.Client(base_url=server.base_url, timeout=120) as http:
        for _ in range(shots // 50):
            answer = http.post("/v1/shots/batch?viewer=1", json={"shots": [SHOT] * 50})
            assert answer.status_code == 200, answer.text


def _download_seconds(server: Server) -> float:
    started = time.perf_counter()
    with httpx.Client(timeout=300) as http:
        assert http.get(server.base_url + "/v1/session.csv").status_code == 200
    return time.perf_counter() - started


def _started(tree: Path, key: str | None) -> dict:
    connect_port = free_port()
    env = {"PYTHONPATH": str(tree), **({"GOLFFLIGHT_API_KEY": key} if key else {})}
    server = start(tree=tree, env=env, args=["--connect-port", str(connect_port)])
    return {"server": server, "connect_port": connect_port, "key": key}


def run(args: argparse.Namespace) -> tuple[list[dict], dict]:
    trees = {"after": REPO, **({"before": args.before_tree} if args.before_tree else {})}
    rows: list[dict] = []
    csv_seconds: dict[str, list[float]] = {label: [] for label in trees}
    bays = {label: _started(tree, None) for label, tree in trees.items()}
    try:
        for bay in bays.values():
            _fill(bay["server"], args.shots)
        for name in ("quiet", *list(ATTACKS)[:2]):
            for label, bay in bays.items():
                rows.append(scenario(name, label, bay, args.seconds))
        for _ in range(3):
            for label, bay in bays.items():
                _idle(bay["server"])
                csv_seconds[label].append(_download_seconds(bay["server"]))
    finally:
        for bay in bays.values():
            bay["server"].stop()
    bays = {label: _started(tree, KEY) for label, tree in trees.items()}
    try:
        for name in ("quiet", list(ATTACKS)[2]):
            for label, bay in bays.items():
                rows.append(scenario(name, label, bay, args.seconds))
    finally:
        for bay in bays.values():
            bay["server"].stop()
    return rows, csv_seconds


def print_table(rows: list[dict], csv_seconds: dict[str, list[float]]) -> None:
    print("\n| tree | scenario | HTTP single p50 / p99 / max | connector p50 / p99 / max | RSS before / peak / after "
          "| within 3x quiet p99 |")
    print("|---|---|---|---|---|---|")
    for row in rows:
        quiet = next(r for r in rows if r["label"] == row["label"] and r["key"] == row["key"]
                     and r["scenario"] == "quiet")
        within = all(row[part]["p99_ms"] <= 3 * quiet[part]["p99_ms"] for part in ("http_single", "connector"))
        h, c = row["http_single"], row["connector"]
        print(f"| {row['label']} | {row['scenario']}{' (key)' if row['key'] else ''} | {h['p50_ms']:.1f} / "
              f"{h['p99_ms']:.1f} / {h['max_ms']:.1f} ms | {c['p50_ms']:.1f} / {c['p99_ms']:.1f} / "
              f"{c['max_ms']:.1f} ms | {row['rss_before_mib']:.0f} / {row['rss_peak_mib']:.0f} / "
              f"{row['rss_after_mib']:.0f} MiB | {'yes' if within else 'NO'} |")
    for label, seconds in csv_seconds.items():
        print(f"{label}: session CSV download {', '.join(f'{s:.2f}' for s in seconds)} s "
              f"(median {statistics.median(seconds):.2f} s)")
    if len(csv_seconds) == 2:
        ratio = statistics.median(csv_seconds["after"]) / statistics.median(csv_seconds["before"])
        print(f"after / before: {ratio:.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before-tree", type=Path)
    parser.add_argument("--seconds", type=float, default=8.0)
    parser.add_argument("--shots", type=int, default=10_000)
    add_results_flag(parser, TRACKED_FILE)
    args = parser.parse_args()
    rows, csv_seconds = run(args)
    print_table(rows, csv_seconds)
    data = {"machine": machine(), "before_tree": str(args.before_tree) if args.before_tree else None,
            "seconds": args.seconds, "session_shots": args.shots, "rows": rows, "csv_download_s": csv_seconds}
    save_results(args.results, data)


if __name__ == "__main__":
    main()
