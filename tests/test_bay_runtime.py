"""The bay runtime as a bay meets it, over a real uvicorn server and real sockets: the viewer draws the flight that
was answered (its path ends at the reply's rest and passes its landing), GSPro shots with the putter selected roll
on the bay's green, a club change reaches connectors as Code 201, a bay file broken while serving keeps the last
good bay, PATCH changes one part, the session downloads as simulate's CSV, and the odd inputs that used to be 500s
are answered."""

from __future__ import annotations

import codecs
import csv
import io
import json
import os
import signal
import socket
import subprocess
import sys
import time

import httpx
import numpy as np
import pytest
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.viewer.event import ShotEvent
from golfflight.shots.files import write_text_atomic

from tests.servers import free_port, running

BAY = {
    "air": {"altitude_m": 1600.0, "temperature_c": 30.0},
    "wind": {"speed_mps": 8.0, "from_deg": 0.0},
    "ground": {"surface": "green", "stimp_ft": 12.0, "elevation_m": -3.0},
}
"""The issue's bay: 1,600 m, 30 degC, an 8 m/s headwind, a stimp-12 green 3 m below the tee."""
BALLS = [
    {"Speed": 167.0, "VLA": 11.0, "HLA": -1.0, "TotalSpin": 2650.0, "SpinAxis": -4.0},
    {"Speed": 123.0, "VLA": 16.1, "HLA": 1.5, "TotalSpin": 7124.0, "SpinAxis": 3.0},
    {"Speed": 102.0, "VLA": 24.0, "HLA": 0.0, "BackSpin": 8600.0, "SideSpin": -400.0},
]
PUTT_MPS = 1.83
"""The stimpmeter's exit speed (4.09 mph)."""


def message(number: int, ball: dict, **more) -> bytes:
    return json.dumps({"DeviceID": "bay test", "ShotNumber": number, "APIversion": "1", "BallData": ball,
                       "ShotDataOptions": {"ContainsBallData": True}, **more}).encode()


class Connector:
    """A connector's socket that reads replies as objects, putting Code 201 player information aside as a
    connector's reading loop does."""

    def __init__(self, port: int):
        self.socket = socket.create_connection(("127.0.0.1", port), timeout=10)
        self.buffer, self.players = "", []

    def objects(self, timeout_s: float) -> list[dict]:
        """Every object that arrives within `timeout_s` (returns as soon as one is complete)."""
        self.socket.settimeout(timeout_s)
        try:
            self.buffer += self.socket.recv(65536).decode()
        except TimeoutError:
            return []
        found, decoder = [], json.JSONDecoder()
        while self.buffer.strip():
            try:
                item, end = decoder.raw_decode(self.buffer.lstrip())
            except ValueError:
                break
            self.buffer = self.buffer.lstrip()[end:]
            found.append(item)
        return found

    def reply(self, data: bytes) -> dict:
        self.socket.sendall(data)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            for item in self.objects(1.0):
                if item["Code"] == 201:
                    self.players.append(item)
                else:
                    return item
        raise AssertionError("no reply")

    def close(self) -> None:
        self.socket.close()


def shot_events(http: httpx.Client, count: int) -> list[ShotEvent]:
    """The kept shots' events (a viewer opening now gets every kept shot)."""
    found = []
    kind = None
    with http.stream("GET", "/v1/events") as stream:
        for line in stream.iter_lines():
            kind = line.removeprefix("event: ") if line.startswith("event: ") else kind
            if line.startswith("data: ") and kind == "shot":  # a stream opens with the session's event
                found.append(ShotEvent.model_validate_json(line.removeprefix("data: ")))
                if len(found) == count:
                    return found
    raise AssertionError("the stream ended early")


def drawn(event: ShotEvent) -> np.ndarray:
    return np.array([(p.x_m, p.y_m, p.z_m) for p in event.flight.trajectory])


@pytest.fixture()
def bay_service():
    port = free_port()
    with running(create_app(ServiceSettings(connect_port=port))) as http:
        yield http, port


