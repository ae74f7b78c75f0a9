"""Issue 43: the bay's sessions. A new session empties every screen (the feed, the stream, the page); sessions are
listed with their shots and bounded; a session's CSV flies again through `golfflight simulate` to the same carries
(air, wind, ground and a putt); the per-club summary's statistics against cases worked by hand and against the CSV;
and in Chromium the summary table, the ellipses and the "New session" control."""

from __future__ import annotations

import asyncio
import csv
import io
import json
import math
import time
from types import SimpleNamespace

import browser
import numpy as np
import pytest
from golfflight.cli import main
from golfflight.contract.bay import Player
from golfflight.contract.columns import columns_message
from golfflight.contract.requests import ShotRequest
from golfflight.contract.session import NewSession
from golfflight.service.runtime.club_stats import ClubStats, Figures
from golfflight.service.runtime.feed import ShotFeed
from golfflight.service.runtime.sessions import Session, Sessions, SessionShot
from golfflight.service.viewer.stream import events
from pydantic import ValidationError
from servers import keyed_service
from test_viewer import DRIVER, KEY, KEYED, WEDGE_BALL, gspro_over_tcp, publish
from test_viewer_bay import live_viewer

WITH_BROWSER = pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))


def landing_at(x_m: float, y_m: float) -> Figures:
    """A shot's figures with its carry the landing's distance, its lateral the landing's x, rest 2 m further."""
    return Figures(y_m, y_m + 2.0, 30.0, x_m, x_m, y_m, x_m, y_m + 2.0)


def summed(points: list[tuple[float, float]]) -> ClubStats:
    stats = ClubStats(landing_at(*points[0]))
    for point in points:
        stats.add(landing_at(*point))
    return stats


# ---- the statistics, worked by hand ------------------------------------------------------------------------------


def test_three_shots_worked_by_hand():
    """Landing points (-1, 100), (1, 100), (0, 103) m: the mean is (0, 101); the deviations are x (-1, 1, 0) and
    y (-1, -1, 2), so var x = (1 + 1 + 0) / 2 = 1, var y = (1 + 1 + 4) / 2 = 3 and cov = (1 - 1 + 0) / 2 = 0: the long
    axis lies down the target line (angle 0), semi-axes sqrt(5.9915 x 3) = 4.2396 m and sqrt(5.9915) = 2.4477 m
    (chi2 with 2 degrees of freedom at 95 %: -2 ln 0.05 = 5.9915). Carry 100, 100, 103: mean 101, sd sqrt(3)."""
    summary = summed([(-1.0, 100.0), (1.0, 100.0), (0.0, 103.0)]).summary("I7", putts=False)
    assert summary.shots == 3
    assert (summary.carry.mean_m, summary.carry.sd_m) == pytest.approx((101.0, math.sqrt(3.0)), rel=1e-12)
    assert (summary.lateral.mean_m, summary.lateral.sd_m) == pytest.approx((0.0, 1.0), abs=1e-12)
    assert (summary.total.mean_m, summary.apex.sd_m) == pytest.approx((103.0, 0.0), abs=1e-12)
    landing = summary.landing
    assert (landing.center_x_m, landing.center_y_m) == pytest.approx((0.0, 101.0), abs=1e-12)
    assert (landing.semi_major_m, landing.semi_minor_m) == pytest.approx((4.23962, 2.44775), rel=1e-5)
    assert landing.angle_deg == pytest.approx(0.0, abs=1e-9)
    assert summary.rest.center_y_m == pytest.approx(103.0) and summary.rest.semi_major_m == pytest.approx(4.23962,
                                                                                                            rel=1e-5)


