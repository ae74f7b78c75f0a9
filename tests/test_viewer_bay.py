"""Issue 23 on the viewer: the bay's screen shows the bay's own shots only (Open Connect and /v1/gspro; HTTP shots and
batches only when their request asks with `?viewer=true`), the event stream stays open with keep-alive comments
and ends when the server shuts down, and in a real headless Chromium: the behind-the-golfer view puts the tee at the
bottom centre and keeps a straight shot on the target line, labels every distance line, and the bay form PUTs
/v1/bay and shows the service's message for a refused value."""

from __future__ import annotations

import asyncio
import csv
import io
import time
from contextlib import contextmanager
from functools import partial
from pathlib import Path

import browser
import httpx
import pytest
from golfflight.contract.clubs import GSPRO_CLUBS
from golfflight.contract.flying import fly_request
from golfflight.contract.requests import ShotRequest
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.runtime.feed import ShotFeed
from golfflight.service.viewer import routes as viewer_routes
from golfflight.service.viewer.stream import KEEPALIVE_FRAME, KEEPALIVE_S, events, serving_server
from servers import free_port, keyed_service, running
from test_viewer import DRIVER, KEY, KEYED, WEDGE_BALL, gspro_over_tcp, next_event, pick_club

STRAIGHT = {"ball_speed_mph": 160.0, "launch_angle_deg": 11.0, "spin_rpm": 2700.0, "spin_axis_deg": 0.0}



@pytest.fixture(scope="module")
def service():
    with keyed_service(KEY) as served:
        yield served


def gspro(number: int) -> dict:
    return {"ShotNumber": number, "APIversion": "1", "BallData": WEDGE_BALL}


def test_only_the_bays_own_shots_reach_the_viewer_unless_a_request_asks(service, monkeypatch):
    http, port, app = service
    monkeypatch.setattr(viewer_routes, "events", partial(events, lifetime_s=60))
    with (
        httpx.Client(base_url=http.base_url, timeout=10) as viewer,
        viewer.stream("GET", "/v1/events", headers=KEYED) as stream,
    ):
        lines = stream.iter_lines()
        assert http.post("/v1/shots", json=DRIVER, headers=KEYED).status_code == 200
        big = {"shots": [DRIVER] * 200}
        assert http.post("/v1/shots/batch", json=big, headers=KEYED).status_code == 200
        assert http.post("/v1/shots?viewer=false", json=DRIVER, headers=KEYED).status_code == 200
        # the next event is the bay's own shot: nothing of the traffic before it
        assert http.post("/v1/gspro", json=gspro(3), headers=KEYED).json()["Code"] == 200
        event = next_event(lines)
        assert (event.source, event.shot_number) == ("gspro-http", 3)
        gspro_over_tcp(port, 4, WEDGE_BALL)
        assert next_event(lines).source == "open-connect"
        # asked for: a tagged HTTP shot and a batch's shots are shown
        assert http.post("/v1/shots?viewer=true", json=DRIVER, headers=KEYED).status_code == 200
        assert next_event(lines).source == "http"
        batch = {"shots": [DRIVER, {**DRIVER, "ball_speed_mph": 120.0}]}
        assert http.post("/v1/shots/batch?viewer=true", json=batch, headers=KEYED).status_code == 200
        assert [next_event(lines).source, next_event(lines).source] == ["batch", "batch"]
    kept = [entry.source for entry in app.state.runtime._feed.subscribe().pending]
    for viewer in app.state.runtime._feed.viewers:
        app.state.runtime._feed.unsubscribe(viewer)
    assert "batch" in kept and kept.count("http") <= 2  # earlier tests' tagged shots at most; none untagged


def test_the_viewer_flag_leaves_the_batch_contract_as_it_was(service):
    http, _, _ = service
    bad = {"shots": [DRIVER, {**DRIVER, "spin_rpm": 99999.0}]}
    for path in ("/v1/shots/batch", "/v1/shots/batch?viewer=true"):
        answer = http.post(path, json=bad, headers=KEYED)
        assert answer.status_code == 422 and answer.json()["detail"][0]["shot"] == 1
    unknown = http.post("/v1/shots/batch", json={"shots": [DRIVER], "viewer": True}, headers=KEYED)
    assert unknown.status_code == 422  # the flag is no body field: the body stays strict
    refused = http.post("/v1/shots?viewer=perhaps", json=DRIVER, headers=KEYED)
    assert refused.status_code == 422 and "viewer" in refused.text
    parameters = http.get("/openapi.json", headers=KEYED).json()["paths"]["/v1/shots/batch"]["post"]["parameters"]
    assert [(p["name"], p["in"], p["schema"]["type"]) for p in parameters] == [("viewer", "query", "boolean")]


