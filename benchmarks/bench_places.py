"""Who keeps a place, and whose shots stay, on a hostile network (issue 55, items 2, 8 and 9): counts, before and after.

python benchmarks/bench_places.py [--tree DIR] [--trials 10] [--flood-s 90] [--results FILE]

Starts `golfflight serve --port P --connect-port Q` of this checkout (or of --tree DIR, e.g. `git archive main | tar
-x -C DIR` for a before run), as bench_hostile.py does, and counts:
(a) a connector that connects, then 20 sockets in a process of their own connect again whenever closed and never
    send a message; once they have gone round every place four times (64 evictions), 0.3 s on, the connector sends
    its first shot: answered Code 200, or pushed out (Code 503) before it could;
(b) with that flood running, a connector that connects and sends its shot at once: Code 200 or not;
(e) the flood from 127.0.0.3 instead; once it has gone round every place (16 evictions), a connector on 127.0.0.1
    connects; 64 evictions and 0.3 s on, it sends its first shot: Code 200 or not;
(c) 16 event streams opened and never read, then one more: does it get its stream (200) or a 503;
(d) a connector on 127.0.0.2 plays 300 shots in session 1; session 2 starts; 8 connections from 127.0.0.1 send
    shots back to back (connecting again when closed for their rate) until 10,500 are answered, past the 10,000
    kept, or --flood-s seconds: how many of session 1's 300 shots are kept.
Prints one line per scenario; with --results FILE, writes the counts, with the machine and its load, to FILE, and
without it writes nothing (no run of it is tracked: docs/reliability.md quotes the printed counts).
"""

from __future__ import annotations

import argparse
import json
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
from bench_hostile import start_service
from common import REPO, add_results_flag, machine, save_results

FLOOD = Path(__file__).with_name("silent_flood.py")
"""20 sockets that send nothing, each connecting again as soon as it is closed."""

FLOOD_SHOTS = 10_500
"""The flood's shots: past the 10,000 the sessions keep."""


def message(number: int) -> bytes:
    return json.dumps({"DeviceID": "bench", "ShotNumber": number, "APIversion": "1", "BallData": {
        "Speed": 150.0, "SpinAxis": 0.0, "TotalSpin": 3000.0, "HLA": 0.0, "VLA": 12.0}}).encode()


def connected(port: int, source: str = "127.0.0.1") -> socket.socket:
    sock = socket.socket()
    sock.bind((source, 0))
    sock.connect(("127.0.0.1", port))
    sock.settimeout(10)
    return sock


def code_of(sock: socket.socket, number: int) -> int:
    """Send shot `number` and read its reply's Code (0: closed without one)."""
    try:
        sock.sendall(message(number))
        data = sock.recv(65536)
        return json.JSONDecoder().raw_decode(data.decode())[0]["Code"] if data else 0
    except (OSError, ValueError):
        return 0


def evicted(base: str) -> int:
    return httpx.get(base + "/healthz", timeout=10).json()["open_connect"]["evicted"]


def flooding(port: int, source: str) -> subprocess.Popen:
    """The flood from address `source`, once its sockets are connected."""
    flood = subprocess.Popen([sys.executable, str(FLOOD), str(port), "20", source], stdout=subprocess.PIPE)
    flood.stdout.readline()
    return flood


def evicted_past(base: str, count: int) -> None:
    """Wait until `count` more connections have given their places (or 20 s)."""
    goal, deadline = evicted(base) + count, time.monotonic() + 20
    while evicted(base) < goal and time.monotonic() < deadline:
        time.sleep(0.02)


def waiting_connector(base: str, port: int, trials: int) -> tuple[int, int]:
    """(a) and (b): Code 200s of `trials` connectors that connected first and waited, and of `trials` that
    connected during the flood and sent at once."""
    waited = at_once = 0
    for trial in range(trials):
        connector = connected(port)
        flood = flooding(port, "127.0.0.1")
        evicted_past(base, 64)
        time.sleep(0.3)
        waited += code_of(connector, trial) == 200
        newcomer = connected(port)
        at_once += code_of(newcomer, trial) == 200
        for sock in (connector, newcomer):
            sock.close()
        flood.kill()
        flood.wait()
    return waited, at_once