def test_a_tilted_scatter_and_a_shot_dropped_again():
    """Deviations (-2, -2), (2, 2), (1, -1), (-1, 1) about (5, 150): var x = var y = (4 + 4 + 1 + 1) / 3 = 10/3,
    cov = (4 + 4 - 1 - 1) / 3 = 2, eigenvalues 10/3 +- 2 = 16/3 and 4/3, the long axis along (1, 1): turned 45 degrees
    right of the line; semi-axes sqrt(5.9915 x 16/3) = 5.6528 m and sqrt(5.9915 x 4/3) = 2.8264 m. A fifth shot added
    and taken off again (the cap) leaves the same numbers."""
    points = [(3.0, 148.0), (7.0, 152.0), (6.0, 149.0), (4.0, 151.0)]
    stats = summed(points)
    landing = stats.summary("DR", False).landing
    assert (landing.center_x_m, landing.center_y_m) == pytest.approx((5.0, 150.0), abs=1e-12)
    assert (landing.semi_major_m, landing.semi_minor_m) == pytest.approx((5.65283, 2.82642), rel=1e-5)
    assert landing.angle_deg == pytest.approx(45.0, abs=1e-9)
    flipped = summed([(10.0 - x, y) for x, y in points]).summary("DR", False).landing  # mirrored: long to the left
    assert flipped.angle_deg == pytest.approx(-45.0, abs=1e-9)
    stats.add(landing_at(40.0, 90.0))
    stats.add(landing_at(40.0, 90.0), sign=-1)
    assert stats.summary("DR", False) == summed(points).summary("DR", False)
    two = summed(points[:2]).summary("DR", False)
    assert two.landing is None and two.carry.sd_m == pytest.approx(math.sqrt(8.0))  # an ellipse needs 3 shots
    one = summed(points[:1]).summary("DR", False)
    assert one.carry.sd_m is None and one.carry.mean_m == 148.0


def fake_shot(shot_id: int, club: str | None, carry_m: float, putt: bool = False) -> SessionShot:
    """A session shot whose result has just the figures a summary reads."""
    result = SimpleNamespace(carry_m=carry_m, total_m=carry_m + 5.0, apex_m=20.0, lateral_m=0.0,
                             landing=SimpleNamespace(x_m=0.0, y_m=carry_m), rest=SimpleNamespace(x_m=0.0,
                                                                                               y_m=carry_m + 5.0))
    player = None if club is None else Player(club=club)
    return SessionShot(shot_id, 0.0, "http", None, player, putt, None, result)


def test_clubs_in_the_bags_order_with_their_carry_gaps():
    session = Session(1, None, 0.0)
    for n, (club, carry, putt) in enumerate([("PW", 120.0, False), (None, 200.0, False), ("DR", 230.0, False),
                                             ("PT", 0.0, True), ("I7", 150.0, False), ("DR", 240.0, False)]):
        session.add(fake_shot(n, club, carry, putt))
    rows = session.club_summaries()
    assert [(row.club, row.putts, row.shots) for row in rows] == [
        ("DR", False, 2), ("I7", False, 1), ("PW", False, 1), ("PT", True, 1), (None, False, 1)]
    assert [row.carry_gap_m for row in rows] == [85.0, 30.0, None, None, None]


def test_the_shots_are_capped_over_all_sessions_and_the_oldest_session_forgotten():
    sessions = Sessions(max_shots=5, max_sessions=3)
    for n in range(3):
        sessions.add(fake_shot(n, "DR", 200.0 + n))
    sessions.start("Ann")
    for n in range(3, 7):
        sessions.add(fake_shot(n, "I7", 150.0))
    first, second = sessions.get(1), sessions.get(2)
    assert [s.id for s in first.shots] == [2] and first.dropped == 2 and [s.session for s in second.shots] == [2] * 4
    assert first.club_summaries()[0].carry.mean_m == 202.0  # the dropped shots came off the sums
    listing = sessions.listing()
    assert [(s.id, s.player, s.shots, s.dropped_shots, s.current) for s in listing.sessions] == [
        (1, None, 1, 2, False), (2, "Ann", 4, 0, True)]
    sessions.start(None), sessions.start(None)
    assert sessions.get(1) is None and sessions.current.id == 4 and listing.max_shots == 5
    for n in range(7, 12):  # session 1's shot went with it: room for one more before session 2's go
        sessions.add(fake_shot(n, "PW", 120.0))
    assert len(sessions.get(2).shots) == 0 and len(sessions.current.shots) == 5
    assert sessions.get(2).club_summaries() == []


