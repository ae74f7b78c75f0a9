"""The bay as golfers and operators meet it (issue 56, items 1, 2, 5 and 6), on one real service (uvicorn on loopback,
Open Connect over a real TCP socket): a drive hit with the putter selected flies as the full shot it is and the reply
says so, while a putt still rolls; every reply kind says what it flew in and where each condition came from; a shot
that is not the bay's launch monitor's counts in no club's statistics unless it names one; /v1/latency keeps single
shots and batches apart; and every surface takes one club vocabulary."""

from __future__ import annotations

import json
import socket

import browser
import pytest
from golfflight.contract.putter import PUTT_MAX_LAUNCH_DEG, PUTT_MAX_SPEED_MPH
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from test_bay_runtime import PUTT_MPS, Connector, message, shot_events
from test_viewer import KEYED
from test_viewer_bay import live_viewer

from tests.servers import free_port, running

GREEN = {"ground": {"surface": "green", "stimp_ft": 11.0}, "player": {"club": "PT"}}
"""The issue's putting bay: the putter selected on a stimp-11 green."""
DRIVE = {"Speed": 167.0, "VLA": 10.9, "HLA": 0.0, "TotalSpin": 2686.0, "SpinAxis": 0.0}
"""The issue's drive: 167 mph, 10.9 deg, 2,686 rpm (rolled 3,334 yd as a putt on that green)."""
PUTT = {"Speed": PUTT_MPS / 0.44704, "VLA": 2.0, "HLA": 0.0, "TotalSpin": 150.0, "SpinAxis": 0.0}
"""A stimpmeter's roll: a real putt."""
SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
SOURCES = ("air", "wind", "ground")


@pytest.fixture(scope="module")
def bay():
    port = free_port()
    with running(create_app(ServiceSettings(connect_port=port))) as http:
        yield http, port


def sources(flight: dict) -> dict[str, str]:
    return {name: flight["flown_in"][f"{name}_from"] for name in SOURCES}


def test_a_drive_with_the_putter_selected_flies_as_a_full_shot_and_a_putt_still_rolls(bay):
    http, port = bay
    assert http.put("/v1/bay", json=GREEN).status_code == 200
    assert http.post("/v1/sessions", json={}).status_code == 201
    connector = Connector(port)
    over_tcp = [connector.reply(message(n, ball)) for n, ball in enumerate((DRIVE, PUTT), 1)]
    connector.close()
    over_http = [http.post("/v1/gspro", json=json.loads(message(n, ball))).json()
                 for n, ball in ((3, DRIVE), (4, PUTT))]
    for drive, putt in (over_tcp, over_http):
        flight = drive["Flight"]
        assert drive["Code"] == 200 and 200.0 < flight["carry_m"] < 300.0 and flight["total_m"] < 350.0
        assert not flight["flown_in"]["putt"] and "flown as a full shot" in flight["flown_in"]["note"]
        assert "167.0 mph" in flight["flown_in"]["note"] and f"{PUTT_MAX_SPEED_MPH:g} mph" in flight["flown_in"]["note"]
        rolled = putt["Flight"]
        assert rolled["carry_m"] == 0.0 and 1.5 <= rolled["total_m"] <= 4.0
        assert rolled["flown_in"]["putt"] and "note" not in rolled["flown_in"]
    events = shot_events(http, 4)
    assert [event.putt for event in events] == [False, True, False, True]
    assert all("flown as a full shot" in events[i].flight.flown_in.note for i in (0, 2))
    assert max(event.flight.apex_m for event in events if event.putt) <= 0.05
    summary = http.get("/v1/session/summary").json()["clubs"]
    assert [(row["club"], row["putts"], row["shots"]) for row in summary] == [("PT", False, 2), ("PT", True, 2)]


def test_a_steep_chip_with_the_putter_is_no_putt_either(bay):
    http, port = bay
    assert http.put("/v1/bay", json=GREEN).status_code == 200
    chip = {"Speed": 20.0, "VLA": PUTT_MAX_LAUNCH_DEG + 15.0, "HLA": 0.0, "TotalSpin": 3000.0, "SpinAxis": 0.0}
    reply = http.post("/v1/gspro", json=json.loads(message(1, chip))).json()
    assert reply["Code"] == 200 and reply["Flight"]["carry_m"] > 1.0 and not reply["Flight"]["flown_in"]["putt"]


