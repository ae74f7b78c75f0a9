"""A bay that cannot be knocked over (issue 42): the session download leaves the loop to the shots, one odd byte in a
connector's ClubData neither blanks the screen nor cuts the stream, a bay file that is not a regular file is a
broken bay file, a Host the bay does not answer to is refused without a key, and stalled HTTP requests are closed."""

from __future__ import annotations

import asyncio
import csv
import io
import json
import os
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from functools import partial
from pathlib import Path

import httpx
import pytest
from golfflight.contract.flying import fly_request
from golfflight.contract.requests import ShotRequest
from golfflight.service.api.http_protocol import DeadlineHttpProtocol
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.runtime.bay import Bay, BayFileError
from golfflight.service.runtime.feed import ShotFeed
from golfflight.service.viewer import routes as viewer_routes
from golfflight.service.viewer.session_csv import session_csv_slices
from golfflight.service.viewer.stream import events
from servers import keyed_service, running
from test_viewer import KEY, KEYED, next_event, reply_over_tcp


def _session(engine, shots: int) -> ShotFeed:
    feed = ShotFeed()
    request = ShotRequest(ball_speed_mps=60.0, launch_angle_deg=14.0, spin_rpm=5000.0)
    result, flight = fly_request(engine, request, keep_states=True)
    for _ in range(shots):
        feed.publish("http", request, result, flight.states, flight.flight_time_s)
    return feed


async def _download_and_count_turns(feed: ShotFeed, slice_s: float) -> tuple[str, int]:
    """The CSV and how many turns another task got while it was made."""
    turns, done = 0, False

    async def other_task():
        nonlocal turns
        while not done:
            turns += 1
            await asyncio.sleep(0)

    ticker = asyncio.create_task(other_task())
    await asyncio.sleep(0)
    turns = 0
    text = "".join([piece async for piece in session_csv_slices(list(feed.session), slice_s)])
    done = True
    await ticker
    return text, turns


def test_the_session_download_lets_the_loop_run_while_it_is_made(engine):
    feed = _session(engine, 2000)
    text, turns = asyncio.run(_download_and_count_turns(feed, slice_s=0.001))
    rows = list(csv.DictReader(io.StringIO(text)))
    assert len(rows) == 2000 and rows[0]["source"] == "http" and float(rows[-1]["ball_speed_mps"]) == 60.0
    assert turns >= 10, f"the loop ran {turns} times while 2,000 rows were made"


def _shot_text(number: int, club_data: str = "") -> bytes:
    ball = '{"Speed": 102.0, "VLA": 24.0, "HLA": -1.5, "TotalSpin": 8600.0, "SpinAxis": 2.0}'
    club = f', "ClubData": {club_data}' if club_data else ""
    return f'{{"ShotNumber": {number}, "APIversion": "1", "BallData": {ball}{club}}}'.encode()


def test_a_lone_surrogate_in_club_data_neither_blanks_the_screen_nor_cuts_the_stream(monkeypatch):
    monkeypatch.setattr(viewer_routes, "events", partial(events, lifetime_s=60))
    with keyed_service(KEY) as (http, port, _), httpx.Client(base_url=http.base_url, timeout=10) as viewer:
        with viewer.stream("GET", "/v1/events", headers=KEYED) as stream:
            lines = stream.iter_lines()
            odd = reply_over_tcp(port, _shot_text(1, r'{"Sp\ud800eed": "fast\udc00", "Loft": 24.5}'))
            assert odd["Code"] == 200
            assert [reply_over_tcp(port, _shot_text(n))["Code"] for n in (2, 3)] == [200, 200]
            received = [next_event(lines) for _ in range(3)]
        assert [event.shot_number for event in received] == [1, 2, 3]
        assert received[0].club_data == {r"Sp\ud800eed": r"fast\udc00", "Loft": 24.5}
        with viewer.stream("GET", "/v1/events", headers=KEYED) as stream:  # a reconnect gets the kept shots
            lines = stream.iter_lines()
            assert [next_event(lines).shot_number for _ in range(3)] == [1, 2, 3]


