"""Where one HTTP single shot's time goes, end to end: client, transport, uvicorn, routing, validation, the flight,
result building and serialisation. Prints a table (mean microseconds per request).

python benchmarks/profile_wire.py [--requests 3000] [--loop auto|asyncio|uvloop] [--http auto|h11|httptools]
                                  [--tree DIR]

A sampling profiler on a 2-core machine takes a core from the very processes it watches, and cProfile multiplies
the cost of every small Python call (the flight's 62 ORT calls most of all), so neither gives the split in real
time. This script instead wraps the few functions that bound each part with `time.perf_counter` (a few hundred
nanoseconds each) in a server process of its own (the service of `--tree`, default this checkout, on uvicorn with
`golfflight serve`'s options), sends keep-alive 7-iron requests from an httpx client, and subtracts: whatever the
server's ASGI app spends outside the wrapped parts is routing, middleware and FastAPI's own glue; whatever the
client waits beyond the server's work and its own CPU is the loopback and the two event loops' scheduling.
"""

from __future__ import annotations

import argparse
import asyncio
import functools
import json
import os
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

import httpx

SHOT = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
TOTALS: dict[str, float] = defaultdict(float)
"""Seconds spent in each wrapped part (server process), summed over the measured requests."""


def _timed(name: str, function):
    """`function` (plain or async) adding its own duration to TOTALS[name]."""
    if asyncio.iscoroutinefunction(function):

        @functools.wraps(function)
        async def timed_async(*args, **kwargs):
            started = time.perf_counter()
            try:
                return await function(*args, **kwargs)
            finally:
                TOTALS[name] += time.perf_counter() - started

        return timed_async

    @functools.wraps(function)
    def timed(*args, **kwargs):
        started = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            TOTALS[name] += time.perf_counter() - started

    return timed


def _wrap(owner, attribute: str, name: str) -> None:
    if hasattr(owner, attribute):
        setattr(owner, attribute, _timed(name, getattr(owner, attribute)))


PARTS = (
    ("uvicorn: parse the request, start its task", "parse"),
    ("uvicorn: write the response", "send"),
    ("body read + JSON parse (json.loads)", "json"),
    ("request validation (pydantic) + dependencies (FastAPI's path; the direct path's model_validate_json)",
     "validate"),
    ("bay's conditions merged in", "bay"),
    ("the flight (FlightEngine.fly)", "flight"),
    ("result building (ShotResult.model_construct)", "result"),
    ("response serialisation (model_dump_json / Response)", "serialise"),
    ("metrics: simulation histogram + window", "record"),
)


class _TimedModel:
    """Stands in for a direct route's body model (`service.api.direct`), timing its one validation."""

    def __init__(self, model):
        self.model = model

    def model_validate_json(self, data):
        started = time.perf_counter()
        try:
            return self.model.model_validate_json(data)
        finally:
            TOTALS["validate"] += time.perf_counter() - started


def _time_direct_validation() -> None:
    """Time the direct path's validation, in a tree that has one (a body read once by `model_validate_json`)."""
    try:
        from golfflight.service.api.direct import DirectRoute
        from golfflight.service.api.routes import gspro, shots
    except ImportError:
        return
    for route in [*shots.router.routes, *gspro.router.routes]:
        if isinstance(route, DirectRoute):
            route.body_model = _TimedModel(route.body_model)