def test_a_quiet_stream_sends_keep_alive_comments(engine):
    request = ShotRequest(**DRIVER)

    async def stream() -> list[str]:
        feed = ShotFeed()
        viewer = feed.subscribe()
        result, flight = fly_request(engine, request, keep_states=True)
        feed.publish("http", request, result, flight.states, flight.flight_time_s)
        return [frame async for frame in events(feed, viewer, lifetime_s=0.55, keepalive_s=0.1)]

    frames = asyncio.run(stream())
    assert frames[0].startswith("retry: ") and frames[1].startswith("event: session\n")
    assert frames[2].startswith("id: 1\n")
    assert 3 <= frames.count(KEEPALIVE_FRAME) <= 6 and len(frames) == 3 + frames.count(KEEPALIVE_FRAME)
    assert KEEPALIVE_S <= 15


def test_a_stream_ends_promptly_when_the_server_shuts_down():
    told = []  # the server's should_exit, as the stream sees it

    async def stream() -> tuple[list[str], float, ShotFeed]:
        feed = ShotFeed()
        asyncio.get_running_loop().call_later(0.3, told.append, True)
        started = time.monotonic()
        frames = [frame async for frame in events(feed, feed.subscribe(), stopping=lambda: bool(told))]
        return frames, time.monotonic() - started, feed

    frames, seconds, feed = asyncio.run(stream())
    assert frames[0] == "retry: 500\n\n" and frames[1].startswith("event: session\n") and len(frames) == 2
    assert 0.3 <= seconds < 1.2 and feed.viewers == ()
    assert serving_server()() is False  # pytest's main thread runs no uvicorn server: never seen as stopping


def test_the_event_stream_stays_open_past_the_old_five_seconds_with_keep_alives(service, monkeypatch):
    http, _, _ = service
    monkeypatch.setattr(viewer_routes, "events", partial(events, keepalive_s=0.5))  # endless, as served
    comments, started = 0, time.monotonic()
    with (
        httpx.Client(base_url=http.base_url, timeout=10) as viewer,
        viewer.stream("GET", "/v1/events", headers=KEYED) as stream,
    ):
        for line in stream.iter_lines():
            comments += line == ": keep-alive"
            if time.monotonic() - started > 6.0:
                break
        else:
            pytest.fail("the stream ended")
    assert comments >= 9


def _latest_path(page) -> list[tuple[float, float]]:
    """The (x, y) points of the behind view's latest flight, once it is drawn."""
    page.wait_for_selector("#behind polyline.latest[data-done]", state="attached", timeout=10_000)
    return [tuple(map(float, p.split(","))) for p in page.get_attribute("#behind polyline.latest", "points").split()]


def _submit_bay_form(page) -> None:
    """Submit the bay form and wait for the page to say the service saved it."""
    page.evaluate("document.querySelector('#bay-message').dataset.state = ''")
    page.click("#bay-form button[type=submit]")
    page.wait_for_selector("#bay-message[data-state=saved]", timeout=10_000)