def test_every_reply_kind_names_the_conditions_and_where_each_came_from(bay):
    http, port = bay
    bay_air = {"altitude_m": 1600.0, "temperature_c": 30.0}
    assert http.put("/v1/bay", json={"air": bay_air, "ground": {"surface": "rough"}}).status_code == 200
    assert http.post("/v1/sessions", json={}).status_code == 201
    single = http.post("/v1/shots?viewer=true", json={**SEVEN_IRON, "air": {"temperature_c": 10.0},
                                                        "wind": {"speed_mph": 10.0}}).json()
    assert sources(single) == {"air": "shot and bay", "wind": "shot", "ground": "bay"}
    assert single["flown_in"]["air"] == {"altitude_m": 1600.0, "temperature_c": 10.0}
    assert single["flown_in"]["ground"]["surface"] == "rough" and single["flown_in"]["wind"]["speed_mph"] == 10.0
    batch = http.post("/v1/shots/batch", json={"shots": [SEVEN_IRON, {**SEVEN_IRON, "air": {}, "ground": {
        "surface": "green"}}]}).json()["results"]
    assert [sources(result) for result in batch] == [
        {"air": "bay", "wind": "default", "ground": "bay"}, {"air": "shot", "wind": "default", "ground": "shot"}]
    assert batch[0]["flown_in"]["air"] == bay_air and batch[1]["flown_in"]["air"] == {}
    assert batch[0]["flown_in"]["wind"]["speed_mps"] == 0.0
    connector = Connector(port)
    tcp = connector.reply(message(7, DRIVE))
    connector.close()
    gspro = http.post("/v1/gspro", json=json.loads(message(8, DRIVE))).json()
    for reply in (tcp, gspro):
        assert sources(reply["Flight"]) == {"air": "bay", "wind": "default", "ground": "bay"}
    event = shot_events(http, 3)[0]
    assert event.source == "http" and event.flight.flown_in.air_from == "shot and bay"
    assert event.flight.flown_in.wind.speed_mph == 10.0


def test_the_largest_reply_still_fits_a_connectors_single_read(bay):
    """MLM2PRO-GSPro-Connector reads each reply with one recv(2048): the conditions and the note must not push a
    reply past it."""
    http, port = bay
    full = {"air": {"altitude_ft": 5280.0, "temperature_f": 95.0, "humidity_pct": 80.0},
            "wind": {"speed_mph": 25.0, "from_deg": 135.0, "profile": "log", "reference_height_m": 10.0},
            "ground": {"surface": "green", "stimp_ft": 13.0, "elevation_ft": -12.0, "slope_deg": 1.5,
                       "slope_dir_deg": 270.0}, "player": {"club": "PT"}}
    assert http.put("/v1/bay", json=full).status_code == 200
    with socket.create_connection(("127.0.0.1", port), timeout=10) as connector:
        connector.sendall(message(2**31 - 1, {**DRIVE, "Speed": 223.0, "VLA": 30.5, "HLA": -59.5}))
        wire = b""
        while not wire.endswith(b"}") or wire.count(b"{") != wire.count(b"}"):
            wire += connector.recv(4096)
    reply = json.loads(wire)
    assert reply["Code"] == 200 and "flown as a full shot" in reply["Flight"]["flown_in"]["note"]
    assert len(wire) < 2048, len(wire)


def test_only_the_bays_launch_monitor_or_a_named_club_counts_in_the_clubs(bay):
    http, port = bay
    assert http.put("/v1/bay", json={"player": {"club": "DR"}}).status_code == 200
    assert http.post("/v1/sessions", json={}).status_code == 201
    assert http.post("/v1/shots?viewer=true", json=SEVEN_IRON).status_code == 200
    assert http.post("/v1/shots?viewer=true", json={**SEVEN_IRON, "club": "7-Iron"}).status_code == 200
    shots = [SEVEN_IRON, {**SEVEN_IRON, "club": "pw"}]
    assert http.post("/v1/shots/batch?viewer=true", json={"shots": shots}).status_code == 200
    connector = Connector(port)
    connector.reply(message(1, DRIVE))
    connector.close()
    summary = http.get("/v1/session/summary").json()["clubs"]
    assert [(row.get("club"), row["shots"]) for row in summary] == [("DR", 1), ("I7", 1), ("PW", 1), (None, 2)]


