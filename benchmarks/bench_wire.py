"""The wire's cost as a difference in one run: a 7-iron flown in process, over HTTP (keep-alive, from httpx and from a
raw socket) and over GSPro Open Connect TCP, interleaved shot by shot, and a batch of 1,024 in process and over HTTP,
interleaved run by run.
Prints a table (overhead in ms beside the absolute figures, and the ratio), --results FILE gets its `wire` section.

python benchmarks/bench_wire.py [--rounds 5] [--shots 500] [--batches 3]
python benchmarks/bench_wire.py --versus ../wt25-before --versus-without uvloop httptools   # before/after A/B

Everything runs in one process tree on the same cores at the same time, so the machine's drift (which moves
absolute figures by 10-30 % from minute to minute) cancels out of the differences. The in-process figure is
`contract.flying.fly_request` on a parsed request, the work `GET /v1/latency` times as the server's simulation (the
flight rolled to rest and its result object); the batch's is `fly_requests` on the parsed shots. `--versus TREE` also
serves the service of another checkout (e.g. a `git worktree` of an older commit) and alternates the two servers
shot by shot and run by run; `--versus-without MODULE...` hides modules from that server only (so that a baseline
whose dependencies did not include them runs as it would have been installed), and the table gains the paired
per-round ratios after / before.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import statistics
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np
from common import REPO, SEVEN_IRON, add_results_flag, mixed_launches, write_results
from golfflight.contract.flying import fly_request, fly_requests
from golfflight.contract.requests import BatchRequest, ShotRequest
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine
from server import RawHttp, Server, free_port, start

SHOT = {
    "ball_speed_mps": SEVEN_IRON.ball_speed_mps,
    "launch_angle_deg": SEVEN_IRON.launch_angle_deg,
    "spin_rpm": SEVEN_IRON.spin_rpm,
}
MPH_PER_MPS = 1 / 0.44704
CONNECT_MESSAGE = json.dumps({
    "DeviceID": "bench",
    "Units": "Yards",
    "ShotNumber": 1,
    "APIversion": "1",
    "BallData": {"Speed": SEVEN_IRON.ball_speed_mps * MPH_PER_MPS, "SpinAxis": 0.0, "TotalSpin": SEVEN_IRON.spin_rpm,
                 "HLA": 0.0, "VLA": SEVEN_IRON.launch_angle_deg},
    "ShotDataOptions": {"ContainsBallData": True, "ContainsClubData": False},
}).encode()


class Connector:
    """One Open Connect connection, as a launch monitor's connector holds it: a message out, its reply in."""

    def __init__(self, port: int):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=30)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def fly(self) -> dict:
        self.sock.sendall(CONNECT_MESSAGE)
        data = b""
        while True:
            data += self.sock.recv(65536)
            try:
                reply = json.loads(data)
            except ValueError:
                continue
            assert reply["Code"] == 200, reply
            return reply

    def close(self) -> None:
        self.sock.close()