def _straight_shot_on_the_centre_line(page, http) -> dict:
    """A batch without the flag never reaches the page; the bay's own straight shot is drawn from the tee at the
    bottom centre up the target line. The behind view's geometry."""
    pick_club(page, "DR")
    assert http.post("/v1/shots/batch", json={"shots": [DRIVER] * 60}, headers=KEYED).status_code == 200
    straight = http.post("/v1/shots?viewer=true", json={**STRAIGHT, "club": "DR"}, headers=KEYED).json()
    assert straight["lateral_m"] == pytest.approx(0.0, abs=1e-6)
    path = _latest_path(page)
    assert page.locator("#shots tbody tr").count() == 1 and "Driver: 1 shot" in page.inner_text("#legend")
    behind = page.evaluate("window.golfflightViewer.behind")
    assert behind["camera"] == {"height_m": 1.6, "back_m": 3, "fov_deg": 55, "pitch_deg": 3.5}
    width, height = behind["width"], behind["height"]
    tee_x, tee_y = behind["tee"]
    assert tee_x == pytest.approx(width / 2) and height - 40 <= tee_y <= height  # bottom centre
    assert behind["vanishing"][0] == pytest.approx(width / 2) and behind["vanishing"][1] < tee_y
    target = page.locator("#behind line.target-line")
    assert [float(target.get_attribute(a)) for a in ("x1", "x2")] == pytest.approx([width / 2] * 2)
    assert len(path) > 30
    assert max(abs(x - width / 2) for x, _ in path) <= 0.5, "a straight shot left the centre line"
    assert path[0] == pytest.approx((tee_x, tee_y), abs=1.0)  # it starts on the tee
    assert min(y for _, y in path) < tee_y - 200  # and flies up the screen
    return behind


def _wedge_right_of_the_line_and_labelled_distances(page, port: int, behind: dict) -> None:
    """A wedge over Open Connect lands right of the line; the distance lines recede to the horizon, each label at
    least LABEL_GAP_PX (14 px) above the one below it, none overlapping, all inside the picture."""
    width, tee = behind["width"], tuple(behind["tee"])
    gspro_over_tcp(port, 1, {**WEDGE_BALL, "HLA": 4.0, "SpinAxis": 8.0})
    page.wait_for_selector("#shots tbody tr[data-shot='2']", timeout=10_000)
    wedge = _latest_path(page)
    assert wedge[0] == pytest.approx(tee, abs=1.0) and wedge[-1][0] > width / 2 + 5
    behind = page.evaluate("window.golfflightViewer.behind")
    lines = [float(y) for y in page.evaluate(  # one task, as the dispersion's dots below are read
        "[...document.querySelectorAll('#behind line.marker-line')].map(e => e.getAttribute('y1'))")]
    horizon = behind["vanishing"][1]
    assert len(lines) >= 6 and all(horizon < y < tee[1] for y in lines) and lines == sorted(lines, reverse=True)
    labels = behind["labels"]
    assert labels[0]["text"] == "50 yd" and labels == sorted(labels, key=lambda label: -label["line_y"])
    assert [label["text"] for label in labels] == page.locator("#behind text.distance").all_text_contents()
    for below, above in zip(labels, labels[1:]):
        assert below["line_y"] - above["line_y"] >= 14, (below, above)
    assert_apart([label["box"] for label in labels], width, behind["height"])
    assert page.inner_text("#n-launch") == "24.0°"  # the degree sign on its number (the wedge)


def assert_apart(boxes: list[list[float]], width: float, height: float) -> None:
    """No two boxes (x, y, width, height) overlap, and each is inside the picture."""
    for i, a in enumerate(boxes):
        assert 0 <= a[0] and a[0] + a[2] <= width and 0 <= a[1] and a[1] + a[3] <= height, a
        for b in boxes[i + 1 :]:
            apart = a[0] + a[2] <= b[0] or b[0] + b[2] <= a[0] or a[1] + a[3] <= b[1] or b[1] + b[3] <= a[1]
            assert apart, (a, b)


def _metric_bay_through_the_form(page, http) -> None:
    """Metric units, then the issue's bay, sent through the page and read back by GET /v1/bay."""
    page.click(".units button[data-units=metric]")
    page.wait_for_selector("#bay-message[data-state=saved]", timeout=10_000)
    assert http.get("/v1/bay", headers=KEYED).json()["units"] == "metric"
    assert page.inner_text("#n-carry").endswith("m") and "(m)" in page.inner_text("#shots thead")
    for field, value in (("temperature", "30"), ("altitude", "1600"), ("wind-speed", "4.47"), ("wind-from", "0")):
        page.fill(f"#bay-{field}", value)
    page.select_option("#bay-surface", "green")
    page.fill("#bay-stimp", "12")
    _submit_bay_form(page)
    bay = http.get("/v1/bay", headers=KEYED).json()
    assert bay["air"] == {"temperature_c": 30.0, "altitude_m": 1600.0}
    assert bay["wind"]["speed_mps"] == pytest.approx(4.47) and bay["wind"]["from_deg"] == 0.0
    assert bay["ground"]["surface"] == "green" and bay["ground"]["stimp_ft"] == 12.0
    assert bay["units"] == "metric"
    summary = page.inner_text("#bay-summary")
    assert "30.0°C" in summary and "1600 m" in summary and "stimp 12" in summary