def test_latency_keeps_single_shots_and_batches_apart(bay):
    http, _ = bay
    assert http.put("/v1/bay", json={}).status_code == 200
    before = http.get("/v1/latency").json()
    for _ in range(3):
        assert http.post("/v1/shots", json=SEVEN_IRON).status_code == 200
    assert http.post("/v1/shots/batch", json={"shots": [SEVEN_IRON] * 2000}).status_code == 200
    after = http.get("/v1/latency").json()
    assert after["simulation"]["count"] - before["simulation"]["count"] == 3
    assert after["request"]["count"] - before["request"]["count"] == 3
    assert after["batch"]["simulation"]["count"] - before["batch"]["simulation"]["count"] == 1
    assert after["batch"]["request"]["count"] - before["batch"]["request"]["count"] == 1
    assert after["batch"]["simulation"]["p50_ms"] > 0 and after["simulation"]["p99_ms"] > 0


@pytest.mark.parametrize(("typed", "code"), [("7i", "I7"), ("7 iron", "I7"), ("I7", "I7"), ("driver", "DR"),
                                             ("3w", "W3"), ("Sand Wedge", "SW"), ("putter", "PT"), ("H4", "H4")])
def test_every_surface_takes_the_clis_names_and_gspros_codes(bay, typed, code):
    http, port = bay
    connector = Connector(port)
    assert connector.reply(message(1, PUTT))["Code"] == 200  # the server has taken the connection
    answer = http.patch("/v1/bay", json={"player": {"club": "LW" if code != "LW" else "SW"}})
    assert answer.status_code == 200
    answer = http.patch("/v1/bay", json={"player": {"club": typed}})
    assert answer.status_code == 200 and answer.json()["player"]["club"] == code
    told = [item for item in connector.objects(2.0) + connector.objects(0.5) if item["Code"] == 201]
    connector.close()
    assert told[-1]["Player"]["Club"] == code
    assert http.post("/v1/shots", json={**SEVEN_IRON, "club": typed}).status_code == 200


def test_an_unknown_club_is_refused_naming_the_field_and_what_is_taken(bay):
    http, _ = bay
    for path, body, field in (("/v1/bay", {"player": {"club": "wedge"}}, "player.club"),
                              ("/v1/shots", {**SEVEN_IRON, "club": "10i"}, "club")):
        answer = http.patch(path, json=body) if path == "/v1/bay" else http.post(path, json=body)
        assert answer.status_code == 422, answer.text
        detail = answer.json()["detail"][0]
        assert detail["field"] == field and "unknown club" in detail["message"]
        assert "I7" in detail["message"] and "7i" in detail["message"]


NOTE_SHOWN = "() => !document.querySelector('#shot-note').hidden"
NOTE_HIDDEN = "() => document.querySelector('#shot-note').hidden"


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
@pytest.mark.parametrize("width", [400, 1280])
def test_the_viewer_says_a_putter_shot_flew_as_a_full_shot_and_a_putt_rolled(width):
    """The page shows the reply's note beside the last shot's numbers, whole within the page's width, and takes it
    away for the putt that follows."""
    with live_viewer(width, 900) as (page, http, _port, errors):
        assert http.patch("/v1/bay", json=GREEN, headers=KEYED).status_code == 200
        drive = http.post("/v1/gspro", json=json.loads(message(1, DRIVE)), headers=KEYED).json()
        page.wait_for_function(NOTE_SHOWN, timeout=10_000)
        note = page.locator("#shot-note")
        assert note.inner_text() == drive["Flight"]["flown_in"]["note"]
        box = note.bounding_box()
        assert box["width"] > 0 and box["x"] >= 0 and box["x"] + box["width"] <= width
        assert not page.inner_text("#last-source").endswith("putt")
        assert http.post("/v1/gspro", json=json.loads(message(2, PUTT)), headers=KEYED).json()["Code"] == 200
        page.wait_for_function(NOTE_HIDDEN, timeout=10_000)
        assert page.inner_text("#last-source").endswith("putt")
        assert errors == []