class Service:
    """One `golfflight serve` (HTTP and Open Connect) under test, its clients and its samples."""

    def __init__(self, name: str, tree: Path, hidden: list[str]):
        self.name = name
        connect = free_port()
        env = {"GOLFFLIGHT_CONNECT_PORT": str(connect)}
        if hidden:
            shim = Path(tempfile.mkdtemp(prefix="bench-wire-"))
            for module in hidden:  # import fails as if the package were not installed
                (shim / f"{module}.py").write_text(f"raise ImportError('{module} hidden by bench_wire')\n")
            env["PYTHONPATH"] = f"{shim}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"
        self.server: Server = start(1, env=env, tree=tree)
        self.http = httpx.Client(base_url=self.server.base_url, timeout=120)
        self.tcp = Connector(connect)
        self.raw = RawHttp(self.server.port, "/v1/shots", json.dumps(SHOT).encode())
        self.single, self.raw_single, self.connect, self.batch, self.flight_p50, self.viewer = [], [], [], [], [], []

    def viewer_events(self, shots: int, round_: int) -> list[float]:
        """Seconds from sending a shot with ?viewer=true to its event arriving on an open GET /v1/events stream
        (the event rendered, its trajectory flown again, and streamed), for `shots` shots each told apart by its
        ball speed. The stream is opened here and closed after: an open one renders every Open Connect shot too."""
        seconds = []
        with self.http.stream("GET", "/v1/events") as stream:
            lines = stream.iter_lines()
            for i in range(-1, shots):  # the first, untimed, waits out the kept shots the stream opens with
                speed = round(50.0 + round_ + i / 1000, 4)
                body = json.dumps({**SHOT, "ball_speed_mps": speed}).encode()
                started = time.perf_counter()
                self.post("/v1/shots?viewer=true", body)
                for line in lines:
                    event = json.loads(line[6:]) if line.startswith("data: ") else {}
                    if event.get("launch", {}).get("ball_speed_mps") == speed:  # a session's event has no launch
                        break
                if i >= 0:
                    seconds.append(time.perf_counter() - started)
        return seconds

    def post(self, path: str, body: bytes) -> dict:
        response = self.http.post(path, content=body, headers={"content-type": "application/json"})
        assert response.status_code == 200, response.text
        return response.json()

    def close(self) -> None:
        self.http.close()
        self.raw.close()
        self.tcp.close()
        self.server.stop()


def timed(call) -> float:
    started = time.perf_counter()
    call()
    return time.perf_counter() - started


def p(samples: list[float], q: float) -> float:
    """The q-th percentile of `samples` (seconds) in milliseconds."""
    return float(np.percentile(samples, q)) * 1e3


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--shots", type=int, default=500, help="single shots a round, each way")
    parser.add_argument("--batches", type=int, default=3, help="batches of 1,024 a round, each way")
    parser.add_argument("--viewer-shots", type=int, default=50, help="shots a round sent to the viewer's stream")
    parser.add_argument("--versus", metavar="TREE", help="also serve this checkout's service, alternating with ours")
    parser.add_argument("--versus-without", nargs="*", default=[], metavar="MODULE",
                        help="modules hidden from the --versus server (as if not installed)")
    add_results_flag(parser)
    return parser.parse_args()


def warm_up(
    services: list[Service], engine: FlightEngine, shot, shot_body: bytes, batch_shots, batch_body: bytes
) -> None:
    """Connections, caches and the batch process, before anything is timed."""
    for service in services:
        for _ in range(200):
            service.post("/v1/shots", shot_body)
            service.raw.post()
            service.tcp.fly()
        service.post("/v1/shots/batch", batch_body)
    for _ in range(200):
        fly_request(engine, shot)
    fly_requests(engine, batch_shots)