def test_a_player_name_is_plain_text():
    assert NewSession(player="  José Ortiz ").player == "José Ortiz"
    for refused in ("=HYPERLINK(1)", "+1", "-x", "@a", "", "   ", "a\tb", "x" * 41, "\ud800"):
        with pytest.raises(ValidationError):
            NewSession(player=refused)
    with pytest.raises(ValidationError):
        NewSession.model_validate({"player": "Ann", "club": "DR"})


# ---- a new session empties the screens ---------------------------------------------------------------------------


def test_a_new_session_empties_the_screens_and_is_announced_first(engine):
    request = ShotRequest(**DRIVER)
    feed = ShotFeed()
    open_viewer = feed.subscribe()
    for _ in range(3):
        publish(feed, engine, request)
    assert len(open_viewer.pending) == 3 and len(feed.session) == 3
    started = feed.start_session("Ann")
    assert (started.id, started.player) == (2, "Ann") and len(feed.session) == 0
    assert not open_viewer.pending and open_viewer.session is started  # the old session's unsent shots let go
    later = feed.subscribe(after_id=1)
    assert not later.pending and later.session is started  # a reconnecting page: nothing of the old session
    publish(feed, engine, request)

    async def stream() -> list[str]:
        return [frame async for frame in events(feed, open_viewer, lifetime_s=0.2)]

    frames = asyncio.run(stream())
    assert frames[1].startswith('event: session\ndata: {"id":2,"player":"Ann",') and '"shots":1' in frames[1]
    assert frames[2].startswith("id: 4\nevent: shot\n") and len(frames) == 3
    assert [s.shots for s in feed.sessions.listing().sessions] == [3, 1]


# ---- over HTTP ---------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def service():
    with keyed_service(KEY) as served:
        yield served


