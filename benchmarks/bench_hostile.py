"""HTTP single shots while Open Connect connectors misbehave: does a hostile (or broken) program on the bay's machine,
which needs no key to reach the Open Connect port, hold up the HTTP service?

python benchmarks/bench_hostile.py [--flood-mb 20] [--hostile-s 10] [--quiet-s 5] [--label after] [--tree DIR]
                                   [--no-write]

Starts `golfflight serve --port P --connect-port Q` in a subprocess, as a user would (of this checkout, or of
--tree DIR: e.g. `git archive HEAD | tar -x -C DIR` for a before run while the checkout changes), waits for GET
/healthz, then times POST /v1/shots (one keep-alive raw socket client, `server.RawHttp`'s request) in three
scenarios: (a) quiet; (b) one connector writing --flood-mb MB of `{"a":{}}` back to back as fast as its socket takes
them while another writes shots back to back and never reads a reply; (c) --flood-mb MB of heartbeats. A hostile
connector that is closed connects again and goes on (what a loop in a hostile program does), until its megabytes
are written and for --hostile-s seconds at least: a server that closes it at once ends a flood's megabytes in
milliseconds, and the scenario would measure nothing. Timing starts once every hostile connector has written. The
connectors run in processes of their own, so the timed client has this process (and its GIL) to itself. After each
flood stops (its sockets closed), the time to a GET /healthz on a new connection is taken.

Prints a table and writes the `hostile` section of results.json: rows carry --label (e.g. "before" / "after"), and
a run replaces only the rows of its own label, so the section can hold a before and an after run.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import socket
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import httpx
import numpy as np
from common import REPO, RESULTS, machine
from server import HOST, RawHttp, free_port

SHOT = {"ball_speed_mph": 150, "launch_angle_deg": 12, "spin_rpm": 3000}
EMPTY = b'{"a":{}}'
"""The flood's object: valid JSON, no ball data, so GSPro's rules give it no reply (the cheapest thing to send)."""
HEARTBEAT = json.dumps({
    "DeviceID": "bench", "Units": "Yards", "ShotNumber": 0, "APIversion": "1",
    "BallData": {"Speed": 0.0, "SpinAxis": 0.0, "TotalSpin": 0.0, "HLA": 0.0, "VLA": 0.0},
    "ShotDataOptions": {"ContainsBallData": False, "LaunchMonitorIsReady": True, "IsHeartBeat": True},
}).encode()
CONNECT_SHOT = json.dumps({
    "DeviceID": "bench", "Units": "Yards", "ShotNumber": 1, "APIversion": "1",
    "BallData": {"Speed": 150.0, "SpinAxis": 0.0, "TotalSpin": 3000.0, "HLA": 0.0, "VLA": 12.0},
    "ShotDataOptions": {"ContainsBallData": True, "ContainsClubData": False},
}).encode()
CHUNK_BYTES = 64 * 1024
"""What a flooder hands its socket per send."""
HTTP_TIMEOUT_S = 120.0
"""A request that takes longer is counted as failed (the colleague's worst was 28.5 s)."""
FLOOD_CAP_S = 300.0
"""A flood still going after this long is stopped (and the run says so)."""
TARGETS = {"p99_ms": 50.0, "max_ms": 250.0, "resets": 0, "healthz_after_s": 1.0}
"""During (b), on the 2-core machine: HTTP single shot p99 and max, connection resets, /healthz after the flood."""


def flood(port: int, unit: bytes, total_bytes: int, least_s: float, writing, report) -> None:
    """Write `unit` back to back until `total_bytes` have gone into sockets and `least_s` have passed, connecting
    again whenever closed; never read. Sets `writing` once the first bytes are written; reports (bytes written,
    connections used, seconds)."""
    chunk = unit * (CHUNK_BYTES // len(unit))
    written, connections, started = 0, 0, time.monotonic()

    def going() -> bool:
        elapsed = time.monotonic() - started
        return (written < total_bytes or elapsed < least_s) and elapsed < FLOOD_CAP_S

    while going():
        try:
            sock = socket.create_connection((HOST, port), timeout=FLOOD_CAP_S)
        except OSError:
            time.sleep(0.01)
            continue
        connections += 1
        try:
            while going():
                written += sock.send(chunk)
                writing.set()
        except OSError:  # reset or closed by the server: connect again
            pass
        finally:
            sock.close()
    report.send((written, connections, time.monotonic() - started))


def never_read(port: int, stop, writing, report) -> None:
    """Write shots back to back and never read a reply, connecting again whenever closed, until `stop` is set.
    Sets `writing` once the first shots are written; reports (shots written, connections used)."""
    chunk = CONNECT_SHOT * (CHUNK_BYTES // len(CONNECT_SHOT))
    written, connections = 0, 0
    while not stop.is_set():
        try:
            sock = socket.create_connection((HOST, port), timeout=0.5)
        except OSError:
            time.sleep(0.01)
            continue
        connections += 1
        try:
            while not stop.is_set():
                try:
                    written += sock.send(chunk)
                    writing.set()
                except TimeoutError:  # the server stopped reading: wait and try again
                    continue
        except OSError:
            pass
        finally:
            sock.close()
    report.send((written // len(CONNECT_SHOT), connections))


@dataclass
class Timed:
    """Single-shot latencies (s) and failures of one scenario."""

    seconds: list[float]
    resets: int = 0
    timeouts: int = 0

    def row(self, scenario: str, label: str) -> dict:
        ms = np.asarray(self.seconds) * 1e3
        p50, p99 = np.percentile(ms, [50, 99]) if len(ms) else (float("nan"), float("nan"))
        return {"name": f"{scenario} [{label}]", "label": label, "scenario": scenario, "unit": "ms",
                "shots": len(ms), "p50": float(p50), "p99": float(p99), "max": float(ms.max()) if len(ms) else None,
                "resets": self.resets, "timeouts": self.timeouts}


class Client:
    """The timed HTTP client: one keep-alive connection, opened again after a reset."""

    def __init__(self, port: int):
        self.port = port
        self.http = self._connect()

    def _connect(self) -> RawHttp:
        http = RawHttp(self.port, "/v1/shots", json.dumps(SHOT).encode())
        http.sock.settimeout(HTTP_TIMEOUT_S)
        return http

    def shot(self, timed: Timed) -> None:
        """One single shot, its latency or failure added to `timed`."""
        started = time.perf_counter()
        try:
            self._post()
        except TimeoutError:
            timed.timeouts += 1
        except (ConnectionError, EOFError):
            timed.resets += 1
        else:
            timed.seconds.append(time.perf_counter() - started)
            return
        self.http.close()
        self.http = self._connect()

    def _post(self) -> None:
        """`RawHttp.post`, with a closed connection raised (EOFError) instead of read forever."""
        sock, data = self.http.sock, b""
        sock.sendall(self.http.request)
        while True:
            received = sock.recv(65536)
            if not received:
                raise EOFError("the server closed the connection")
            data += received
            head, blank, rest = data.partition(b"\r\n\r\n")
            if blank:
                length = next(int(line.split(b":")[1]) for line in head.split(b"\r\n")
                              if line.lower().startswith(b"content-length:"))
                if len(rest) >= length:
                    assert head.startswith(b"HTTP/1.1 200"), head
                    return

    def close(self) -> None:
        self.http.close()


def healthz_seconds(base_url: str) -> float:
    """Seconds to a GET /healthz answered 200 on a new connection."""
    started = time.perf_counter()
    response = httpx.get(base_url + "/healthz", timeout=HTTP_TIMEOUT_S)
    assert response.status_code == 200, response.text
    return time.perf_counter() - started


def start_service(tree: Path) -> tuple[subprocess.Popen, str, int]:
    """`golfflight serve --port P --connect-port Q` of the checkout `tree` (its working directory: the checkout's
    golfflight package comes first on the path), once /healthz answers 200: (process, base URL, Q)."""
    port, connect = free_port(), free_port()
    command = [sys.executable, "-m", "golfflight", "serve", "--port", str(port), "--connect-port", str(connect)]
    process = subprocess.Popen(command, cwd=tree, stdout=subprocess.DEVNULL)
    base_url = f"http://{HOST}:{port}"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and process.poll() is None:
        try:
            if httpx.get(base_url + "/healthz", timeout=2).status_code == 200:
                return process, base_url, connect
        except httpx.TransportError:
            pass
        time.sleep(0.05)
    process.kill()
    raise RuntimeError("golfflight serve did not become ready within 60 s")


def timed_while(client: Client, busy) -> Timed:
    """Single shots back to back while `busy()` says the scenario goes on."""
    timed = Timed([])
    while busy():
        client.shot(timed)
    return timed


def flood_scenario(client: Client, connect: int, unit: bytes, args: argparse.Namespace,
                   never_reader: bool) -> tuple[Timed, dict]:
    """Single shots while a flooder (and, with `never_reader`, a connector that never reads) runs; the figures of
    the hostile connectors. /healthz is timed by the caller once their sockets are closed."""
    context = multiprocessing.get_context("spawn")
    flood_out, flood_in = context.Pipe(duplex=False)
    flooding, reading_none, stop = context.Event(), context.Event(), context.Event()
    total = int(args.flood_mb * 2**20)
    flooder = context.Process(target=flood, args=(connect, unit, total, args.hostile_s, flooding, flood_in))
    reader_out, reader_in = context.Pipe(duplex=False)
    reader = context.Process(target=never_read, args=(connect, stop, reading_none, reader_in)) if never_reader else None
    for process in (flooder, reader):
        if process:
            process.start()
    assert flooding.wait(timeout=60) and (reading_none.wait(timeout=60) if reader else True), "connectors not writing"
    timed = timed_while(client, flooder.is_alive)
    stop.set()
    written, connections, seconds = flood_out.recv()
    flooder.join()
    figures = {"flood_mb": written / 2**20, "flood_s": seconds, "flood_connections": connections}
    if reader:
        shots, reader_connections = reader_out.recv()
        reader.join()
        figures |= {"never_reader_shots_written": shots, "never_reader_connections": reader_connections}
    return timed, figures


def run(args: argparse.Namespace) -> list[dict]:
    process, base_url, connect = start_service(args.tree)
    client = Client(int(base_url.rsplit(":", 1)[1]))
    rows = []
    try:
        for _ in range(200):
            client.shot(Timed([]))  # warm up
        deadline = time.monotonic() + args.quiet_s
        rows.append(timed_while(client, lambda: time.monotonic() < deadline).row("(a) quiet", args.label))
        for scenario, unit, never_reader in (
            (f"(b) {args.flood_mb:g} MB of {EMPTY.decode()} + a connector that never reads", EMPTY, True),
            (f"(c) {args.flood_mb:g} MB of heartbeats", HEARTBEAT, False),
        ):
            print(f"{scenario} ...", flush=True)
            timed, figures = flood_scenario(client, connect, unit, args, never_reader)
            row = timed.row(scenario, args.label) | figures | {"healthz_after_s": healthz_seconds(base_url)}
            rows.append(row)
    finally:
        client.close()
        process.terminate()
        process.wait(timeout=60)
    during = rows[1]
    met = (during["p99"] <= TARGETS["p99_ms"] and during["max"] <= TARGETS["max_ms"]
           and during["resets"] + during["timeouts"] == TARGETS["resets"]
           and during["healthz_after_s"] <= TARGETS["healthz_after_s"])
    rows.append({"name": f"targets during (b) [{args.label}]", "label": args.label, "targets": TARGETS, "met": met})
    return rows


def print_rows(rows: list[dict]) -> None:
    print("\nHTTP single shot (POST /v1/shots, keep-alive) while Open Connect connectors misbehave\n")
    print("| scenario | shots | p50 | p99 | max | resets / timeouts | flood | /healthz after |")
    print("|---|---:|---:|---:|---:|---:|---|---:|")
    for row in rows:
        if "met" in row:
            print(f"| {row['name']}: p99 <= {TARGETS['p99_ms']:g} ms, max <= {TARGETS['max_ms']:g} ms, no reset, "
                  f"/healthz <= {TARGETS['healthz_after_s']:g} s | {'met' if row['met'] else 'NOT met'} |||||||")
            continue
        flood_text = (f"{row['flood_mb']:.1f} MB in {row['flood_s']:.1f} s, {row['flood_connections']} connections"
                      if "flood_mb" in row else "")
        if "never_reader_connections" in row:
            flood_text += (f"; never-reader: {row['never_reader_shots_written']:,} shots written, "
                           f"{row['never_reader_connections']} connections")
        healthz = f"{row['healthz_after_s'] * 1e3:.0f} ms" if "healthz_after_s" in row else ""
        print(f"| {row['name']} | {row['shots']:,} | {row['p50']:.1f} ms | {row['p99']:.1f} ms | {row['max']:.1f} ms "
              f"| {row['resets']} / {row['timeouts']} | {flood_text} | {healthz} |")


def write_section(rows: list[dict], label: str) -> None:
    """The `hostile` section of results.json: this run's rows in place of earlier rows of the same label; the
    machine at each label's run is kept beside it."""
    data = json.loads(RESULTS.read_text()) if RESULTS.is_file() else {}
    section = data.get("hostile", {"machines": {}, "rows": []})
    section["rows"] = [row for row in section["rows"] if row.get("label") != label] + rows
    section["machines"][label] = machine()
    data["hostile"] = section
    RESULTS.write_text(json.dumps(data, indent=2) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flood-mb", type=float, default=20.0, help="megabytes each flooder writes")
    parser.add_argument("--hostile-s", type=float, default=10.0, help="seconds each flood lasts at least")
    parser.add_argument("--quiet-s", type=float, default=5.0, help="seconds of (a)")
    parser.add_argument("--label", default="this tree", help="what is measured (rows of other labels are kept)")
    parser.add_argument("--tree", type=Path, default=REPO, help="the checkout whose service is measured")
    parser.add_argument("--no-write", action="store_true", help="leave benchmarks/results.json as it is")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()}", flush=True)
    rows = run(args)
    print_rows(rows)
    if not args.no_write:
        write_section(rows, args.label)


if __name__ == "__main__":
    main()