def _imperial_bay_through_the_form(page, http) -> None:
    """Imperial: the form shows the same bay in °F, ft and mph; untouched values go back unrounded."""
    page.click(".units button[data-units=imperial]")
    page.wait_for_function("() => document.querySelector('#bay-altitude').value === '5249'", timeout=10_000)
    assert page.input_value("#bay-temperature") == "86" and page.input_value("#bay-wind-speed") == "10"
    page.fill("#bay-humidity", "40")
    _submit_bay_form(page)
    bay = http.get("/v1/bay", headers=KEYED).json()
    assert bay["air"] == {"temperature_c": 30.0, "altitude_m": 1600.0, "humidity_pct": 40.0}
    assert bay["wind"]["speed_mps"] == pytest.approx(4.47) and bay["units"] == "imperial"


def _refused_value_and_a_bay_set_over_the_api(page, http) -> None:
    """A refused value shows the service's own message and leaves the bay unchanged; a bay set over the API in mph
    reads as a wind on the page, not "calm"."""
    page.fill("#bay-humidity", "150")
    page.click("#bay-form button[type=submit]")
    page.wait_for_selector("#bay-message[data-state=refused]", timeout=10_000)
    message = page.inner_text("#bay-message")
    assert "humidity_pct" in message and "150" in message, message
    assert http.get("/v1/bay", headers=KEYED).json()["air"]["humidity_pct"] == 40.0
    mph = {"wind": {"speed_mph": 10.0, "from_deg": 0.0}}
    assert http.put("/v1/bay", json=mph, headers=KEYED).status_code == 200
    page.evaluate("loadBay()")
    page.wait_for_function(
        "() => document.querySelector('#bay-summary').textContent.includes('wind 10')", timeout=10_000
    )


@contextmanager
def live_viewer(width: int, height: int):
    """(page, HTTP client, Open Connect port, the page's script errors) of a keyed service's viewer, open and live
    in headless Chromium at width x height."""
    port = free_port()
    with running(create_app(ServiceSettings(api_key=KEY, connect_port=port))) as http:
        base = str(http.base_url).rstrip("/")
        with browser.headless_page(width, height) as page:
            errors: list[str] = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.goto(f"{base}/viewer#key={KEY}")
            page.wait_for_selector("#status[data-state=live]", timeout=10_000)
            yield page, http, port, errors


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_the_page_behind_the_golfer_and_the_bay_form_in_chromium():
    """One page through the steps in order: each step starts from the state the one before left."""
    with live_viewer(1400, 1000) as (page, http, port, errors):
        page.wait_for_function("() => document.querySelector('#bay-summary').textContent !== '—'", timeout=10_000)
        behind = _straight_shot_on_the_centre_line(page, http)
        _wedge_right_of_the_line_and_labelled_distances(page, port, behind)
        _metric_bay_through_the_form(page, http)
        _imperial_bay_through_the_form(page, http)
        _refused_value_and_a_bay_set_over_the_api(page, http)
        assert errors == []


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_the_narrow_layout_keeps_the_lateral_column_and_whole_dots():
    with live_viewer(390, 844) as (page, _, port, _errors):
        for number, (hla, axis) in enumerate(((-6.0, -20.0), (0.0, 0.0), (6.0, 25.0)), start=1):
            gspro_over_tcp(port, number, {**WEDGE_BALL, "HLA": hla, "SpinAxis": axis})
        page.wait_for_selector("#shots tbody tr[data-shot='3']", timeout=10_000)
        page.wait_for_function(  # the session's summary of the three read and drawn: no redraw while measured
            "() => session.summary && session.summary.clubs.reduce((n, c) => n + c.shots, 0) === 3", timeout=10_000)
        assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")  # no sideways scroll
        scroll = page.locator(".shots .scroll")
        assert scroll.evaluate("e => e.scrollWidth <= e.clientWidth"), "the shot table is cut"
        lateral = page.locator("#shots th", has_text="lateral")
        assert lateral.is_visible() and lateral.bounding_box()["x"] + lateral.bounding_box()["width"] <= 390
        # the picture, its dots and rings read in one task: eval_on_selector_all queries, then evaluates in a second
        # round trip, and a redraw between them (the session's summary comes) left detached dots measuring 0 x 0 at 0
        drawn = page.evaluate("""() => {
            const svg = document.querySelector('#dispersion'), box = svg.getBoundingClientRect();
            const rect = (d) => {
                const r = d.getBoundingClientRect();
                return {x: r.x, width: r.width, height: r.height};
            };
            return {box: {x: box.x, width: box.width}, dots: [...svg.querySelectorAll('circle.dot')].map(rect),
                    rings: [...svg.querySelectorAll('circle.rest-dot')].map((e) => getComputedStyle(e).stroke)};
        }""")
        box = drawn["box"]
        assert drawn["dots"]
        for b in drawn["dots"]:  # each dot whole, inside its picture
            assert box["x"] <= b["x"] and b["x"] + b["width"] <= box["x"] + box["width"]
            assert abs(b["width"] - b["height"]) < 0.5
        assert drawn["rings"] and "rgb(12, 17, 20)" not in drawn["rings"]  # rings in the club's colour, not dark
        tile = page.locator("#n-landing-angle").bounding_box()
        assert tile["height"] < 40  # number and degree sign on one line


