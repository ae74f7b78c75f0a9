"""Issue 55, one hostile client on the bay's network, over real sockets: a request head is bounded (431) and a client
looping 8 MiB headers leaves a real `golfflight serve`'s memory bounded (item 1); answers a client never reads end
after the write deadline and unread session downloads hold no session's rows (item 5); a web page of another origin
cannot start sessions in a real Chromium, the service's own page can (item 6); the key is checked before any body is
read (item 7); /healthz names no directory and malformed requests write one log line, not one each (item 10)."""

from __future__ import annotations

import asyncio
import csv
import io
import json
import logging
import socket
import threading
import time
from collections.abc import Iterator
from contextlib import suppress
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import browser
import httpx
import psutil
import pytest
from golfflight.contract.flying import fly_request
from golfflight.contract.requests import ShotRequest
from golfflight.service.api.http_protocol import MAX_HEAD_BYTES, DeadlineHttpProtocol
from golfflight.service.app import create_app
from golfflight.service.runtime.feed import ShotFeed
from golfflight.service.settings import ServiceSettings
from golfflight.service.viewer.loop_turns import LoopTurns
from golfflight.service.viewer.session_csv import session_csv_slices
from servers import free_port, running, serve_process

SHOT = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
KEY = "hostile-network-key"


class _QuickWrites(DeadlineHttpProtocol):
    write_timeout_s = 0.5


@pytest.fixture(scope="module")
def bay(tmp_path_factory):
    """(client, bay file) of one in-process service without a key, writes unread for 0.5 s closing a connection."""
    path = tmp_path_factory.mktemp("bay dir") / "bay.json"
    with running(create_app(ServiceSettings(bay_file=path)), http=_QuickWrites) as http:
        yield http, path


@pytest.fixture(scope="module")
def served(tmp_path_factory) -> Iterator[tuple[psutil.Process, int]]:
    """(process, port) of a real `golfflight serve` without a key."""
    with serve_process(tmp_path_factory.mktemp("serve") / "serve.log") as (server, http):
        yield server, http.base_url.port


def _answer(port: int, request: bytes) -> bytes:
    """What the server sends for `request` until it closes the connection (or resets it)."""
    with socket.create_connection(("127.0.0.1", port), timeout=20) as sock:
        sock.sendall(request)
        received = b""
        with suppress(ConnectionResetError):
            while chunk := sock.recv(65536):
                received += chunk
        return received


def _head_of(size: int) -> bytes:
    """A GET /healthz whose request line and headers are `size` bytes."""
    start, end = b"GET /healthz HTTP/1.1\r\nhost: localhost\r\nconnection: close\r\nx-pad: ", b"\r\n\r\n"
    return start + b"a" * (size - len(start) - len(end)) + end


def test_a_request_head_over_the_limit_is_refused_431_and_one_under_it_is_answered(bay):
    port = bay[0].base_url.port
    under = _answer(port, _head_of(MAX_HEAD_BYTES - 512))
    over = _answer(port, _head_of(MAX_HEAD_BYTES + 512)[:-4])  # unfinished: the limit, not the end, refuses it
    assert under.startswith(b"HTTP/1.1 200"), under[:200]
    assert over.startswith(b"HTTP/1.1 431") and f"the limit is {MAX_HEAD_BYTES:,} bytes".encode() in over, over[:300]


def _rss_mib(server: psutil.Process) -> float:
    return server.memory_info().rss / 2**20


