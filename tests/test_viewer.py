"""The live shot viewer: the feed's bounds, the event stream over a real uvicorn server (HTTP and Open Connect shots
reach it in milliseconds; a stalled viewer never delays a shot), the page's key handling, and the page itself in a
real headless Chromium (Debian's package, driven by Playwright; skipped where either is missing)."""

from __future__ import annotations

import asyncio
import json
import socket
import statistics
import time
from functools import partial

import browser
import httpx
import numpy as np
import pytest
from golfflight.contract.flying import fly_request
from golfflight.contract.requests import ShotRequest
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.runtime.feed import HISTORY, ShotFeed
from golfflight.service.viewer import routes as viewer_routes
from golfflight.service.viewer.event import SCHEMA_PATH, ShotEvent, schema_text
from golfflight.service.viewer.frames import MAX_POINTS, frame
from golfflight.service.viewer.stream import events
from servers import free_port, keyed_service, running

KEY = "viewer-test-key"
KEYED = {"x-api-key": KEY}
DRIVER = {"ball_speed_mph": 167.0, "launch_angle_deg": 10.9, "back_spin_rpm": 2686.0, "side_spin_rpm": -250.0}
WEDGE_BALL = {"Speed": 102.0, "VLA": 24.0, "HLA": -1.5, "TotalSpin": 8600.0, "SpinAxis": 2.0}



@pytest.fixture(scope="module")
def service():
    """(client, Open Connect port, app) of one keyed service listening on HTTP and TCP."""
    with keyed_service(KEY) as served:
        yield served


def gspro_over_tcp(port: int, number: int, ball: dict) -> dict:
    """A connector's shot over TCP and its reply (the player information GSPro pushes, Code 201, passed over)."""
    return reply_over_tcp(port, json.dumps({"ShotNumber": number, "APIversion": "1", "BallData": ball}).encode())


def reply_over_tcp(port: int, text: bytes) -> dict:
    """One connector message, its JSON text as given, over TCP and its reply (Code 201 pushes passed over)."""
    with socket.create_connection(("127.0.0.1", port), timeout=10) as connector:
        connector.sendall(text)
        received, decoder = "", json.JSONDecoder()
        while True:
            received += connector.recv(65536).decode()
            while received.strip():
                try:
                    message, end = decoder.raw_decode(received.lstrip())
                except ValueError:
                    break
                received = received.lstrip()[end:]
                if message.get("Code") != 201:
                    return message


def pick_club(page, code: str) -> None:
    """Pick a club in the page's "Club hit now" menu and wait until the bay has it (PATCH /v1/bay answered)."""
    page.select_option("#club", code)
    page.wait_for_selector(f"#club[data-saved='{code}']", state="attached", timeout=10_000)


def next_event(lines, deadline_s: float = 5.0) -> ShotEvent:
    """The next shot event from an SSE stream's lines (validated against the event model); other events (the
    session's) are passed over."""
    started, kind = time.monotonic(), None
    for line in lines:
        if line.startswith("event: "):
            kind = line.removeprefix("event: ")
        if line.startswith("data: ") and kind == "shot":
            return ShotEvent.model_validate_json(line.removeprefix("data: "))
        assert time.monotonic() - started < deadline_s, "no shot event in time"
    raise AssertionError("the stream ended before a shot event")


def test_the_event_schema_is_current():
    assert SCHEMA_PATH.read_text() == schema_text(), (
        "event.schema.json is stale: run `python -m golfflight.service.viewer`"
    )


def publish(feed: ShotFeed, engine, request: ShotRequest, source: str = "http", putt: bool = False):
    """Fly a request as the runtime does (states kept) and publish it; the feed's entry."""
    result, flight = fly_request(engine, request, keep_states=True, putt=putt)
    return feed.publish(source, request, result, flight.states, flight.flight_time_s, putt=putt)


def test_the_feed_keeps_its_last_shots_and_a_full_viewer_drops_its_oldest(engine):
    request = ShotRequest(**DRIVER)
    feed = ShotFeed(history=5)
    stalled = feed.subscribe()
    for _ in range(12):
        publish(feed, engine, request)
    assert [entry.id for entry in stalled.pending] == [8, 9, 10, 11, 12] and stalled.dropped == 7
    assert [entry.id for entry in feed.subscribe().pending] == [8, 9, 10, 11, 12]
    assert [entry.id for entry in feed.subscribe(after_id=10).pending] == [11, 12]
    restarted = feed.subscribe(after_id=400)  # an id from before a restart: everything kept
    assert len(restarted.pending) == 5 and len(feed.session) == 12
    for viewer in feed.viewers:
        feed.unsubscribe(viewer)
    assert feed.viewers == ()