# ---- the bay's player and units, the labels at two widths, the session's CSV (issue 30) ----------------------

WITH_BROWSER = pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
CLUB_DATA = {"Speed": 87.0, "AngleOfAttack": -4.2, "Path": 1.5, "FaceToTarget": -0.8, "Loft": 21.0}
IRON_BALL = {"Speed": 120.0, "VLA": 16.3, "HLA": 1.0, "TotalSpin": 7000.0, "SpinAxis": 3.0}
PUTT_BALL = {"Speed": 1.83 / 0.44704, "VLA": 2.0, "HLA": 0.0, "TotalSpin": 150.0, "SpinAxis": 0.0}
LONG_DRIVE = {"ball_speed_mph": 185.0, "launch_angle_deg": 11.0, "back_spin_rpm": 2300.0, "side_spin_rpm": 300.0}

TEXT_BOXES = """() => [...document.querySelectorAll('svg')].map(svg => {
  const s = svg.getBoundingClientRect();
  return {id: svg.id, box: [s.left, s.top, s.right, s.bottom], texts: [...svg.querySelectorAll('text')].map(t => {
    const b = t.getBoundingClientRect();
    return {text: t.textContent, box: [b.left, b.top, b.right, b.bottom],
            px: parseFloat(getComputedStyle(t).fontSize) * svg.getScreenCTM().a};
  })};
})"""
"""Every SVG's box on screen and each of its texts' boxes and rendered font sizes (CSS px)."""


def _club_cells(page) -> list[str]:
    return page.eval_on_selector_all("#shots tbody tr", "rows => rows.map(r => r.cells[2].textContent)")


def _bay_loaded(page) -> None:
    page.wait_for_function("() => document.querySelector('#bay-summary').textContent !== '—'", timeout=10_000)