def test_a_shot_that_cannot_be_shown_is_left_out_and_the_stream_goes_on(engine, caplog):
    async def stream() -> list[str]:
        feed = ShotFeed()
        viewer = feed.subscribe()
        request = ShotRequest(ball_speed_mps=60.0, launch_angle_deg=14.0, spin_rpm=5000.0)
        result, flight = fly_request(engine, request, keep_states=True)
        feed.publish("http", request, result, flight.states, flight.flight_time_s, club_data={"odd": "\ud800"})
        feed.publish("http", request, result, flight.states, flight.flight_time_s)
        return [text async for text in events(feed, viewer, lifetime_s=0.3)]

    frames = asyncio.run(stream())
    assert [text.split("\n")[0] for text in frames[1:]] == ["event: session", "id: 2"]  # the stream's session first
    assert "shot 1 cannot be shown" in caplog.text


def _fifo(path: Path) -> None:
    os.mkfifo(path)


def _dev_zero(path: Path) -> None:
    path.symlink_to("/dev/zero")


def _sparse_gigabyte(path: Path) -> None:
    with path.open("wb") as file:
        file.truncate(2**30)


@pytest.mark.parametrize("replacement, named", [(_fifo, "FIFO"), (_dev_zero, "character device"),
                                                (_sparse_gigabyte, "1,073,741,824 bytes")])
def test_a_bay_file_that_is_not_a_small_regular_file_is_a_broken_bay_file(tmp_path, replacement, named):
    path = tmp_path / "bay.json"
    shot = {"ball_speed_mps": 60.0, "launch_angle_deg": 14.0, "spin_rpm": 5000.0}
    with running(create_app(ServiceSettings(bay_file=path))) as http:
        assert http.put("/v1/bay", json={"air": {"altitude_m": 1600.0}}).status_code == 200
        good = http.post("/v1/shots", json=shot).json()
        staged = tmp_path / "staged"
        replacement(staged)
        os.replace(staged, path)
        started = time.monotonic()
        answer = http.post("/v1/shots", json=shot)
        seconds = time.monotonic() - started
        health = http.get("/healthz").json()
    assert answer.status_code == 200 and answer.json() == good, "the last good bay stays in force"
    assert seconds < 5.0, f"a shot took {seconds:.1f} s"
    assert health["status"] == "degraded" and named in health["problems"]["bay"]


def test_a_bay_file_that_is_a_fifo_stops_the_start_with_its_name(tmp_path):
    path = tmp_path / "bay.json"
    os.mkfifo(path)
    with pytest.raises(BayFileError, match="FIFO"):
        Bay(path)


def test_without_a_key_a_page_reached_by_dns_rebinding_can_neither_change_the_bay_nor_read_the_session():
    rebound = {"host": "evil.example.com"}
    with running(create_app(ServiceSettings(allowed_hosts=["bay-pc.local"]))) as http:
        assert http.patch("/v1/bay", json={"player": {"club": "PT"}}, headers=rebound).status_code == 403
        refused = http.get("/v1/session.csv", headers=rebound)
        assert refused.status_code == 403 and "evil.example.com" in refused.json()["detail"]
        assert "GOLFFLIGHT_ALLOWED_HOSTS" in refused.json()["detail"]
        assert http.get("/v1/bay").json()["player"]["club"] != "PT"
        port = http.base_url.port
        for host in (f"localhost:{port}", f"127.0.0.1:{port}", "[::1]", "BAY-PC.local.", "127.0.0.1"):
            assert http.get("/v1/bay", headers={"host": host}).status_code == 200, host
        assert http.get("/healthz", headers=rebound).status_code == 200  # health checkers hold no names


def test_with_a_key_the_key_is_the_guard_and_any_host_is_answered():
    with running(create_app(ServiceSettings(api_key="k"))) as http:
        assert http.get("/v1/bay", headers={"host": "golf.example.com", "x-api-key": "k"}).status_code == 200