def rows_of(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_sessions_are_started_listed_and_refused_over_http(service):
    http, _, _ = service
    before = http.get("/v1/sessions", headers=KEYED).json()
    started = http.post("/v1/sessions", json={"player": "Bea"}, headers=KEYED)
    assert started.status_code == 201
    info = started.json()
    assert info["player"] == "Bea" and info["current"] and info["shots"] == 0 and info["id"] == before["current"] + 1
    assert http.post("/v1/sessions", headers=KEYED).status_code == 201  # no body: no player
    listing = http.get("/v1/sessions", headers=KEYED).json()
    assert listing["current"] == info["id"] + 1 and listing["max_shots"] == 10_000 and listing["max_sessions"] == 100
    assert [s["player"] for s in listing["sessions"] if s["id"] == info["id"]] == ["Bea"]
    refused = http.post("/v1/sessions", json={"player": "=cmd|' /C calc'!A0"}, headers=KEYED)
    assert refused.status_code == 422 and "formula" in refused.text
    assert http.post("/v1/sessions", json={"player": "Bea"}).status_code == 401
    for path in ("/v1/session.csv?session=99999", "/v1/session/summary?session=99999"):
        missing = http.get(path, headers=KEYED)
        assert missing.status_code == 404 and "GET /v1/sessions" in missing.json()["detail"]
    assert http.get("/v1/session.csv?session=0", headers=KEYED).status_code == 422


SWING = [  # (ball speed mph, launch deg, spin rpm, spin axis deg): a 7-iron's scatter
    (120.0, 16.3, 7000.0, 3.0), (118.0, 17.5, 7300.0, -4.0), (122.5, 15.4, 6600.0, 8.0), (119.0, 16.0, 7100.0, 0.0)]


def test_the_summary_is_the_statistics_of_the_sessions_csv(service):
    http, port, _ = service
    assert http.post("/v1/sessions", json={"player": "Cy"}, headers=KEYED).status_code == 201
    assert http.patch("/v1/bay", json={"player": {"club": "I7"}}, headers=KEYED).status_code == 200
    for speed, angle, spin, axis in SWING:
        shot = {"ball_speed_mph": speed, "launch_angle_deg": angle, "spin_rpm": spin, "spin_axis_deg": axis,
                "club": "7i"}  # not the bay's launch monitor: counted in the club it names (issue 56)
        assert http.post("/v1/shots?viewer=true", json=shot, headers=KEYED).status_code == 200
    assert http.patch("/v1/bay", json={"player": {"club": "DR"}}, headers=KEYED).status_code == 200
    gspro_over_tcp(port, 1, {"Speed": 165.0, "VLA": 11.0, "HLA": 1.0, "TotalSpin": 2600.0, "SpinAxis": -3.0})
    summary = http.get("/v1/session/summary", headers=KEYED).json()
    rows = rows_of(http.get("/v1/session.csv", headers=KEYED).text)
    assert summary["session"]["player"] == "Cy" and {row["player"] for row in rows} == {"Cy"}
    driver, iron = summary["clubs"]
    assert (driver["club"], driver["shots"], iron["club"], iron["shots"]) == ("DR", 1, "I7", 4)
    assert driver["carry_gap_m"] == pytest.approx(driver["carry"]["mean_m"] - iron["carry"]["mean_m"])
    assert "sd_m" not in driver["carry"] and "landing" not in driver and "carry_gap_m" not in iron
    column = {name: np.array([float(r[name]) for r in rows if r["club"] == "I7"]) for name in rows[0]
              if name.endswith("_m")}
    for figure, name in (("carry", "carry_m"), ("total", "total_m"), ("apex", "apex_m"), ("lateral", "lateral_m")):
        values = column[name]
        assert iron[figure]["mean_m"] == pytest.approx(values.mean(), abs=1e-9)
        assert iron[figure]["sd_m"] == pytest.approx(values.std(ddof=1), abs=1e-9)
    for point in ("landing", "rest"):
        xy = np.array([column[f"{point}_x_m"], column[f"{point}_y_m"]])
        eigenvalues, vectors = np.linalg.eigh(np.cov(xy))
        long_axis = vectors[:, 1] * np.sign(vectors[1, 1])  # (x, y), pointing down the line
        ellipse = iron[point]
        assert (ellipse["center_x_m"], ellipse["center_y_m"]) == pytest.approx(tuple(xy.mean(axis=1)), abs=1e-9)
        assert ellipse["semi_major_m"] == pytest.approx(math.sqrt(-2 * math.log(0.05) * eigenvalues[1]), rel=1e-9)
        assert ellipse["semi_minor_m"] == pytest.approx(math.sqrt(-2 * math.log(0.05) * eigenvalues[0]), rel=1e-6,
                                                        abs=1e-9)
        assert ellipse["angle_deg"] == pytest.approx(math.degrees(math.atan2(*long_axis)), abs=1e-6)


# ---- the session's CSV flies again ---------------------------------------------------------------------------------

BAY = {"air": {"temperature_f": 88.0, "altitude_ft": 5200.0, "humidity_pct": 30.0},
       "wind": {"speed_mph": 12.0, "from_deg": 200.0, "profile": "log"},
       "ground": {"surface": "green", "stimp_ft": 11.5, "elevation_m": -2.0, "slope_deg": 1.0, "slope_dir_deg": 90.0}}
OWN = {"ball_speed_mph": 150.0, "launch_angle_deg": 12.5, "back_spin_rpm": 4000.0, "side_spin_rpm": -600.0,
       "air": {"density_kg_m3": 1.1}, "wind": {"speed_mps": 6.0, "from_deg": 90.0},
       "ground": {"surface": "rough", "elevation_ft": 10.0}}
PUTT = {"Speed": 2.4 / 0.44704, "VLA": 1.5, "HLA": -2.0, "TotalSpin": 120.0, "SpinAxis": 0.0}


def fly_a_varied_session(http, port) -> None:
    """A new session: a shot with its own air, wind and ground over HTTP, a wedge over TCP and a drive over
    /v1/gspro in the bay's hot, high, windy air onto a sloping green below the tee, and a putt with the putter."""
    assert http.post("/v1/sessions", json={"player": "Dee"}, headers=KEYED).status_code == 201
    assert http.patch("/v1/bay", json={"player": {"club": "I5"}}, headers=KEYED).status_code == 200
    assert http.post("/v1/shots?viewer=true", json={**OWN, "club": "5 iron"}, headers=KEYED).status_code == 200
    assert http.patch("/v1/bay", json={**BAY, "player": {"club": "SW"}}, headers=KEYED).status_code == 200
    gspro_over_tcp(port, 1, WEDGE_BALL)
    drive = {"ShotNumber": 2, "APIversion": "1", "BallData": {"Speed": 160.0, "VLA": 12.0, "HLA": 0.5,
                                                              "BackSpin": 2700.0, "SideSpin": 300.0}}
    assert http.patch("/v1/bay", json={"player": {"club": "DR"}}, headers=KEYED).status_code == 200
    assert http.post("/v1/gspro", json=drive, headers=KEYED).json()["Code"] == 200
    assert http.patch("/v1/bay", json={"player": {"club": "PT"}}, headers=KEYED).status_code == 200
    gspro_over_tcp(port, 3, PUTT)
    assert http.put("/v1/bay", json={}, headers=KEYED).status_code == 200


def test_simulate_flies_the_session_csv_back_to_the_same_carries(service, tmp_path):
    http, port, _ = service
    fly_a_varied_session(http, port)
    session = tmp_path / "session.csv"
    session.write_text(http.get("/v1/session.csv", headers=KEYED).text)
    served = rows_of(session.read_text())
    assert [(r["club"], r["putt"], r["source"]) for r in served] == [
        ("I5", "0", "http"), ("SW", "0", "open-connect"), ("DR", "0", "gspro-http"), ("PT", "1", "open-connect")]
    assert served[1]["wind_profile"] == "log" and served[1]["ground_surface"] == "green"
    assert float(served[-1]["carry_m"]) == 0.0 and float(served[-1]["total_m"]) > 0.5  # rolled, not flown
    out = tmp_path / "again.csv"
    assert main(["simulate", str(session), "--out", str(out)]) == 0
    again = rows_of(out.read_text())
    assert [r["shot_id"] for r in again] == [r["shot_id"] for r in served]
    for before, after in zip(served, again, strict=True):
        for name in ("carry_m", "total_m", "rest_x_m", "rest_y_m", "apex_m"):
            assert abs(float(after[name]) - float(before[name])) < 0.01, (before["shot_id"], name)
        for echoed in ("session", "player", "source", "club", "putt", "wind_speed_mps", "wind_speed_mph",
                       "wind_from_deg", "ground_surface", "ground_elevation_m", "ground_elevation_ft"):
            assert after.get(echoed, "") == before.get(echoed, ""), (before["shot_id"], echoed)
    assert float(again[0]["air_density_kg_m3"]) == 1.1 and float(again[1]["air_density_kg_m3"]) < 1.05


def test_simulate_honours_the_wind_and_echoes_the_club(tmp_path, capsys):
    launches = tmp_path / "launches.csv"
    launches.write_text("club,ball_speed_mps,launch_angle_deg,spin_rpm,wind_speed_mps,wind_from_deg\n"
                        "7-iron,53.6,16.3,7000,,\n7-iron,53.6,16.3,7000,8,0\n")
    assert main(["simulate", str(launches)]) == 0
    calm, headwind = json.loads(capsys.readouterr().out)["results"]
    assert calm["club"] == headwind["club"] == "7-iron" and headwind["wind_speed_mps"] == 8.0
    assert "wind_speed_mps" not in calm and headwind["carry_m"] < calm["carry_m"] - 5
    assert "putt" in (columns_message("f.csv", ["ball_speed_mps", "launch_angle_deg", "spin_rpm", "putt"]) or "")


# ---- the page ------------------------------------------------------------------------------------------------------

POLYGON_CENTRE = """(club) => {
  const points = document.querySelector(`#dispersion polygon.ellipse[data-club='${club}']`).getAttribute('points')
    .trim().split(' ').map(p => p.split(',').map(Number));
  return [points.reduce((s, p) => s + p[0], 0) / points.length, points.reduce((s, p) => s + p[1], 0) / points.length];
}"""
DOTS_CENTRE = """(ids) => {
  const dots = ids.map(id => document.querySelector(`#dispersion circle.dot[data-shot='${id}']`));
  return [dots.reduce((s, d) => s + Number(d.getAttribute('cx')), 0) / dots.length,
          dots.reduce((s, d) => s + Number(d.getAttribute('cy')), 0) / dots.length];
}"""


def _iron_and_driver_shots(page, http, port) -> None:
    """Four 7-irons over TCP and three drivers over HTTP, each club picked before its shots."""
    assert http.patch("/v1/bay", json={"player": {"club": "I7"}}, headers=KEYED).status_code == 200
    for number, (speed, angle, spin, axis) in enumerate(SWING, start=1):
        gspro_over_tcp(port, number, {"Speed": speed, "VLA": angle, "HLA": axis / 4, "TotalSpin": spin,
                                      "SpinAxis": axis})
    assert http.patch("/v1/bay", json={"player": {"club": "DR"}}, headers=KEYED).status_code == 200
    for side_spin in (-400.0, 0.0, 500.0):
        drive = {**DRIVER, "side_spin_rpm": side_spin, "club": "driver"}
        assert http.post("/v1/shots?viewer=true", json=drive, headers=KEYED).status_code == 200
    page.wait_for_selector("#shots tbody tr[data-shot='7']", timeout=10_000)
    page.wait_for_function(  # the summary read after the last drive
        "() => { const r = document.querySelector(\"#summary tbody tr[data-club='DR']\"); "
        "return r !== null && r.cells[1].textContent === '3'; }", timeout=10_000)


def _summary_table_and_ellipses(page, http) -> None:
    """The table's rows and figures are the API's in yards; each ellipse is centred on its club's landing dots."""
    summary = http.get("/v1/session/summary", headers=KEYED).json()
    rows = page.eval_on_selector_all("#summary tbody tr", "rows => rows.map(r => [...r.cells].map(c => c.textContent))")
    assert [row[:2] for row in rows] == [["Driver", "3"], ["7-iron", "4"]]
    driver, iron = summary["clubs"]
    carry = f"{driver['carry']['mean_m'] / 0.9144:.1f} ± {driver['carry']['sd_m'] / 0.9144:.1f}"
    assert rows[0][2] == carry and rows[0][3] == f"{driver['carry_gap_m'] / 0.9144:.1f}" and rows[1][3] == "—"
    ellipse = iron["landing"]
    assert rows[1][7] == f"{2 * ellipse['semi_major_m'] / 0.9144:.1f} × {2 * ellipse['semi_minor_m'] / 0.9144:.1f}"
    assert "(yd)" in page.inner_text("#summary thead")
    assert page.locator("#dispersion polygon.ellipse").count() == 2
    for club, ids in (("I7", [1, 2, 3, 4]), ("DR", [5, 6, 7])):
        centre, dots = page.evaluate(POLYGON_CENTRE, club), page.evaluate(DOTS_CENTRE, ids)
        assert centre == pytest.approx(dots, abs=0.5), club  # the projection is affine: the centre is the mean


def _new_session_empties_both_screens(page, second, http) -> None:
    page.fill("#session-player", "Eve")
    page.click("#new-session")
    for screen in (page, second):
        screen.wait_for_function("() => document.querySelectorAll('#shots tbody tr').length === 0", timeout=10_000)
        screen.wait_for_function("() => document.querySelector('#session-title').textContent.includes('Eve')",
                                 timeout=10_000)
        assert screen.locator("#dispersion circle.dot, #dispersion polygon.ellipse, #legend li").count() == 0
        assert screen.locator("#summary").is_hidden() and screen.inner_text("#n-carry") == "—"
        assert screen.locator("#behind polyline.path, #side polyline.path, #top polyline.path").count() == 0
    listing = http.get("/v1/sessions", headers=KEYED).json()
    assert [s["player"] for s in listing["sessions"] if s["current"]] == ["Eve"]
    assert page.input_value("#session-player") == ""


@WITH_BROWSER
def test_the_page_shows_the_summary_and_ellipses_and_new_session_empties_every_screen(tmp_path):
    with live_viewer(1400, 1000) as (page, http, port, errors):
        _iron_and_driver_shots(page, http, port)
        time.sleep(3.5)  # the last drive has played: its landing and rest drawn
        _summary_table_and_ellipses(page, http)
        page.screenshot(path=str(tmp_path / "summary.png"), full_page=True)
        second = page.context.new_page()  # another screen of the bay
        second.goto(str(http.base_url).rstrip("/") + "/viewer")
        second.wait_for_selector("#key-form:not([hidden])", timeout=10_000)
        second.fill("#key", KEY)
        second.click("#key-form button")
        second.wait_for_selector("#summary tbody tr[data-club='I7']", timeout=10_000)
        _new_session_empties_both_screens(page, second, http)
        assert http.post("/v1/shots?viewer=true", json={**DRIVER, "club": "DR"}, headers=KEYED).status_code == 200
        for screen in (page, second):
            screen.wait_for_selector("#shots tbody tr[data-shot='8']", timeout=10_000)
            screen.wait_for_selector("#summary tbody tr[data-club='DR']", timeout=10_000)
        page.reload()  # a reloaded screen gets the current session's shots only
        page.wait_for_selector("#shots tbody tr[data-shot='8']", timeout=10_000)
        assert page.locator("#shots tbody tr").count() == 1 and "Eve" in page.inner_text("#session-title")
        page.fill("#session-player", "=1+1")
        page.click("#new-session")
        page.wait_for_selector("#session-message[data-state=refused]", timeout=10_000)
        assert "formula" in page.inner_text("#session-message") and page.locator("#shots tbody tr").count() == 1
        assert errors == []
    assert (tmp_path / "summary.png").stat().st_size > 20_000


def test_past_the_cap_the_source_holding_the_most_lets_its_oldest_go():
    sessions = Sessions(max_shots=6, max_sessions=2)
    for n in range(2):
        sessions.add(fake_shot(n, "DR", 200.0)._replace(client="bay"))
    sessions.start(None)
    for n in range(2, 9):  # another address's flood: past the cap, only its own oldest go
        sessions.add(fake_shot(n, "PW", 120.0)._replace(client="flood"))
    assert [s.id for s in sessions.get(1).shots] == [0, 1] and [s.id for s in sessions.current.shots] == [5, 6, 7, 8]
    assert sessions.current.dropped == 3 and sessions.get(1).dropped == 0
    sessions.start(None)  # session 1 forgotten with its shots: the flood's next shots fit beside its own
    for n in range(9, 11):
        sessions.add(fake_shot(n, "PW", 120.0)._replace(client="flood"))
    assert [s.id for s in sessions.get(2).shots] == [5, 6, 7, 8] and len(sessions.current.shots) == 2