def _huge_head(port: int, size: int) -> socket.socket:
    """A connection that sent a request line and one header of `size` bytes, as fast as the server took them, and
    stays open (a hostile loop that never closes what it opened)."""
    piece = b"a" * 256 * 1024
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    with suppress(BrokenPipeError, ConnectionResetError):
        sock.sendall(b"GET /healthz HTTP/1.1\r\nhost: localhost\r\nx-pad: ")
        for _ in range(size // len(piece)):
            sock.sendall(piece)
    return sock


def test_clients_looping_8_mib_headers_leave_a_real_servers_memory_bounded(served):
    server, port = served
    before, peak, opened = _rss_mib(server), 0.0, []
    until = time.monotonic() + 3.0

    def loop():
        while time.monotonic() < until:
            opened.append(_huge_head(port, 8 * 2**20))

    clients = [threading.Thread(target=loop) for _ in range(3)]
    for client in clients:
        client.start()
    try:
        while any(client.is_alive() for client in clients):
            peak = max(peak, _rss_mib(server))
            time.sleep(0.05)
    finally:
        for sock in opened:
            sock.close()
    assert peak - before < 64, f"{len(opened)} heads of 8 MiB: RSS {before:.0f} MiB -> peak {peak:.0f} MiB"
    assert _answer(port, _head_of(200)).startswith(b"HTTP/1.1 200")


def test_an_answer_its_client_never_reads_ends_after_the_write_deadline(bay):
    """A 10,000-shot batch whose answer (several MiB) is not read: the server stops writing when the sockets' buffers
    are full, and after its write deadline (0.5 s here) ends the connection instead of keeping the rest in memory."""
    body = json.dumps({"shots": [SHOT] * 10_000}).encode()
    head = b"POST /v1/shots/batch HTTP/1.1\r\nhost: localhost\r\ncontent-type: application/json\r\n"
    with socket.create_connection(("127.0.0.1", bay[0].base_url.port), timeout=20) as sock:
        sock.sendall(head + b"content-length: %d\r\n\r\n" % len(body) + body)
        sock.recv(1, socket.MSG_PEEK)  # the batch has flown: its answer is being written (nothing taken)
        time.sleep(2.0)  # the buffers fill, the writes pause, the deadline passes
        received = b""
        with suppress(ConnectionResetError):
            while chunk := sock.recv(1 << 20):
                received += chunk
    answer_head, _, answer = received.partition(b"\r\n\r\n")
    assert answer_head.startswith(b"HTTP/1.1 200"), answer_head[:200]
    length = int(next(line.split(b":")[1] for line in answer_head.split(b"\r\n")
                      if line.lower().startswith(b"content-length:")))
    assert len(answer) < length, f"all {length:,} bytes of the answer were kept until read"


def _fill(http_port: int, shots: int) -> None:
    """`shots` shots into the session, in shown batches of 50 (a batch shows its last 50)."""
    with httpx.Client(base_url=f"http://127.0.0.1:{http_port}", timeout=60) as http:
        for _ in range(shots // 50):
            assert http.post("/v1/shots/batch?viewer=1", json={"shots": [SHOT] * 50}).status_code == 200


def _idle(server: psutil.Process, limit_s: float = 60.0) -> None:
    """Wait until the server has used under a tenth of a core for a second (its work done)."""
    deadline, idle = time.monotonic() + limit_s, 0
    while time.monotonic() < deadline:
        idle = idle + 1 if server.cpu_percent(interval=0.5) < 10.0 else 0
        if idle == 2:
            return
    raise AssertionError("the server never went idle")


def test_session_downloads_nobody_reads_hold_no_sessions_rows_in_a_real_server(served):
    server, port = served
    _fill(port, 10_000)
    _idle(server)
    before = _rss_mib(server)
    sockets = []
    for _ in range(4):
        sock = socket.socket()
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        sock.connect(("127.0.0.1", port))
        sock.sendall(b"GET /v1/session.csv HTTP/1.1\r\nhost: localhost\r\n\r\n")
        sockets.append(sock)
    try:
        _idle(server)  # each download made as much as its client's socket took, then waits
        grown = _rss_mib(server) - before
    finally:
        for sock in sockets:
            sock.close()
    assert grown < 24, f"4 unread downloads of 10,000 shots grew the server by {grown:.0f} MiB"


async def _downloads_and_turns(shots: list, downloads: int) -> tuple[list[str], int, int]:
    """`downloads` CSVs of `shots` made at once on one LoopTurns, as the service makes them: (their texts, the
    slices they took, the turns another task got meanwhile)."""
    turns, slices, done = 0, 0, False

    async def other_task():
        nonlocal turns
        while not done:
            turns += 1
            await asyncio.sleep(0)

    async def download() -> str:
        nonlocal slices
        pieces = []
        async for piece in session_csv_slices(shots, 0.0005, turns=shared):
            slices += 1
            pieces.append(piece)
        return "".join(pieces)

    shared = LoopTurns()
    ticker = asyncio.create_task(other_task())
    texts = await asyncio.gather(*[download() for _ in range(downloads)])
    done = True
    await ticker
    return texts, slices, turns


def test_downloads_made_at_once_take_one_slice_per_turn_of_the_loop_over_them_all(engine):
    """Ten at once: the loop turns at least once per slice of any of them (a shot waits one slice, not ten)."""
    request = ShotRequest(ball_speed_mps=60.0, launch_angle_deg=14.0, spin_rpm=5000.0)
    result, flight = fly_request(engine, request, keep_states=True)
    feed = ShotFeed()
    for _ in range(500):
        feed.publish("http", request, result, flight.states, flight.flight_time_s)
    texts, slices, turns = asyncio.run(_downloads_and_turns(list(feed.session), 10))
    assert all(text == texts[0] for text in texts) and len(list(csv.DictReader(io.StringIO(texts[0])))) == 500
    assert slices >= 20 and turns >= slices, f"{slices} slices in {turns} turns of the loop"


class _OtherSite(BaseHTTPRequestHandler):
    """A web page of another origin that POSTs to the bay the ways a page may without asking (no-cors)."""

    target = ""

    def do_GET(self):  # noqa: N802 (http.server's name)
        script = f"""<script>
        const url = "{self.target}/v1/sessions";
        const form = new FormData(); form.append("player", "Eve");
        window.sent = Promise.all([
          fetch(url, {{method: "POST", mode: "no-cors"}}),
          fetch(url, {{method: "POST", mode: "no-cors", body: "", headers: {{"content-type": "text/plain"}}}}),
          fetch(url, {{method: "POST", mode: "no-cors", body: new URLSearchParams({{player: "Eve"}})}}),
          fetch(url, {{method: "POST", mode: "no-cors", body: form}}),
        ]).then(() => "sent");
        </script>""".encode()
        self.send_response(200)
        self.send_header("content-type", "text/html")
        self.send_header("content-length", str(len(script)))
        self.end_headers()
        self.wfile.write(script)

    def log_message(self, *args):
        pass


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_a_page_of_another_origin_cannot_start_sessions_and_the_services_own_page_can(bay):
    http, _ = bay
    base = str(http.base_url).rstrip("/")
    _OtherSite.target = base
    other = ThreadingHTTPServer(("127.0.0.1", free_port()), _OtherSite)
    threading.Thread(target=other.serve_forever, daemon=True).start()
    try:
        sessions = len(http.get("/v1/sessions").json()["sessions"])
        with browser.headless_page() as page:
            page.goto(f"http://127.0.0.1:{other.server_address[1]}/")
            assert page.evaluate("window.sent") == "sent"
            assert len(http.get("/v1/sessions").json()["sessions"]) == sessions, "another site started sessions"
            page.goto(f"{base}/viewer")
            own = page.evaluate("fetch('v1/sessions', {method: 'POST'}).then(answer => answer.status)")
        assert own == 201
        assert len(http.get("/v1/sessions").json()["sessions"]) == sessions + 1
        assert http.post("/v1/sessions").status_code == 201  # a client that is no web page: no Origin
    finally:
        other.shutdown()


def test_the_key_is_checked_before_a_chunked_body_is_read():
    """A chunked body that never ends, without the key: the 401 comes at once, not after the body deadline."""
    with running(create_app(ServiceSettings(api_key=KEY))) as http:
        with socket.create_connection(("127.0.0.1", http.base_url.port), timeout=5) as sock:
            sock.sendall(b"POST /v1/shots/batch HTTP/1.1\r\nhost: localhost\r\ncontent-type: application/json\r\n"
                         b"transfer-encoding: chunked\r\n\r\n")
            sock.sendall((b"10000\r\n" + b" " * 0x10000 + b"\r\n") * 2)  # 128 KiB of a body, never finished
            answer = sock.recv(65536)
    assert answer.startswith(b"HTTP/1.1 401"), answer[:200]


def test_healthz_names_the_broken_bay_file_without_its_directory(bay):
    http, path = bay
    assert http.put("/v1/bay", json={"air": {"altitude_m": 1600.0}}).status_code == 200
    path.write_text("not bay conditions")
    deadline = time.monotonic() + 10
    while (health := http.get("/healthz").json())["status"] != "degraded":
        assert time.monotonic() < deadline, health
        time.sleep(0.1)
    shown = str(health)
    assert "bay.json" in health["problems"]["bay"]
    assert str(path.parent) not in shown and "bay dir" not in shown, shown


def test_a_client_looping_malformed_requests_writes_one_log_line_not_one_each(bay):
    lines: list[str] = []
    handler = logging.Handler()
    handler.emit = lambda record: lines.append(record.getMessage())
    logger = logging.getLogger("uvicorn.error")
    logger.addHandler(handler)
    try:
        for _ in range(200):
            assert _answer(bay[0].base_url.port, b"NOT HTTP AT ALL\r\n\r\n").startswith(b"HTTP/1.1 400")
    finally:
        logger.removeHandler(handler)
    invalid = [line for line in lines if line.startswith("Invalid HTTP request received.")]
    assert len(invalid) <= 1, invalid[:5]