def test_one_viewer_too_many_ends_the_oldest_stream_of_the_address_holding_the_most():
    feed = ShotFeed(max_viewers=3)
    first, second, third = feed.subscribe(client="a"), feed.subscribe(client="a"), feed.subscribe(client="b")
    fourth = feed.subscribe(client="c")  # "a" holds the most: its oldest goes
    assert first.ended and "closed to make room" in first.ended and set(feed.viewers) == {second, third, fourth}
    fifth = feed.subscribe(client="b")  # a tie: "b"'s own oldest goes
    assert third.ended and set(feed.viewers) == {second, fourth, fifth}
    assert not (second.ended or fourth.ended or fifth.ended)


GREEN_BELOW = {"surface": "green", "stimp_ft": 12.0, "elevation_m": -3.0}


@pytest.mark.parametrize(
    ("shot", "putt"),
    [
        (DRIVER, False),
        ({**DRIVER, "trajectory": {"rate_hz": 1000}}, False),
        ({**DRIVER, "ground": GREEN_BELOW, "wind": {"speed_mps": 8.0, "from_deg": 0.0},
          "air": {"altitude_m": 1600.0, "temperature_c": 30.0}}, False),
        ({"ball_speed_mps": 1.83, "launch_angle_deg": 2.0, "spin_rpm": 100.0, "ground": GREEN_BELOW}, True),
    ],
)
def test_the_drawn_path_is_the_answered_flight_through_its_landing_to_its_rest(engine, shot, putt):
    request = ShotRequest(**shot)
    feed = ShotFeed()
    entry = publish(feed, engine, request, putt=putt)
    answered = entry.result
    event = ShotEvent.model_validate_json(frame(entry).split("data: ", 1)[1])
    flight = event.flight
    assert flight.carry_m == answered.carry_m and flight.rest == answered.rest
    assert 2 <= len(flight.trajectory) <= MAX_POINTS
    points = np.array([(p.x_m, p.y_m, p.z_m) for p in flight.trajectory])
    floor = request.ground.elevation_m if request.ground is not None else 0.0  # a putt rolls on that green too
    assert points[-1] == pytest.approx((answered.rest.x_m, answered.rest.y_m, floor), abs=1e-9)
    landing = (answered.landing.x_m, answered.landing.y_m, floor)
    assert np.min(np.linalg.norm(points - landing, axis=1)) < 1e-9  # the landing itself, not a chord beside it
    assert event.putt is putt and entry.frame is not None and entry.states is None  # only the event is kept


def test_a_stream_ends_after_its_lifetime_and_lets_its_viewer_go(engine):
    request = ShotRequest(**DRIVER)

    async def stream() -> tuple[ShotFeed, list[str], float]:
        feed = ShotFeed()
        viewer = feed.subscribe()
        publish(feed, engine, request)
        started = time.monotonic()
        frames = [frame async for frame in events(feed, viewer, lifetime_s=0.3)]
        return feed, frames, time.monotonic() - started

    feed, frames, seconds = asyncio.run(stream())
    assert frames[0].startswith("retry: ") and frames[1].startswith("event: session\ndata: {\"id\":1,")
    assert frames[2].startswith("id: 1\nevent: shot\ndata: {")
    assert len(frames) == 3 and 0.3 <= seconds < 1.0 and feed.viewers == ()


def test_the_page_is_open_but_the_stream_needs_the_key_and_neither_is_in_the_openapi(service):
    http, _, _ = service
    page = http.get("/viewer")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    assert "default-src 'self'" in page.headers["content-security-policy"]
    for name, kind in (("viewer.js", "text/javascript"), ("viewer.css", "text/css")):
        asset = http.get(f"/viewer/{name}")
        assert asset.status_code == 200 and asset.headers["content-type"].startswith(kind)
        assert "http://" not in asset.text.replace("http://www.w3.org/2000/svg", "") and "https://" not in asset.text
    assert http.get("/viewer/viewer.html").status_code == 401  # only the names the page uses are open
    assert http.get("/viewer/model_card.json", headers=KEYED).status_code == 404
    assert http.get("/v1/events").status_code == 401
    paths = http.get("/openapi.json", headers=KEYED).json()["paths"]
    assert "/v1/events" not in paths and "/viewer" not in paths