def test_the_viewer_draws_the_flight_answered_over_tcp_and_http_in_the_bays_conditions(bay_service):
    http, port = bay_service
    assert http.put("/v1/bay", json=BAY).status_code == 200
    connector = Connector(port)
    replies = [connector.reply(message(n, ball)) for n, ball in enumerate(BALLS, 1)]
    replies += [http.post("/v1/gspro", json=json.loads(message(10 + n, ball))).json()
                for n, ball in enumerate(BALLS, 1)]
    connector.close()
    events = shot_events(http, len(replies))
    for reply, event in zip(replies, events, strict=True):
        assert reply["Code"] == 200 and event.shot_number == reply["ShotNumber"]
        answered, path = reply["Flight"], drawn(event)
        rest = np.array([answered["rest"]["x_m"], answered["rest"]["y_m"], -3.0])
        landing = np.array([answered["landing"]["x_m"], answered["landing"]["y_m"], -3.0])
        assert np.linalg.norm(path[-1] - rest) < 0.05, "the drawn path ends at the reply's rest"
        assert np.min(np.linalg.norm(path - landing, axis=1)) < 0.05, "the drawn path passes the reply's landing"
        assert event.ground.elevation_m == -3.0 and event.air.altitude_m == 1600.0


def test_with_the_putter_a_connectors_shot_rolls_on_the_bays_green(bay_service):
    http, port = bay_service
    green = {"ground": {"surface": "green", "stimp_ft": 11.0}, "player": {"club": "PT"}}
    assert http.patch("/v1/bay", json=green).status_code == 200
    connector = Connector(port)
    putts = {}
    for number, speed in ((1, PUTT_MPS), (2, 2 * PUTT_MPS)):
        ball = {"Speed": speed / 0.44704, "VLA": 2.0, "HLA": 0.0, "TotalSpin": 150.0, "SpinAxis": 0.0}
        putts[speed] = connector.reply(message(number, ball))["Flight"]
    connector.close()
    short, long = putts[PUTT_MPS], putts[2 * PUTT_MPS]
    assert 1.5 <= short["total_m"] <= 4.0 and 2.5 <= long["total_m"] / short["total_m"] <= 5.5
    assert short["carry_m"] == 0.0 and short["apex_m"] <= 0.05
    event = shot_events(http, 2)[0]
    assert event.putt and event.player.club == "PT" and drawn(event)[:, 2].max() <= 0.05


def test_a_club_change_reaches_every_connector_as_code_201_and_a_heartbeat_gets_nothing(bay_service):
    http, port = bay_service
    first, second = Connector(port), Connector(port)
    heartbeat = {"DeviceID": "x", "ShotNumber": 0, "ShotDataOptions": {"IsHeartBeat": True}}
    first.socket.sendall(json.dumps(heartbeat).encode())
    assert first.objects(0.5) == []
    started = time.monotonic()
    assert http.patch("/v1/bay", json={"player": {"club": "I7", "handed": "LH"}}).status_code == 200
    for connector in (first, second):
        (told,) = connector.objects(1.0)
        assert told == {"Code": 201, "Message": "GSPro Player Information", "Player": {"Handed": "LH", "Club": "I7"}}
        connector.close()
    assert time.monotonic() - started < 1.0
    assert http.get("/v1/bay").json()["player"] == {"club": "I7", "handed": "LH"}


def test_patch_changes_only_the_parts_it_names(bay_service):
    http, _ = bay_service
    assert http.put("/v1/bay", json=BAY).status_code == 200
    before = http.get("/v1/bay").json()
    assert http.patch("/v1/bay", json={"units": "metric"}).json() == {**before, "units": "metric"}
    assert http.patch("/v1/bay", json={"player": {"club": "SW"}}).json()["player"] == {"club": "SW", "handed": "RH"}
    calm = http.patch("/v1/bay", json={"wind": None}).json()
    assert "wind" not in calm and calm["air"] == before["air"] and calm["ground"] == before["ground"]
    refused = http.patch("/v1/bay", json={"player": {"club": "XX"}})
    assert refused.status_code == 422 and "player.club" in refused.text
    assert http.get("/v1/bay").json() == calm


