"""HTTP single shots while Open Connect connectors misbehave: does a hostile (or broken) program on the bay's machine,
which needs no key to reach the Open Connect port, hold up the HTTP service?

python benchmarks/bench_hostile.py [--flood-mb 20] [--hostile-s 10] [--quiet-s 5] [--connector-shots 20]
                                   [--label after] [--tree DIR] [--results FILE]

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

Then Open Connect's places (issue 42): a hostile program holds every place (16 sockets), (d) idle or (e) each
trickling a byte a second, and connects again whenever one is closed; once it holds them, a connector connects and
sends a shot --connector-shots times, 0.25 s apart, a new connection each time, and the time from its connect to its
shot's reply is taken, with the reply's Code (200: it got in; 503: it was refused).

Prints a table; --results FILE gets its `hostile` section: rows carry --label (e.g. "before" / "after"), and
a run replaces only the rows of its own label, so the section can hold a before and an after run.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import select
import socket
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import httpx
import numpy as np
from common import REPO, add_results_flag, machine, read_results, save_results
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
PLACES = 16
"""The sockets the hostile program of (d) and (e) holds: every place Open Connect has (`limits.MAX_CONNECTIONS`)."""
CONNECTOR_TARGET_S = 1.0
"""During (d) and (e): every connector's shot answered Code 200 within this long of its connect."""
CONNECTOR_GAP_S = 0.25
"""Between two connectors' shots in (d) and (e): time for the hostile program to take back the place it lost."""


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


def hold_places(port: int, trickle: bool, stop, holding, report) -> None:
    """Hold PLACES sockets to the Open Connect port, sending nothing or (`trickle`) a byte of a heartbeat a second on
    each, connecting again whenever one is closed, until `stop`; sets `holding` once all are connected; reports the
    connections used."""
    sockets = [socket.create_connection((HOST, port)) for _ in range(PLACES)]
    connections, sent = PLACES, 0
    holding.set()
    next_byte = time.monotonic()
    while not stop.is_set():
        readable, _, _ = select.select(sockets, [], [], 0.05)
        for sock in readable:
            if not _still_open(sock):
                sockets[sockets.index(sock)] = socket.create_connection((HOST, port))
                connections += 1
        if trickle and time.monotonic() >= next_byte:
            for sock in sockets:
                _send_quietly(sock, HEARTBEAT[sent % len(HEARTBEAT) : sent % len(HEARTBEAT) + 1])
            sent, next_byte = sent + 1, next_byte + 1.0
    for sock in sockets:
        sock.close()
    report.send(connections)


def _still_open(sock: socket.socket) -> bool:
    """Read what the server wrote (a refusal); False, with the socket closed, once the server has closed it."""
    try:
        if sock.recv(65536):
            return True
    except OSError:
        pass
    sock.close()
    return False


def _send_quietly(sock: socket.socket, data: bytes) -> None:
    """Send `data`, ignoring a socket the server has just closed (it is replaced at its next read)."""
    try:
        sock.send(data)
    except OSError:
        pass


def connector_shot(port: int) -> tuple[float, int]:
    """A connector connecting and sending a shot at once: (seconds from its connect to the reply, the reply's Code;
    0 when the connection closed without one)."""
    started = time.perf_counter()
    with socket.create_connection((HOST, port), timeout=HTTP_TIMEOUT_S) as sock:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.sendall(CONNECT_SHOT)
        data = b""
        while True:
            try:
                received = sock.recv(65536)
            except ConnectionResetError:
                received = b""
            data += received
            try:
                reply, _ = json.JSONDecoder().raw_decode(data.decode())
                return time.perf_counter() - started, reply["Code"]
            except ValueError:
                if not received:
                    return time.perf_counter() - started, 0


def places_scenario(connect: int, trickle: bool, shots: int, base_url: str) -> dict:
    """(d) or (e): connector shots while a hostile program holds every place; the figures of one row (less its
    name and label)."""
    context = multiprocessing.get_context("spawn")
    report_out, report_in = context.Pipe(duplex=False)
    stop, holding = context.Event(), context.Event()
    holder = context.Process(target=hold_places, args=(connect, trickle, stop, holding, report_in))
    holder.start()
    assert holding.wait(timeout=60), "the hostile program did not connect"
    time.sleep(3.0 if trickle else 1.0)  # every place taken (and, trickling, a few bytes into each)
    evicted_before = evictions(base_url)
    timed = []
    for _ in range(shots):
        timed.append(connector_shot(connect))
        time.sleep(CONNECTOR_GAP_S)
    evicted = evictions(base_url)
    stop.set()
    connections = report_out.recv()
    holder.join()
    ms = np.asarray([seconds for seconds, _ in timed]) * 1e3
    return {"unit": "ms", "connector_shots": shots, "answered": sum(code == 200 for _, code in timed),
            "codes": sorted({code for _, code in timed}), "p50": float(np.percentile(ms, 50)),
            "max": float(ms.max()), "hostile_connections": connections,
            "evicted": None if evicted is None else evicted - evicted_before}