def test_shots_over_http_batch_and_tcp_reach_an_open_stream_in_milliseconds(service, monkeypatch):
    http, port, _ = service
    monkeypatch.setattr(viewer_routes, "events", partial(events, lifetime_s=60))  # one stream for the whole test
    headers = {**KEYED, "last-event-id": str(10**9)}  # from "before a restart": replays what is kept, then live
    with (
        httpx.Client(base_url=http.base_url, timeout=10) as viewer,
        viewer.stream("GET", "/v1/events", headers=KEYED) as stream,
    ):
        assert stream.headers["content-type"].startswith("text/event-stream")
        lines = stream.iter_lines()
        started = time.perf_counter()
        reply = http.post("/v1/shots?viewer=true", json=DRIVER, headers=KEYED).json()
        event = next_event(lines)
        http_s = time.perf_counter() - started
        assert event.source == "http" and event.flight.carry_yd == reply["carry_yd"]

        started = time.perf_counter()
        tcp = gspro_over_tcp(port, 7, WEDGE_BALL)
        event = next_event(lines)
        tcp_s = time.perf_counter() - started
        assert event.source == "open-connect" and event.shot_number == 7
        assert event.flight.carry_yd == tcp["Flight"]["carry_yd"] and event.flight.trajectory

        batch = http.post(
            "/v1/shots/batch?viewer=true", json={"shots": [DRIVER, {**DRIVER, "ball_speed_mph": 120.0}]}, headers=KEYED
        ).json()
        firsts = [next_event(lines), next_event(lines)]
        assert [e.source for e in firsts] == ["batch", "batch"]
        assert [e.flight.carry_yd for e in firsts] == pytest.approx([r["carry_yd"] for r in batch["results"]])
    with (
        httpx.Client(base_url=http.base_url, timeout=10) as viewer,
        viewer.stream("GET", "/v1/events", headers=headers) as stream,
    ):
        assert next_event(stream.iter_lines()).id == 1  # a restarted service's history, from its start
    print(f"shot to stream: HTTP {http_s * 1e3:.1f} ms, Open Connect {tcp_s * 1e3:.1f} ms (reply included)")
    assert http_s < 1.0 and tcp_s < 1.0


