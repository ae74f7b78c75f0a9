"""A real uvicorn server on 127.0.0.1 in a thread for tests that need one (the service as clients see it), on the
event loop and HTTP parser `golfflight serve` picks (`fast_io`); a real `golfflight serve` process for tests that
measure its memory."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

import httpx
import psutil
import uvicorn

from golfflight.commands.serve import fast_io


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@contextmanager
def running(app, ready_path: str = "/healthz", timeout_s: float = 120.0, http=None) -> Iterator[httpx.Client]:
    """Serve `app` on a free loopback port until the block ends; yields a keep-alive client, once `ready_path`
    answers 200 (or any answer, for apps whose model is meant to fail). `http`: another HTTP protocol class than
    `serve`'s (e.g. one with shorter request deadlines)."""
    port = free_port()
    io = {**fast_io(), **({"http": http} if http is not None else {})}
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", **io))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=30) as http:
            deadline = time.monotonic() + timeout_s
            while True:
                try:
                    answer = http.get(ready_path)
                    if answer.status_code == 200 or answer.json().get("status") == "failed":
                        break
                except (httpx.TransportError, ValueError):
                    pass
                assert time.monotonic() < deadline, "the service did not become ready"
                time.sleep(0.05)
            yield http
    finally:
        server.should_exit = True
        thread.join(timeout=10)


@contextmanager
def keyed_service(key: str) -> Iterator[tuple[httpx.Client, int, object]]:
    """(client, Open Connect port, app) of one service with an API key, listening on HTTP and on Open Connect TCP."""
    from golfflight.service.app import create_app
    from golfflight.service.settings import ServiceSettings

    port = free_port()
    app = create_app(ServiceSettings(api_key=key, connect_port=port))
    with running(app) as http:
        yield http, port, app


def shot(http: httpx.Client, **body) -> dict:
    """POST one shot to /v1/shots, asserting a 200, and return its JSON."""
    response = http.post("/v1/shots", json=body)
    assert response.status_code == 200, response.text
    return response.json()


@contextmanager
def serve_process(log: Path) -> Iterator[tuple[psutil.Process, httpx.Client]]:
    """(server process, keep-alive client) of a real `golfflight serve` on a free loopback port (its output in
    `log`; none of this environment's GOLFFLIGHT_* settings), once /healthz answers 200; it and its children (the
    batch process) are killed at the end."""
    port = free_port()
    command = [sys.executable, "-m", "golfflight", "serve", "--port", str(port)]
    inherited = {key: value for key, value in os.environ.items() if not key.startswith("GOLFFLIGHT_")}
    with open(log, "w") as output:
        popen = subprocess.Popen(command, env=inherited, stdout=output, stderr=subprocess.STDOUT)
    server = psutil.Process(popen.pid)
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=60) as http:
            deadline = time.monotonic() + 90
            while not _ready(http):
                assert time.monotonic() < deadline and popen.poll() is None, log.read_text()
                time.sleep(0.05)
            yield server, http
    finally:
        children = server.children(recursive=True) if popen.poll() is None else []
        popen.kill()
        popen.wait(30)
        for child in children:
            with suppress(psutil.NoSuchProcess):
                child.kill()


def _ready(http: httpx.Client) -> bool:
    try:
        return http.get("/healthz").status_code == 200
    except httpx.TransportError:
        return False


def flight_of(answer: dict) -> dict:
    """An answer's flight without what it says it flew in (`flown_in`): the same conditions given in two forms (mph
    or m/s, a ground given or left out, from the shot or from the bay) fly the same numbers but echo their own."""
    return {key: value for key, value in answer.items() if key != "flown_in"}