class _QuickDeadlines(DeadlineHttpProtocol):
    head_timeout_s = 0.5
    body_timeout_s = 0.5


@contextmanager
def _served_with_quick_deadlines() -> Iterator[int]:
    """The service on a free loopback port, its request deadlines half a second: the port."""
    with running(create_app(ServiceSettings()), http=_QuickDeadlines) as http:
        yield http.base_url.port


def _closed_after(sock: socket.socket) -> tuple[bytes, float]:
    """What the server sends until it closes the connection, and how long that took."""
    started, received = time.monotonic(), b""
    while chunk := sock.recv(65536):
        received += chunk
    return received, time.monotonic() - started


SHOT_HEAD = b"POST /v1/shots HTTP/1.1\r\nhost: localhost\r\ncontent-type: application/json\r\n"
SHOT_BODY = b'{"ball_speed_mps": 60, "launch_angle_deg": 14, "spin_rpm": 5000}'
SHOT = SHOT_HEAD + b"content-length: %d\r\n\r\n" % len(SHOT_BODY) + SHOT_BODY


@pytest.mark.parametrize("sent, answer", [
    (b"", b""),  # nothing asked: closed silently, as uvicorn closes a connection idle between requests
    (b"GET /healthz HTTP/1.1\r\nhost: localhost\r\n", b"HTTP/1.1 408"),
    (SHOT_HEAD + b"content-length: 80\r\n\r\n{\"ball_speed_mps\": 6", b"HTTP/1.1 408"),
    (SHOT + b"GET /healthz HTTP/1.1\r\n", b"HTTP/1.1 200"),  # a second request stalls after the first's answer
])
def test_a_request_that_stalls_is_closed_at_its_deadline_and_the_service_answers_on(sent, answer):
    with _served_with_quick_deadlines() as port:
        with socket.create_connection(("127.0.0.1", port), timeout=30) as stalled:
            stalled.sendall(sent)
            received, seconds = _closed_after(stalled)
        assert received.startswith(answer) and 0.4 <= seconds < 20
        if sent.startswith(SHOT):
            assert received.count(b"HTTP/1.1 ") == 2 and b"HTTP/1.1 408" in received
        assert httpx.get(f"http://127.0.0.1:{port}/healthz", timeout=30).status_code == 200


def test_a_keep_alive_client_is_not_cut_by_the_deadlines():
    with _served_with_quick_deadlines() as port, httpx.Client(base_url=f"http://127.0.0.1:{port}") as http:
        for _ in range(3):
            assert http.post("/v1/shots", json={"ball_speed_mps": 60.0, "launch_angle_deg": 14.0,
                                                "spin_rpm": 5000.0}).status_code == 200
            time.sleep(0.7)  # longer than either deadline, shorter than uvicorn's keep-alive


def test_serve_raises_its_open_files_limit_to_the_hard_one():
    script = ("import resource\n"
              "soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)\n"
              "resource.setrlimit(resource.RLIMIT_NOFILE, (min(1024, hard), hard))\n"
              "from golfflight.commands.serve import open_files_raised\n"
              "print(open_files_raised(), *resource.getrlimit(resource.RLIMIT_NOFILE))\n")
    raised, soft, hard = map(int, subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                                                 check=True).stdout.split())
    assert raised == soft == hard


def test_a_body_nested_too_deeply_is_refused_as_that_on_every_route():
    body = b'{"a": ' + b"[" * 5000 + b"]" * 5000 + b"}"
    json_body = {"content-type": "application/json"}
    with running(create_app(ServiceSettings())) as http:
        for method, path in (("POST", "/v1/shots"), ("POST", "/v1/shots/batch"), ("PATCH", "/v1/bay")):
            refused = http.request(method, path, content=body, headers=json_body)
            assert refused.status_code == 422 and "nested too deeply" in refused.json()["detail"][0]["msg"], path
        gspro = http.post("/v1/gspro", content=body, headers=json_body).json()
        assert gspro["Code"] == 500 and "nested too deeply" in gspro["Message"]
