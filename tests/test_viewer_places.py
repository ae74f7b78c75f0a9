"""The viewer's places (issue 55, item 8): sixteen event streams held open and idle used to lock every screen out
(503 "16 viewers are open already") for as long as they stayed. Now a new stream takes the place of the oldest stream
of the address that holds the most, which ends with a comment saying so. A real uvicorn server, raw sockets that
open streams and never read them, and the page in a real headless Chromium."""

from __future__ import annotations

import socket
import time

import browser
import pytest
from golfflight.service.app import create_app
from golfflight.service.runtime.feed import MAX_VIEWERS
from golfflight.service.settings import ServiceSettings
from servers import free_port, running

KEY = "viewer-places-key"
KEYED = {"x-api-key": KEY}
DRIVER = {"ball_speed_mph": 167.0, "launch_angle_deg": 10.9, "back_spin_rpm": 2686.0, "side_spin_rpm": -250.0}
GAVE_WAY = b"closed to make room for a new stream"


def idle_stream(port: int, source: str = "127.0.0.1") -> socket.socket:
    """A stream opened from `source` (an address of the loopback network) and never read."""
    sock = socket.socket()
    sock.bind((source, 0))
    sock.connect(("127.0.0.1", port))
    sock.sendall(f"GET /v1/events HTTP/1.1\r\nHost: bay\r\nX-API-Key: {KEY}\r\n\r\n".encode())
    return sock


def open_streams(app, count: int) -> None:
    """Wait until `count` streams are open."""
    deadline = time.monotonic() + 10
    while len(app.state.runtime._feed.viewers) < count:
        assert time.monotonic() < deadline, "the streams were not opened"
        time.sleep(0.02)


def ended(sock: socket.socket, timeout_s: float = 5.0) -> bytes:
    """What the stream sent, read once it has ended (its last chunk), or within `timeout_s`."""
    sock.settimeout(timeout_s)
    data = b""
    deadline = time.monotonic() + timeout_s
    while not data.endswith(b"0\r\n\r\n") and time.monotonic() < deadline:
        try:
            received = sock.recv(65536)
        except (TimeoutError, OSError):
            break
        if not received:
            break
        data += received
    return data


def close_all(sockets: list[socket.socket]) -> None:
    for sock in sockets:
        sock.close()


@pytest.fixture()
def served():
    app = create_app(ServiceSettings(api_key=KEY))
    with running(app) as http:
        yield http, app


def test_streams_held_from_one_address_give_way_to_a_stream_from_another_and_push_out_only_their_own(served):
    http, app = served
    held = [idle_stream(http.base_url.port, "127.0.0.2") for _ in range(MAX_VIEWERS)]
    open_streams(app, MAX_VIEWERS)
    screen = idle_stream(http.base_url.port)  # a screen elsewhere: the oldest held stream gives way
    assert GAVE_WAY in ended(held[0])
    more = [idle_stream(http.base_url.port, "127.0.0.2") for _ in range(MAX_VIEWERS)]  # the holder's own go
    for sock in held[1:]:
        assert GAVE_WAY in ended(sock)
    open_streams(app, MAX_VIEWERS)
    clients = [viewer.client for viewer in app.state.runtime._feed.viewers]
    assert clients.count("127.0.0.1") == 1 and clients.count("127.0.0.2") == MAX_VIEWERS - 1
    screen.settimeout(0.5)
    assert GAVE_WAY not in screen.recv(65536)  # the screen's stream: its session event, still open
    close_all([*held, *more, screen])


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_the_page_goes_live_and_shows_shots_past_sixteen_idle_streams(served):
    http, app = served
    held = [idle_stream(http.base_url.port) for _ in range(MAX_VIEWERS)]
    open_streams(app, MAX_VIEWERS)
    base = str(http.base_url).rstrip("/")
    with browser.headless_page() as page:
        page.goto(f"{base}/viewer#key={KEY}")
        page.wait_for_selector("#status[data-state=live]", timeout=10_000)
        assert http.post("/v1/shots?viewer=1", json=DRIVER, headers=KEYED).status_code == 200
        page.wait_for_selector("#shots tbody tr[data-shot='1']", timeout=10_000)
    assert GAVE_WAY in ended(held[0])  # the oldest idle stream gave its place
    close_all(held)
