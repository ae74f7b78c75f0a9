"""What the wire costs with no application at all: the floor under `bench_wire.py`'s overheads on this machine.

python benchmarks/wire_floor.py [--rounds 3] [--requests 1500] [--work-us N]

Two servers in processes of their own, each spending `--work-us` of busy CPU per request (default: the in-process
7-iron's p50, measured first, so both sides sleep and wake as they do around a real flight) and answering a
1 kB body: an asyncio Protocol on uvloop that writes back what it got (Open Connect's shape), and a bare ASGI app on
uvicorn with uvloop and httptools (`golfflight serve`'s choice) answering a POST. Raw keep-alive socket clients (for
HTTP `server.RawHttp`, as in `bench_wire.py`) time round trips; the figure is the round trip minus the work. Prints
a table and --results FILE gets its `wire_floor` section.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import socket
import statistics
import subprocess
import sys
import time

from common import SEVEN_IRON, add_results_flag, write_results

ANSWER = json.dumps({f"figure_{i}": 123.456789 for i in range(48)}).encode()
BODY = json.dumps({"ball_speed_mps": SEVEN_IRON.ball_speed_mps, "launch_angle_deg": SEVEN_IRON.launch_angle_deg,
                   "spin_rpm": SEVEN_IRON.spin_rpm}).encode()


def busy(seconds: float) -> None:
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass


def serve_tcp(port: int, work: float) -> None:
    import uvloop

    class Echo(asyncio.Protocol):
        def connection_made(self, transport):
            self.transport = transport

        def data_received(self, data):
            busy(work)
            self.transport.write(ANSWER)

    async def main():
        server = await asyncio.get_running_loop().create_server(Echo, "127.0.0.1", port)
        await server.serve_forever()

    uvloop.run(main())


def serve_http(port: int, work: float) -> None:
    import uvicorn

    async def app(scope, receive, send):
        if scope["type"] != "http":
            return
        await receive()
        busy(work)
        headers = [(b"content-type", b"application/json"), (b"content-length", str(len(ANSWER)).encode())]
        await send({"type": "http.response.start", "status": 200, "headers": headers})
        await send({"type": "http.response.body", "body": ANSWER})

    uvicorn.run(app, host="127.0.0.1", port=port, log_level="warning", loop="uvloop", http="httptools",
                access_log=False)


def connected(port: int, timeout_s: float = 30.0) -> None:
    """Return once something listens on `port`."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=timeout_s).close()
            return
        except ConnectionRefusedError:
            assert time.monotonic() < deadline, "the floor server did not start"
            time.sleep(0.1)


class TcpClient:
    """A raw connection to the TCP floor server: the shot's bytes out, the 1 kB answer back."""

    def __init__(self, port: int):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=30)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def post(self) -> None:
        self.sock.sendall(BODY)
        received = 0
        while received < len(ANSWER):
            received += len(self.sock.recv(65536))


def timed(call) -> float:
    started = time.perf_counter()
    call()
    return time.perf_counter() - started


def in_process_p50() -> float:
    """The 7-iron's p50 in process (`contract.flying.fly_request`), seconds."""
    from golfflight.contract.flying import fly_request
    from golfflight.contract.requests import ShotRequest
    from golfflight.flight.bundle_location import model_dir
    from golfflight.flight.engine import FlightEngine

    engine, shot = FlightEngine(model_dir()), ShotRequest.model_validate_json(BODY)
    for _ in range(200):
        fly_request(engine, shot)
    seconds = []
    for _ in range(1000):
        started = time.perf_counter()
        fly_request(engine, shot)
        seconds.append(time.perf_counter() - started)
    return statistics.median(seconds)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--requests", type=int, default=1500)
    parser.add_argument("--work-us", type=float, help="busy CPU per request (default: the in-process 7-iron's p50)")
    parser.add_argument("--serve", nargs=3, metavar=("KIND", "PORT", "WORK_S"), help=argparse.SUPPRESS)
    add_results_flag(parser)
    args = parser.parse_args()
    if args.serve:
        kind, port, work = args.serve
        (serve_tcp if kind == "tcp" else serve_http)(int(port), float(work))
        return
    from server import RawHttp, free_port

    work = args.work_us / 1e6 if args.work_us is not None else in_process_p50()
    servers, clients = [], {}
    try:
        for kind in ("tcp", "http"):
            port = free_port()
            servers.append(subprocess.Popen([sys.executable, __file__, "--serve", kind, str(port), str(work)]))
            connected(port)
            clients[kind] = TcpClient(port) if kind == "tcp" else RawHttp(port, "/v1/shots", BODY)
        for client in clients.values():
            for _ in range(300):
                client.post()
        samples = {kind: [] for kind in clients}
        for _ in range(args.rounds):
            rounds = {kind: [] for kind in clients}
            for _ in range(args.requests):
                for kind, client in clients.items():
                    rounds[kind].append(timed(client.post))
            for kind in clients:
                samples[kind].append(statistics.median(rounds[kind]) - work)
    finally:
        for process in servers:
            process.terminate()
            process.wait(30)
    names = {"tcp": "TCP: an asyncio Protocol on uvloop answering 1 kB", "http": "HTTP: a bare ASGI app on uvicorn "
             "(uvloop, httptools) answering 1 kB"}
    rows = [{"name": f"{names[kind]}, round trip p50 minus {work * 1e3:.3f} ms of work", "unit": "ms",
             "p50": statistics.median(samples[kind]) * 1e3, "per_round_ms": [s * 1e3 for s in samples[kind]]}
            for kind in clients]
    print(f"\nThe wire's floor: {args.rounds} rounds x {args.requests} requests each way, interleaved, "
          f"{work * 1e6:.0f} us of busy work a request\n")
    print("| server | p50 beyond the work | per round |")
    print("|---|---:|---|")
    for row in rows:
        print(f"| {row['name']} | {row['p50']:.3f} ms | {', '.join(f'{r:.3f}' for r in row['per_round_ms'])} |")
    write_results("wire_floor", rows, args.results)


if __name__ == "__main__":
    main()