@WITH_BROWSER
def test_the_club_menu_is_the_bays_player_and_each_shot_keeps_its_club_through_a_reload():
    with live_viewer(1280, 900) as (page, http, port, errors):
        page.wait_for_selector("#club[data-saved='DR']", state="attached", timeout=10_000)  # the bay's club at load
        options = page.eval_on_selector_all("#club option", "os => os.map(o => [o.value, o.textContent])")
        assert options == [[code, name] for code, name in GSPRO_CLUBS.items()]
        assert http.patch("/v1/bay", json={"player": {"club": "W3"}}, headers=KEYED).status_code == 200
        page.evaluate("loadBay()")  # as the page's poll does: the menu follows a change made elsewhere
        page.wait_for_function("() => document.querySelector('#club').value === 'W3'", timeout=10_000)
        before = http.get("/v1/bay", headers=KEYED).json()
        pick_club(page, "I7")
        after = http.get("/v1/bay", headers=KEYED).json()
        assert after["player"] == {"club": "I7", "handed": "RH"} and {**after, "player": before["player"]} == before

        gspro_over_tcp(port, 1, IRON_BALL)
        message = {"ShotNumber": 2, "APIversion": "1", "BallData": IRON_BALL, "ClubData": CLUB_DATA,
                   "ShotDataOptions": {"ContainsBallData": True, "ContainsClubData": True}}
        assert http.post("/v1/gspro", json=message, headers=KEYED).json()["Code"] == 200
        page.wait_for_selector("#shots tbody tr[data-shot='2']", timeout=10_000)
        assert page.is_visible("#club-numbers") and page.inner_text("#club-Speed").startswith("87.0")
        assert page.inner_text("#club-Speed").endswith("mph") and page.inner_text("#club-AngleOfAttack") == "-4.2°"
        assert page.inner_text("#club-numbers-title").startswith("Club")
        pick_club(page, "PT")
        gspro_over_tcp(port, 3, PUTT_BALL)
        assert http.post("/v1/shots/batch?viewer=true", json={"shots": [DRIVER]}, headers=KEYED).status_code == 200
        page.wait_for_selector("#shots tbody tr[data-shot='4']", timeout=10_000)
        tags = ["—", "PT putt", "I7", "I7"]  # newest first: the batch has no player
        assert _club_cells(page) == tags and page.get_attribute("#shots tbody tr[data-shot='3']", "data-putt") == "1"
        assert not page.is_visible("#club-numbers")  # the last shot came without ClubData
        assert "Putter: 1 putt" in page.inner_text("#legend") and "7-iron: 2 shots" in page.inner_text("#legend")

        page.reload()  # the tags are the service's, not this page's
        page.wait_for_selector("#shots tbody tr[data-shot='4']", timeout=10_000)
        assert _club_cells(page) == tags
        page.wait_for_function("() => document.querySelector('#club').value === 'PT'", timeout=10_000)
        assert errors == []


BAY_SET_ELSEWHERE = {
    "air": {"temperature_c": 21.37, "pressure_hpa": 1003.2, "humidity_pct": 55.0},
    "wind": {"speed_mph": 7.3, "from_deg": 135.0},
    "ground": {"surface": "green", "stimp_ft": 11.5, "elevation_m": -2.5, "slope_deg": 1.0, "slope_dir_deg": 90.0},
    "player": {"club": "H4", "handed": "LH"},
    "units": "imperial",
}
"""A bay with values the page's units would round (21.37 °C is 70.466 °F) and forms it does not show (pressure)."""


def _without(part: dict, *names: str) -> dict:
    return {k: v for k, v in part.items() if k not in names}


@WITH_BROWSER
def test_the_units_buttons_and_the_bay_form_send_only_what_they_change():
    with live_viewer(1280, 900) as (page, http, port, errors):
        assert http.put("/v1/bay", json=BAY_SET_ELSEWHERE, headers=KEYED).status_code == 200
        page.evaluate("loadBay()")
        page.wait_for_function("() => document.querySelector('#club').value === 'H4'", timeout=10_000)
        before = http.get("/v1/bay", headers=KEYED).json()
        sent: list = []
        page.on("request", lambda request: sent.append(request.post_data_json) if request.method == "PATCH" else None)
        for units in ("metric", "imperial"):
            page.evaluate("document.querySelector('#bay-message').dataset.state = ''")
            page.click(f".units button[data-units={units}]")
            page.wait_for_selector("#bay-message[data-state=saved]", timeout=10_000)
            assert sent[-1] == {"units": units}
            assert http.get("/v1/bay", headers=KEYED).json() == {**before, "units": units}
        assert len(sent) == 2

        page.fill("#bay-temperature", "70")  # imperial: °F, as typed; the air's other values as they came
        _submit_bay_form(page)
        air = {"temperature_f": 70, "pressure_hpa": 1003.2, "humidity_pct": 55.0}
        assert sent[-1] == {"air": air}
        bay = http.get("/v1/bay", headers=KEYED).json()
        assert bay == {**before, "air": air}

        page.fill("#bay-wind-speed", "12")
        page.fill("#bay-elevation", "-10")
        _submit_bay_form(page)
        wind = {**_without(before["wind"], "speed_mph"), "speed_mph": 12}
        ground = {**_without(before["ground"], "elevation_m"), "elevation_ft": -10}
        assert sent[-1] == {"wind": wind, "ground": ground}
        assert http.get("/v1/bay", headers=KEYED).json() == {**before, "air": air, "wind": wind, "ground": ground}
        page.wait_for_function("() => Math.abs(window.golfflightViewer.behind.ground_m + 3.048) < 1e-9", timeout=10_000)
        assert page.input_value("#bay-elevation") == "-10" and "10.0 ft from the tee" in page.inner_text("#bay-summary")

        page.evaluate("document.querySelector('#bay-message').dataset.state = ''")
        page.click("#bay-form button[type=submit]")  # nothing changed: nothing sent
        page.wait_for_selector("#bay-message[data-state=unchanged]", timeout=10_000)
        assert len(sent) == 4 and errors == []