def joined_during_flood(base: str, port: int, trials: int) -> int:
    """(e): Code 200s of `trials` connectors that connected during a flood from another address and waited."""
    waited = 0
    for trial in range(trials):
        flood = flooding(port, "127.0.0.3")
        evicted_past(base, 16)
        connector = connected(port)
        evicted_past(base, 64)
        time.sleep(0.3)
        waited += code_of(connector, trial) == 200
        connector.close()
        flood.kill()
        flood.wait()
    return waited


def viewer_places(base: str) -> int:
    """(c): the status of a 17th stream past 16 held open and unread."""
    port = int(base.rsplit(":", 1)[1])
    held = []
    for _ in range(16):
        sock = connected(port)
        sock.sendall(f"GET /v1/events HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
        held.append(sock)
    time.sleep(1.0)
    with httpx.stream("GET", base + "/v1/events", timeout=10) as answer:
        status = answer.status_code
    for sock in held:
        sock.close()
    return status


def session_kept(base: str, port: int, flood_s: float) -> tuple[int, int, int]:
    """(d): session 1's shots answered, those kept after the flood, and the shots the flood got answered."""
    connector, played = connected(port, "127.0.0.2"), 0
    for number in range(300):
        played += code_of(connector, number) == 200
        time.sleep(1 / 150)  # under the per-connection rate limit
    connector.close()
    httpx.post(base + "/v1/sessions", json={}, timeout=10)
    answered, stop = [0] * 8, time.monotonic() + flood_s

    def flood(index: int) -> None:
        sock, number = connected(port), 0
        while time.monotonic() < stop and sum(answered) < FLOOD_SHOTS:
            if code_of(sock, number) == 200:
                answered[index] += 1
            else:  # closed for its rate: connect again, as a flood would
                sock.close()
                sock = connected(port)
            number += 1
        sock.close()

    threads = [threading.Thread(target=flood, args=(index,)) for index in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    first = httpx.get(base + "/v1/sessions", timeout=10).json()["sessions"][0]
    return played, first["shots"], sum(answered)


def counted(base: str, port: int, trials: int, flood_s: float) -> dict:
    """Every scenario's counts, each printed as it is counted."""
    waited, at_once = waiting_connector(base, port, trials)
    print(f"(a) connected first, first shot 0.3 s after 64 evictions: {waited} of {trials} Code 200")
    print(f"(b) connected during the flood, shot at once: {at_once} of {trials} Code 200")
    other_address = joined_during_flood(base, port, trials)
    print(f"(e) connected during a flood from another address, waited: {other_address} of {trials} Code 200")
    stream_status = viewer_places(base)
    print(f"(c) a 17th event stream past 16 held unread: HTTP {stream_status}")
    played, kept, answered = session_kept(base, port, flood_s)
    print(f"(d) session 1's {played} shots: {kept} kept after {answered} flood shots from another address")
    return {"a_connected_first_code_200": waited, "b_shot_at_once_code_200": at_once,
            "e_other_address_code_200": other_address, "c_17th_stream_http_status": stream_status,
            "d_session_1_played": played, "d_session_1_kept": kept, "d_flood_shots_answered": answered}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tree", type=Path, default=REPO)
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--flood-s", type=float, default=90.0)
    add_results_flag(parser, tracked=None)
    args = parser.parse_args()
    process, base, port = start_service(args.tree)
    try:
        counts = counted(base, port, args.trials, args.flood_s)
    finally:
        process.terminate()
        process.wait(60)
    save_results(args.results, {"script": "benchmarks/bench_places.py", "machine": machine(), "tree": str(args.tree),
                                "trials": args.trials, "flood_s": args.flood_s, "counts": counts})


if __name__ == "__main__":
    main()