def one_round(round_: int, args: argparse.Namespace, services: list[Service], engine: FlightEngine, shot,
              shot_body: bytes, batch_shots, batch_body: bytes) -> tuple[list[float], list[float]]:
    """One round, every way interleaved shot by shot and batch by batch; the services keep their own timings, the
    in-process single shots and batches are returned."""
    own = []
    http, raw, tcp = ({s.name: [] for s in services} for _ in range(3))
    for i in range(args.shots):
        order = services if (i + round_) % 2 == 0 else services[::-1]
        own.append(timed(lambda: fly_request(engine, shot)))
        for service in order:
            http[service.name].append(timed(lambda s=service: s.post("/v1/shots", shot_body)))
        for service in order:
            raw[service.name].append(timed(service.raw.post))
        for service in order:
            tcp[service.name].append(timed(service.tcp.fly))
    for service in services:
        service.single.append(http[service.name])
        service.raw_single.append(raw[service.name])
        service.connect.append(tcp[service.name])
        service.flight_p50.append(service.http.get("/v1/latency").json()["simulation"]["p50_ms"])
    runs, batch = [], {s.name: [] for s in services}
    for j in range(args.batches):
        runs.append(timed(lambda: fly_requests(engine, batch_shots)))
        for service in services if (j + round_) % 2 == 0 else services[::-1]:
            batch[service.name].append(timed(lambda s=service: s.post("/v1/shots/batch", batch_body)))
    for service in services:
        service.batch.append(batch[service.name])
    for service in services if round_ % 2 == 0 else services[::-1]:
        service.viewer.append(service.viewer_events(args.viewer_shots, round_))
    print(f"round {round_ + 1}/{args.rounds}: in process {p(own, 50):.3f} ms, "
          + ", ".join(f"{s.name} HTTP {p(s.single[-1], 50):.3f} ms (raw client {p(s.raw_single[-1], 50):.3f} ms), "
                      f"TCP {p(s.connect[-1], 50):.3f} ms, "
                      f"batch {statistics.median(s.batch[-1]) * 1e3:.1f} ms" for s in services)
          + f", batch in process {statistics.median(runs) * 1e3:.1f} ms", flush=True)
    return own, runs


def median_of_rounds(rounds: list[list[float]], q: float) -> float:
    return statistics.median(p(samples, q) for samples in rounds)


def service_rows(service: Service, label: str, flight: float, flight_batch: float) -> list[dict]:
    """One service's rows: its own flight, HTTP and TCP single shots, the batch and the viewer, against in process."""
    server_flight = statistics.median(service.flight_p50)
    single, single99 = median_of_rounds(service.single, 50), median_of_rounds(service.single, 99)
    raw, raw99 = median_of_rounds(service.raw_single, 50), median_of_rounds(service.raw_single, 99)
    connect = median_of_rounds(service.connect, 50)
    batch = statistics.median(statistics.median(r) for r in service.batch) * 1e3
    return [
        {"name": f"server's own flight (/v1/latency){label}", "unit": "ms", "p50": server_flight},
        {"name": f"HTTP single shot, keep-alive{label}", "unit": "ms", "p50": single, "p99": single99,
         "over_in_process_ms": single - flight, "over_server_flight_ms": single - server_flight,
         "ratio_to_in_process": single / flight,
         "target": "p50 <= server's flight + 0.5 ms, p99 <= 2.5 ms",
         "met": single <= server_flight + 0.5 and single99 <= 2.5},
        {"name": f"HTTP single shot, keep-alive raw socket client{label}", "unit": "ms", "p50": raw, "p99": raw99,
         "over_in_process_ms": raw - flight, "over_server_flight_ms": raw - server_flight,
         "ratio_to_in_process": raw / flight,
         "target": "p50 <= server's flight + 0.5 ms, p99 <= 2.5 ms",
         "met": raw <= server_flight + 0.5 and raw99 <= 2.5},
        {"name": f"Open Connect TCP reply{label}", "unit": "ms", "p50": connect,
         "p99": median_of_rounds(service.connect, 99), "over_in_process_ms": connect - flight,
         "over_server_flight_ms": connect - server_flight, "ratio_to_in_process": connect / flight,
         "target": "p50 <= server's flight + 0.3 ms", "met": connect <= server_flight + 0.3},
        {"name": f"HTTP batch of 1,024{label}", "unit": "ms", "p50": batch,
         "p99": statistics.median(max(r) for r in service.batch) * 1e3, "over_in_process_ms": batch - flight_batch,
         "ratio_to_in_process": batch / flight_batch, "target": "<= 1.5 x in process",
         "met": batch <= 1.5 * flight_batch},
        {"name": f"viewer: shot sent to its event on the stream{label}", "unit": "ms",
         "p50": median_of_rounds(service.viewer, 50), "p99": median_of_rounds(service.viewer, 99)},
    ]