def evictions(base_url: str) -> int | None:
    """Open Connect's evictions since the service started (GET /healthz), or None where it does not say."""
    answer = httpx.get(base_url + "/healthz", timeout=HTTP_TIMEOUT_S).json()
    return answer.get("open_connect", {}).get("evicted")


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
        for scenario, trickle in ((f"(d) {PLACES} idle sockets held", False),
                                  (f"(e) {PLACES} sockets trickling a byte a second", True)):
            print(f"{scenario} ...", flush=True)
            figures = places_scenario(connect, trickle, args.connector_shots, base_url)
            rows.append({"name": f"{scenario} [{args.label}]", "label": args.label, "scenario": scenario} | figures)
    finally:
        client.close()
        process.terminate()
        process.wait(timeout=60)
    rows.append(targets_row(rows, args.label))
    rows.append(places_targets_row(rows, args.label))
    return rows


def targets_row(rows: list[dict], label: str) -> dict:
    """Whether (b) met TARGETS."""
    during = rows[1]
    met = (during["p99"] <= TARGETS["p99_ms"] and during["max"] <= TARGETS["max_ms"]
           and during["resets"] + during["timeouts"] == TARGETS["resets"]
           and during["healthz_after_s"] <= TARGETS["healthz_after_s"])
    return {"name": f"targets during (b) [{label}]", "label": label, "targets": TARGETS, "met": met}


def places_targets_row(rows: list[dict], label: str) -> dict:
    """Whether every connector's shot in (d) and (e) was answered Code 200 within CONNECTOR_TARGET_S."""
    places = [row for row in rows if "connector_shots" in row]
    met = all(row["answered"] == row["connector_shots"] and row["max"] <= CONNECTOR_TARGET_S * 1e3 for row in places)
    return {"name": f"targets during (d), (e) [{label}]", "label": label,
            "targets": {"connector_max_s": CONNECTOR_TARGET_S, "answered": "all, Code 200"}, "met": met}


def print_rows(rows: list[dict]) -> None:
    print("\nHTTP single shot (POST /v1/shots, keep-alive) while Open Connect connectors misbehave\n")
    print("| scenario | shots | p50 | p99 | max | resets / timeouts | flood | /healthz after |")
    print("|---|---:|---:|---:|---:|---:|---|---:|")
    for row in rows:
        if row.get("targets") == TARGETS:
            print(f"| {row['name']}: p99 <= {TARGETS['p99_ms']:g} ms, max <= {TARGETS['max_ms']:g} ms, no reset, "
                  f"/healthz <= {TARGETS['healthz_after_s']:g} s | {'met' if row['met'] else 'NOT met'} |||||||")
        elif "shots" in row:
            print_http_row(row)
    print_places(rows)


def print_http_row(row: dict) -> None:
    flood_text = (f"{row['flood_mb']:.1f} MB in {row['flood_s']:.1f} s, {row['flood_connections']} connections"
                  if "flood_mb" in row else "")
    if "never_reader_connections" in row:
        flood_text += (f"; never-reader: {row['never_reader_shots_written']:,} shots written, "
                       f"{row['never_reader_connections']} connections")
    healthz = f"{row['healthz_after_s'] * 1e3:.0f} ms" if "healthz_after_s" in row else ""
    print(f"| {row['name']} | {row['shots']:,} | {row['p50']:.1f} ms | {row['p99']:.1f} ms | {row['max']:.1f} ms "
          f"| {row['resets']} / {row['timeouts']} | {flood_text} | {healthz} |")


def print_places(rows: list[dict]) -> None:
    """The table of (d) and (e): a new connector's shot while a hostile program holds every place."""
    print(f"\nA new connector's shot (connect to reply) while a hostile program holds all {PLACES} places\n")
    print("| scenario | answered Code 200 | codes | p50 | max | hostile connections | evicted (/healthz) |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for row in rows:
        if "connector_shots" in row:
            print(f"| {row['name']} | {row['answered']} of {row['connector_shots']} | {row['codes']} "
                  f"| {row['p50']:.1f} ms | {row['max']:.1f} ms | {row['hostile_connections']} | {row['evicted']} |")
        elif "connector_max_s" in row.get("targets", {}):
            print(f"| {row['name']}: every shot Code 200 within {CONNECTOR_TARGET_S:g} s "
                  f"| {'met' if row['met'] else 'NOT met'} ||||||")


def write_section(rows: list[dict], label: str, path: Path | None) -> None:
    """The `hostile` section of the results file named: this run's rows in place of earlier rows of the same label;
    the machine at each label's run is kept beside it."""
    data = read_results(path)
    section = data.get("hostile", {"machines": {}, "rows": []})
    section["rows"] = [row for row in section["rows"] if row.get("label") != label] + rows
    section["machines"][label] = machine()
    data["hostile"] = section
    save_results(path, data)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flood-mb", type=float, default=20.0, help="megabytes each flooder writes")
    parser.add_argument("--hostile-s", type=float, default=10.0, help="seconds each flood lasts at least")
    parser.add_argument("--quiet-s", type=float, default=5.0, help="seconds of (a)")
    parser.add_argument("--connector-shots", type=int, default=20, help="connectors' shots in (d) and (e) each")
    parser.add_argument("--label", default="this tree", help="what is measured (rows of other labels are kept)")
    parser.add_argument("--tree", type=Path, default=REPO, help="the checkout whose service is measured")
    add_results_flag(parser)
    args = parser.parse_args()
    print(f"load average {os.getloadavg()}", flush=True)
    rows = run(args)
    print_rows(rows)
    write_section(rows, args.label, args.results)


if __name__ == "__main__":
    main()