def test_a_bay_file_broken_while_serving_keeps_the_last_good_bay_until_a_put_repairs_it(tmp_path):
    path, port = tmp_path / "bay.json", free_port()
    with running(create_app(ServiceSettings(connect_port=port, bay_file=path))) as http:
        assert http.put("/v1/bay", json=BAY).status_code == 200
        good = http.post("/v1/shots", json={"ball_speed_mps": 60.0, "launch_angle_deg": 14.0, "spin_rpm": 5000.0})
        for broken in (b"{not json", b"\xff\xfe binary", None):
            time.sleep(0.01)  # a new modification time
            path.unlink() if broken is None else path.write_bytes(broken)
            health = http.get("/healthz").json()
            assert health["status"] == "degraded" and health["problems"]["bay"].startswith(f"{path.name}: ")
            assert str(path.parent) not in health["problems"]["bay"], "no key is needed for /healthz: no directory"
            again = http.post("/v1/shots", json={"ball_speed_mps": 60.0, "launch_angle_deg": 14.0,
                                                 "spin_rpm": 5000.0})
            assert again.status_code == 200 and again.json() == good.json(), "the last good bay stays in force"
            own = http.post("/v1/shots", json={"ball_speed_mps": 60.0, "launch_angle_deg": 14.0, "spin_rpm": 5000.0,
                                               "air": {"temperature_c": 10.0}, "wind": {"speed_mps": 0.0},
                                               "ground": {"surface": "rough"}})
            assert own.status_code == 200
            assert http.post("/v1/gspro", json=json.loads(message(1, BALLS[1]))).status_code == 200
            assert http.get("/v1/bay").json()["air"] == BAY["air"]
            connector = Connector(port)
            assert connector.reply(message(2, BALLS[0]))["Code"] == 200
            connector.close()
        assert http.put("/v1/bay", json=BAY).status_code == 200
        assert http.get("/healthz").json()["status"] == "ready" and json.loads(path.read_text())["air"]


def test_the_sessions_shots_download_as_simulates_csv(bay_service):
    http, port = bay_service
    assert http.patch("/v1/bay", json={"player": {"club": "I7"}}).status_code == 200
    connector = Connector(port)
    connector.reply(message(1, BALLS[1]))
    connector.close()
    http.post("/v1/shots?viewer=true", json={"ball_speed_mph": 150.0, "launch_angle_deg": 12.0, "spin_rpm": 3000.0,
                                             "wind": {"speed_mph": 10.0, "from_deg": 90.0}})
    answer = http.get("/v1/session.csv")
    assert answer.status_code == 200 and answer.headers["content-type"].startswith("text/csv")
    rows = list(csv.DictReader(io.StringIO(answer.text)))
    assert [row["source"] for row in rows] == ["open-connect", "http"] and rows[0]["club"] == "I7"
    assert float(rows[1]["ball_speed_mps"]) == pytest.approx(150.0 * 0.44704)
    assert float(rows[1]["wind_speed_mph"]) == 10.0 and float(rows[1]["wind_from_deg"]) == 90.0
    assert float(rows[0]["carry_m"]) > 100 and rows[0]["rest_x_m"] and rows[0]["shot_id"] == "1"


@pytest.mark.parametrize("header", ["²".encode("latin-1"), b"1" * 5000, b"-3", b"12abc"])
def test_an_odd_last_event_id_starts_the_stream_from_the_kept_shots(bay_service, header):
    http, _ = bay_service
    with http.stream("GET", "/v1/events", headers={"last-event-id": header}) as stream:
        assert stream.status_code == 200


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16", "utf-16-le", "utf-32"])
def test_a_batch_body_in_any_json_encoding_is_flown_as_the_app_read_it(bay_service, encoding):
    http, _ = bay_service
    body = json.dumps({"shots": [{"ball_speed_mps": 60.0, "launch_angle_deg": 14.0, "spin_rpm": 5000.0}]})
    plain = http.post("/v1/shots/batch", content=body.encode(), headers={"content-type": "application/json"})
    encoded = body.encode(encoding)
    if encoding == "utf-16-le":
        assert not encoded.startswith(codecs.BOM_UTF16_LE)
    answer = http.post("/v1/shots/batch", content=encoded, headers={"content-type": "application/json"})
    assert answer.status_code == 200 and answer.json() == plain.json()


