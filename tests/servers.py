"""A real uvicorn server on 127.0.0.1 in a thread for tests that need one (the service as clients see it), on the
event loop and HTTP parser `golfflight serve` picks (`fast_io`)."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

import httpx
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