def serve(port: int, loop: str, http: str) -> None:
    """The service on uvicorn with the parts wrapped; GET /_profile answers TOTALS and resets them."""
    import fastapi.routing
    import golfflight.service.runtime.runtime as bay_runtime
    import pydantic
    import starlette.requests
    import starlette.responses
    import uvicorn
    from golfflight.contract import flying
    from golfflight.flight.engine import FlightEngine
    from golfflight.service.app import create_app
    from uvicorn.protocols.http import h11_impl

    try:  # httptools_impl imports httptools itself
        from uvicorn.protocols.http import httptools_impl
    except ImportError:
        httptools_impl = None
    if httptools_impl is not None:
        _wrap(httptools_impl.HttpToolsProtocol, "data_received", "parse")
        _wrap(httptools_impl.RequestResponseCycle, "send", "send")
    _wrap(h11_impl.H11Protocol, "data_received", "parse")
    _wrap(h11_impl.RequestResponseCycle, "send", "send")
    _wrap(starlette.requests.Request, "json", "json")
    _wrap(fastapi.routing, "solve_dependencies", "validate")
    _time_direct_validation()
    _wrap(bay_runtime, "in_bay", "bay")
    _wrap(FlightEngine, "fly", "flight")
    _wrap(flying, "result_of", "result")
    _wrap(pydantic.BaseModel, "model_dump_json", "serialise")
    _wrap(starlette.responses.Response, "__init__", "serialise")
    _wrap(bay_runtime.BayRuntime, "_record_simulation", "record")

    inner = create_app()

    async def app(scope, receive, send):
        if scope["type"] == "http" and scope["path"] == "/_profile":
            body = json.dumps(TOTALS).encode()
            TOTALS.clear()
            await send({"type": "http.response.start", "status": 200, "headers": []})
            await send({"type": "http.response.body", "body": body})
            return
        started = time.perf_counter()
        try:
            await inner(scope, receive, send)
        finally:
            TOTALS["app"] += time.perf_counter() - started

    config = uvicorn.Config(app, host="127.0.0.1", port=port, loop=loop, http=http, log_level="warning",
                            access_log=False)
    uvicorn.Server(config).run()


def measure(args: argparse.Namespace) -> None:
    from server import free_port

    port = free_port()
    tree = Path(args.tree).resolve()
    command = [sys.executable, str(Path(__file__).resolve()), "--serve", str(port), "--loop", args.loop,
               "--http", args.http]
    server = subprocess.Popen(command, cwd=tree, env={**os.environ, "PYTHONPATH": str(tree)})
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=30) as client:
            deadline = time.monotonic() + 60
            while True:
                try:
                    if client.get("/healthz").status_code == 200:
                        break
                except httpx.TransportError:
                    pass
                assert time.monotonic() < deadline, "the server did not start"
                time.sleep(0.1)
            for _ in range(500):
                client.post("/v1/shots", json=SHOT).json()
            client.get("/_profile")
            walls = []
            cpu = time.process_time()
            for _ in range(args.requests):
                started = time.perf_counter()
                client.post("/v1/shots", json=SHOT).json()
                walls.append(time.perf_counter() - started)
            cpu = time.process_time() - cpu
            server_side = client.get("/_profile").json()
    finally:
        server.terminate()
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            server.kill()
    n = args.requests
    us = {name: seconds / n * 1e6 for name, seconds in server_side.items()}
    wall = sum(walls) / n * 1e6
    walls.sort()
    client_cpu = cpu / n * 1e6
    inside = sum(us.get(key, 0.0) for _, key in PARTS if key != "parse")
    routing = us["app"] - inside
    transport = wall - client_cpu - us["app"] - us.get("parse", 0.0)
    rows = [("client (httpx: build the request, parse the JSON answer)", client_cpu),
            ("loopback + both event loops (the rest of the wall time)", transport),
            (PARTS[0][0], us.get("parse", 0.0)),
            ("routing + middleware + FastAPI's glue (the app's time outside the rows below)", routing)]
    rows += [(label, us.get(key, 0.0)) for label, key in PARTS[1:]]
    print(f"\n{n} keep-alive 7-iron requests, loop={args.loop}, http={args.http}, tree {tree}\n")
    print("| part | mean per request | share |")
    print("|---|---:|---:|")
    for label, value in rows:
        print(f"| {label} | {value:.0f} us | {value / wall:.0%} |")
    print(f"| **whole request, client's wall clock** (p50 {walls[n // 2] * 1e3:.3f} ms) | {wall:.0f} us | 100% |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--requests", type=int, default=3000)
    parser.add_argument("--loop", default="auto", help="uvicorn's event loop: auto, asyncio or uvloop")
    parser.add_argument("--http", default="auto", help="uvicorn's HTTP parser: auto, h11 or httptools")
    parser.add_argument("--tree", default=str(Path(__file__).resolve().parents[1]),
                        help="the checkout whose service is profiled (e.g. a git worktree of an older commit)")
    parser.add_argument("--serve", type=int, metavar="PORT", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.serve:
        sys.path.insert(0, os.getcwd())
        serve(args.serve, args.loop, args.http)
    else:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        measure(args)


if __name__ == "__main__":
    main()