def test_a_refused_connector_message_names_its_shot_over_tcp_and_http(bay_service):
    http, port = bay_service
    bad = json.loads(message(42, {**BALLS[0], "Speed": 400.0}))
    connector = Connector(port)
    tcp = connector.reply(json.dumps(bad).encode())
    connector.close()
    over_http = http.post("/v1/gspro", json=bad).json()
    for reply in (tcp, over_http):
        assert reply["Code"] == 500 and reply["ShotNumber"] == 42 and "BallData.Speed" in reply["Message"]


def test_a_club_changed_in_the_bay_file_reaches_a_connector_at_once_apart_from_any_shot(tmp_path):
    """Issue 43: the 201 used to go out at the next shot, 3.5 ms ahead of its 200, and a connector that reads once
    per shot took it for its reply; now the file is watched and the 201 comes within 2 s, on its own."""
    path, port = tmp_path / "bay.json", free_port()
    with running(create_app(ServiceSettings(connect_port=port, bay_file=path))) as http:
        assert json.loads(path.read_text()) == {"player": {"club": "DR", "handed": "RH"}, "units": "imperial"}
        connector = Connector(port)
        assert connector.reply(message(1, BALLS[0]))["Code"] == 200
        write_text_atomic(path, json.dumps({"player": {"club": "I7", "handed": "RH"}}))
        started, told = time.monotonic(), []
        while not told and time.monotonic() - started < 2.0:
            told = connector.objects(0.1)
        assert told == [{"Code": 201, "Message": "GSPro Player Information", "Player": {"Handed": "RH", "Club": "I7"}}]
        connector.socket.sendall(message(2, BALLS[1]))
        replies = []
        while not replies:  # read once per shot: the first object is this shot's reply
            replies = connector.objects(5.0)
        assert [reply["Code"] for reply in replies] == [200] and replies[0]["ShotNumber"] == 2
        assert http.get("/v1/bay").json()["player"]["club"] == "I7"
        connector.close()


def test_the_servers_log_says_when_connectors_come_and_go_the_bay_file_breaks_and_heals_and_a_limit_refuses(tmp_path):
    """Issue 43: the log held only the start line after all of these."""
    http_port, tcp_port, bay, log = free_port(), free_port(), tmp_path / "bay.json", tmp_path / "serve.log"
    command = [sys.executable, "-m", "golfflight", "serve", "--port", str(http_port), "--connect-port", str(tcp_port),
               "--bay", str(bay)]
    env = {key: value for key, value in os.environ.items() if key != "GOLFFLIGHT_API_KEY"}
    with open(log, "w") as output:
        server = subprocess.Popen(command, stdout=output, stderr=subprocess.STDOUT, env=env)
    try:
        base = f"http://127.0.0.1:{http_port}"
        deadline = time.monotonic() + 90
        while not _ready(base):
            assert time.monotonic() < deadline and server.poll() is None, log.read_text()
            time.sleep(0.1)
        connector = Connector(tcp_port)
        assert connector.reply(message(1, BALLS[0]))["Code"] == 200
        connector.close()
        bay.write_text("{not json")
        time.sleep(1.0)  # the watch reads it
        assert httpx.put(f"{base}/v1/bay", json=BAY).status_code == 200
        flood = Connector(tcp_port)
        flood.socket.sendall(b'{"a":{}}' * 1000)  # past the burst of 100 messages: refused and closed
        time.sleep(1.0)
        flood.close()
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(60)
    text = log.read_text()
    for said in ("a connector connected from 127.0.0.1:", "a connector from 127.0.0.1:", "left (0 connected)",
                 "bay file: " + str(bay) + ": not bay conditions", "is bay conditions again",
                 "sent messages too fast: closed"):
        assert said in text, f"{said!r} not in the log:\n{text}"


def _ready(base: str) -> bool:
    try:
        return httpx.get(base + "/healthz", timeout=5).status_code == 200
    except httpx.TransportError:
        return False