def paired_rows(after: Service, before: Service, rounds: int) -> list[dict]:
    """after / before, round by round (the same minute of the machine's drift on both sides)."""
    rows = []
    for what, pick in (("HTTP single shot p50", lambda s, r: p(s.single[r], 50)),
                       ("HTTP single shot p99", lambda s, r: p(s.single[r], 99)),
                       ("HTTP single shot p50, raw socket client", lambda s, r: p(s.raw_single[r], 50)),
                       ("Open Connect TCP reply p50", lambda s, r: p(s.connect[r], 50)),
                       ("HTTP batch of 1,024", lambda s, r: statistics.median(s.batch[r]) * 1e3),
                       ("viewer event p50", lambda s, r: p(s.viewer[r], 50))):
        ratios = [pick(after, r) / pick(before, r) for r in range(rounds)]
        rows.append({"name": f"after / before: {what}", "unit": "", "per_round": ratios,
                     "p50": statistics.median(ratios)})
    return rows


def print_rows(rows: list[dict], args: argparse.Namespace) -> None:
    print(f"\nThe wire, {args.rounds} rounds x {args.shots} shots and {args.batches} batches each way (medians of the"
          " rounds; overhead = the figure minus the in-process one)\n")
    print("| measurement | p50 | p99 | overhead vs in process | vs server's flight | ratio to in process | met |")
    print("|---|---:|---:|---:|---:|---:|---|")
    for row in rows:
        if "per_round" in row:
            print(f"| {row['name']} | {row['p50']:.2f} (per round: "
                  f"{', '.join(f'{r:.2f}' for r in row['per_round'])}) | | | | | |")
            continue
        cells = [f"{row['p50']:.3f} ms", f"{row['p99']:.3f} ms" if row.get("p99") is not None else "",
                 f"+{row['over_in_process_ms']:.3f} ms" if "over_in_process_ms" in row else "",
                 f"+{row['over_server_flight_ms']:.3f} ms" if "over_server_flight_ms" in row else "",
                 f"{row['ratio_to_in_process']:.2f}x" if "ratio_to_in_process" in row else "",
                 ("yes" if row["met"] else "NO") + f" ({row['target']})" if "met" in row else ""]
        print(f"| {row['name']} | " + " | ".join(cells) + " |")


def main() -> None:
    args = parse_args()
    engine = FlightEngine(model_dir())
    shot = ShotRequest.model_validate(SHOT)
    shot_body = json.dumps(SHOT).encode()
    batch_body = json.dumps({"shots": [launch._asdict() for launch in mixed_launches(1024)]}).encode()
    batch_shots = BatchRequest.model_validate_json(batch_body).shots
    services = [Service("after" if args.versus else "this tree", REPO, [])]
    if args.versus:
        services.append(Service("before", Path(args.versus).resolve(), args.versus_without))
    inprocess, inprocess_batch = [], []
    try:
        warm_up(services, engine, shot, shot_body, batch_shots, batch_body)
        for round_ in range(args.rounds):
            own, runs = one_round(round_, args, services, engine, shot, shot_body, batch_shots, batch_body)
            inprocess.append(own)
            inprocess_batch.append(runs)
    finally:
        for service in services:
            service.close()
    flight = median_of_rounds(inprocess, 50)
    flight_batch = statistics.median(statistics.median(r) for r in inprocess_batch) * 1e3
    rows = [{"name": "in process: one 7-iron (fly_request)", "unit": "ms", "p50": flight,
             "p99": median_of_rounds(inprocess, 99)},
            {"name": "in process: batch of 1,024 (fly_requests)", "unit": "ms", "p50": flight_batch}]
    for service in services:
        rows += service_rows(service, "" if len(services) == 1 else f" [{service.name}]", flight, flight_batch)
    if len(services) == 2:
        rows += paired_rows(*services, args.rounds)
    print_rows(rows, args)
    write_results("wire", rows, args.results)


if __name__ == "__main__":
    main()