def test_a_stalled_viewer_never_delays_a_shot(service, monkeypatch):
    http, _, app = service
    feed = app.state.runtime._feed
    monkeypatch.setattr(viewer_routes, "events", partial(events, lifetime_s=120))  # stalled, not just slow to close

    def timed(shot: dict, n: int) -> list[float]:
        seconds = []
        for _ in range(n):
            started = time.perf_counter()
            assert http.post("/v1/shots?viewer=true", json=shot, headers=KEYED).status_code == 200
            seconds.append(time.perf_counter() - started)
        return seconds

    def until(condition, what: str, within_s: float = 10.0) -> None:
        deadline = time.monotonic() + within_s
        while not condition():
            assert time.monotonic() < deadline, what
            time.sleep(0.01)

    until(lambda: not feed.viewers, "an earlier test's stream is still open")
    alone = timed(DRIVER, 60)
    stalled = socket.socket()
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # and it never reads
    stalled.connect(("127.0.0.1", http.base_url.port))
    stalled.sendall(f"GET /v1/events HTTP/1.1\r\nhost: x\r\nx-api-key: {KEY}\r\n\r\n".encode())
    until(lambda: feed.viewers, "the stalled viewer never subscribed")
    timed({**DRIVER, "trajectory": {"rate_hz": 1000}}, 100)  # about 50 KB an event: the socket's buffers fill
    (viewer,) = feed.viewers
    during = timed(DRIVER, 60)
    assert len(viewer.pending) == HISTORY and viewer.dropped > 0  # bounded, the oldest gone
    stalled.close()
    until(lambda: not feed.viewers, "a closed viewer was never let go")
    p50_alone, p50_during = statistics.median(alone), statistics.median(during)
    print(
        f"POST /v1/shots p50 {p50_alone * 1e3:.2f} ms alone, {p50_during * 1e3:.2f} ms with a stalled viewer "
        f"(max {max(during) * 1e3:.1f} ms; the viewer's queue held {HISTORY}, dropped {viewer.dropped})"
    )
    assert p50_during < 3 * p50_alone + 0.010 and max(during) < 0.5  # a blocked shot would take seconds


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_the_page_in_chromium_draws_shots_from_http_and_open_connect(tmp_path):
    port = free_port()
    with running(create_app(ServiceSettings(api_key=KEY, connect_port=port))) as http:
        base = str(http.base_url).rstrip("/")
        with browser.headless_page() as page:
            errors: list[str] = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.goto(f"{base}/viewer#key={KEY}")
            page.wait_for_selector("#status[data-state=live]", timeout=10_000)
            assert "key=" not in page.url  # taken off the address bar

            pick_club(page, "DR")
            started = time.perf_counter()
            driver = http.post("/v1/shots?viewer=1", json={**DRIVER, "club": "driver"}, headers=KEYED).json()
            page.wait_for_selector("#shots tbody tr[data-shot='1']", timeout=10_000)
            seen_s = time.perf_counter() - started
            assert page.inner_text("#n-carry").startswith(f"{driver['carry_yd']:.1f}")

            pick_club(page, "SW")
            wedge = gspro_over_tcp(port, 7, WEDGE_BALL)["Flight"]
            page.wait_for_selector("#shots tbody tr[data-shot='2']", timeout=10_000)
            page.wait_for_selector("#side polyline.latest[data-done]", timeout=10_000)
            assert page.inner_text("#last-source") == "#2 · Open Connect shot 7 · Sand wedge"
            assert page.inner_text("#n-carry").startswith(f"{wedge['carry_yd']:.1f}")
            assert page.inner_text("#n-apex").startswith(f"{wedge['apex_yd']:.1f}")
            assert page.inner_text("#n-landing-angle").startswith(f"{wedge['landing_angle_deg']:.1f}")
            assert page.inner_text("#n-ball-speed").startswith("102.0")
            assert page.inner_text("#n-total").startswith(f"{wedge['total_yd']:.1f}")
            assert page.inner_text("#n-roll").startswith(f"{wedge['roll_m'] / 0.9144:.1f}")

            for view, across in (("behind", 1), ("side", 0), ("top", 0)):  # behind: the arc rises up the picture
                for shot in ("1", "2"):
                    points = page.get_attribute(f"#{view} polyline[data-shot='{shot}']", "points").split()
                    spread = [float(point.split(",")[across]) for point in points]
                    assert len(points) >= 30 and max(spread) - min(spread) > 20, (view, shot)
            assert page.locator("#dispersion circle.dot:not(.rest-dot)").count() == 2
            legend = page.inner_text("#legend")
            assert "Driver: 1 shot" in legend and "Sand wedge: 1 shot" in legend
            assert [page.get_attribute(f"#shots tbody tr[data-shot='{n}']", "data-club") for n in (1, 2)] == ["DR", "SW"]

            page.click(".units button[data-units=metric]")  # the bay's units: shown once PATCH /v1/bay answers
            page.wait_for_function("() => !document.querySelector('#n-carry').textContent.endsWith('yd')",
                                   timeout=10_000)
            assert page.inner_text("#n-carry").startswith(f"{wedge['carry_m']:.1f}")
            page.screenshot(path=str(tmp_path / "viewer.png"), full_page=True)

            second = page.context.new_page()  # another screen in the bay: the kept shots, then live ones
            second.goto(f"{base}/viewer")  # the key is in this tab session's storage only: asked for
            second.wait_for_selector("#key-form:not([hidden])", timeout=10_000)
            second.fill("#key", KEY)
            second.click("#key-form button")
            second.wait_for_selector("#shots tbody tr[data-shot='2']", timeout=10_000)
            gspro_over_tcp(port, 8, {**WEDGE_BALL, "Speed": 110.0})
            for each in (page, second):
                each.wait_for_selector("#shots tbody tr[data-shot='3']", timeout=10_000)
            assert errors == []
    print(f"shot to the page's table: {seen_s * 1e3:.0f} ms")
    assert (tmp_path / "viewer.png").stat().st_size > 20_000