@WITH_BROWSER
@pytest.mark.parametrize("width", [400, 1280])
def test_every_label_is_whole_and_at_least_10_px_at_400_and_1280_px(width):
    with live_viewer(width, 900) as (page, http, port, errors):
        _bay_loaded(page)
        assert http.patch("/v1/bay", json={"ground": {"elevation_m": -3.0}}, headers=KEYED).status_code == 200
        page.evaluate("loadBay()")
        assert http.post("/v1/shots?viewer=true", json=LONG_DRIVE, headers=KEYED).status_code == 200
        gspro_over_tcp(port, 2, WEDGE_BALL)
        gspro_over_tcp(port, 3, IRON_BALL)
        page.wait_for_selector("#shots tbody tr[data-shot='3']", timeout=10_000)
        page.wait_for_selector("#side polyline.latest[data-done]", state="attached", timeout=10_000)
        for units in ("imperial", "metric"):
            if units == "metric":
                page.click(".units button[data-units=metric]")
                page.wait_for_function("() => document.querySelector('#side text').textContent.endsWith(' m')",
                                       timeout=10_000)
            views = {view["id"]: view for view in page.evaluate(TEXT_BOXES)}
            assert set(views) == {"behind", "side", "top", "dispersion"}
            sizes = []
            for view in views.values():
                left, top, right, bottom = view["box"]
                for text in view["texts"]:
                    x0, y0, x1, y1 = text["box"]
                    inside = left - 0.5 <= x0 and x1 <= right + 0.5 and top - 0.5 <= y0 and y1 <= bottom + 0.5
                    assert inside, (units, view["id"], text, view["box"])
                    assert text["px"] >= 10, (units, view["id"], text)
                    sizes.append(text["px"])
            side = page.locator("#side text.along").all_text_contents()
            along = [int(text.split()[0]) for text in side]
            assert len(along) >= 4 and len({b - a for a, b in zip(along, along[1:])}) == 1, side  # evenly spaced
            assert width == 400 or units == "metric" or "350 yd" in side, side
            behind = page.evaluate("window.golfflightViewer.behind")
            assert behind["labels"] and behind["ground_m"] == -3.0
            assert_apart([label["box"] for label in behind["labels"]], behind["width"], behind["height"])
            for below, above in zip(behind["labels"], behind["labels"][1:]):
                assert below["line_y"] - above["line_y"] >= 14
            print(f"{width} px, {units}: labels {min(sizes):.1f}-{max(sizes):.1f} px, behind labels "
                  f"{[label['text'] for label in behind['labels']]}, side {side}")
        assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth") and errors == []


@WITH_BROWSER
def test_the_session_csv_downloads_with_the_key():
    with live_viewer(1280, 900) as (page, http, port, errors):
        _bay_loaded(page)
        gspro_over_tcp(port, 1, WEDGE_BALL)
        assert http.post("/v1/shots?viewer=true", json=DRIVER, headers=KEYED).status_code == 200
        page.wait_for_selector("#shots tbody tr[data-shot='2']", timeout=10_000)
        with page.expect_download(timeout=10_000) as download:
            page.click("#download-csv")
        saved = download.value
        text = Path(saved.path()).read_text()
        assert saved.suggested_filename == "golfflight-session-1.csv"
        assert text == http.get("/v1/session.csv", headers=KEYED).text
        rows = list(csv.DictReader(io.StringIO(text)))
        assert [row["source"] for row in rows] == ["open-connect", "http"] and rows[0]["club"] == "DR"
        assert [row["session"] for row in rows] == ["1", "1"]
        assert http.get("/v1/session.csv").status_code == 401 and errors == []  # the page sent the key
