"""The simulator bay's conditions (contract.bay; the server's store: service.runtime.bay): a shot without its own flies
in the bay's air, wind and ground (over HTTP, in a batch and over GSPro Open Connect's TCP), a shot's own win,
PUT /v1/bay validates like a shot and is kept in the bay file across restarts, written whole or not at all."""

from __future__ import annotations

import json
import socket

import pytest
from golfflight.contract.bay import BayConditions, in_bay
from golfflight.contract.requests import AirRequest, GroundRequest, ShotRequest, WindRequest
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.runtime.bay import Bay, BayFileError

from tests.servers import free_port, running, shot

DENVER_HEAT = {"air": {"altitude_m": 1600.0, "temperature_c": 30.0},
               "wind": {"speed_mps": 4.4704, "from_deg": 0.0},
               "ground": {"surface": "green", "stimp_ft": 12.0}}
"""The issue's bay: 1,600 m, 30 degC, a 10 mph headwind, a stimp-12 green."""
SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
OPEN_CONNECT_SHOT = {"DeviceID": "bay test", "Units": "Yards", "ShotNumber": 1, "APIversion": "1",
                     "BallData": {"Speed": 123.0, "SpinAxis": 0.0, "TotalSpin": 7100.0, "HLA": 0.0, "VLA": 16.0},
                     "ShotDataOptions": {"ContainsBallData": True, "IsHeartBeat": False}}


def test_a_shot_takes_the_bays_conditions_only_where_it_has_none():
    bay = BayConditions.model_validate(DENVER_HEAT)
    bare = ShotRequest(**SEVEN_IRON)
    assert in_bay(bare, bay).air == bay.air and in_bay(bare, bay).ground == bay.ground
    own = ShotRequest(**SEVEN_IRON, air=AirRequest(temperature_c=10.0))
    filled = in_bay(own, bay)
    assert filled.air == AirRequest(altitude_m=1600.0, temperature_c=10.0) and filled.wind == bay.wind
    assert in_bay(bare, BayConditions()) is bare


def test_the_bay_file_is_kept_whole_and_read_back(tmp_path):
    path = tmp_path / "bay" / "bay.json"
    bay = Bay(path)
    assert bay.conditions == BayConditions() and Bay(path).conditions == BayConditions(), "created at once"
    conditions = BayConditions(wind=WindRequest(speed_mps=3.0, from_deg=90.0), units="metric")
    bay.set(conditions)
    assert Bay(path).conditions == conditions
    assert [p.name for p in path.parent.iterdir()] == ["bay.json"], "no temporary file left behind"


def test_another_workers_change_is_read_at_the_next_use(tmp_path):
    path = tmp_path / "bay.json"
    mine, other = Bay(path), Bay(path)
    other.set(BayConditions(ground=GroundRequest(surface="rough")))
    assert mine.conditions.ground == GroundRequest(surface="rough")


def test_a_bad_bay_file_names_itself_and_the_field(tmp_path):
    path = tmp_path / "bay.json"
    path.write_text(json.dumps({"air": {"altitude_m": 99999.0}}))
    with pytest.raises(BayFileError, match=r"bay.json: not bay conditions \(air.altitude_m"):
        Bay(path)


def _open_connect_carry(port: int) -> float:
    with socket.create_connection(("127.0.0.1", port), timeout=10) as connector:
        connector.sendall(json.dumps(OPEN_CONNECT_SHOT).encode())
        reply = json.loads(connector.recv(65536).decode())
    assert reply["Code"] == 200, reply
    return reply["Flight"]["carry_m"]


def sources(answer: dict) -> set[str]:
    """Where the answer says its air, wind and ground came from, taken out of it (the rest compares as numbers)."""
    return {answer["flown_in"].pop(f"{name}_from") for name in ("air", "wind", "ground")}


def test_http_batch_and_open_connect_shots_fly_in_the_bay_and_it_survives_a_restart(tmp_path):
    path, port = tmp_path / "bay.json", free_port()
    with running(create_app(ServiceSettings(connect_port=port, bay_file=path))) as http:
        calm = shot(http, **SEVEN_IRON)
        tcp_calm = _open_connect_carry(port)
        answer = http.put("/v1/bay", json=DENVER_HEAT)
        assert answer.status_code == 200, answer.text
        assert http.get("/v1/bay").json() == {**DENVER_HEAT, "units": "imperial",
                                               "player": {"club": "DR", "handed": "RH"},
                                               "wind": {**DENVER_HEAT["wind"], "profile": "uniform",
                                                        "reference_height_m": 10.0},
                                               "ground": {**DENVER_HEAT["ground"], "elevation_m": 0.0,
                                                          "slope_deg": 0.0, "slope_dir_deg": 0.0}}
        in_bay_shot = shot(http, **SEVEN_IRON)
        explicit = shot(http, **SEVEN_IRON, **DENVER_HEAT)
        assert sources(in_bay_shot) == {"bay"} and sources(explicit) == {"shot"}
        assert in_bay_shot == explicit and in_bay_shot["carry_m"] != calm["carry_m"]
        assert in_bay_shot["total_m"] - in_bay_shot["carry_m"] != calm["total_m"] - calm["carry_m"], "the green"
        own = shot(http, **SEVEN_IRON, air={}, wind={"speed_mps": 0.0}, ground={"surface": "fairway"})
        assert own.pop("flown_in")["air_from"] == "shot" and calm.pop("flown_in")["air_from"] == "default"
        assert own == calm, "a shot's own conditions win"
        batch = http.post("/v1/shots/batch", json={"shots": [SEVEN_IRON]}).json()["results"][0]
        assert batch["carry_m"] == pytest.approx(explicit["carry_m"], abs=1e-6)
        tcp = _open_connect_carry(port)
        assert tcp != tcp_calm
        assert tcp == pytest.approx(shot(http, ball_speed_mph=123.0, launch_angle_deg=16.0, spin_rpm=7100.0,
                                         **DENVER_HEAT)["carry_m"], abs=1e-6)
    with running(create_app(ServiceSettings(bay_file=path))) as http:
        restarted = shot(http, **SEVEN_IRON)
        assert sources(restarted) == {"bay"} and restarted == explicit, "the bay came back from its file"


def test_a_bad_bay_is_refused_like_a_bad_shot_and_changes_nothing(tmp_path):
    path = tmp_path / "bay.json"
    with running(create_app(ServiceSettings(bay_file=path))) as http:
        http.put("/v1/bay", json={"wind": {"speed_mps": 3.0}})
        answer = http.put("/v1/bay", json={"air": {"altitude_m": 99999.0}})
        assert answer.status_code == 422
        detail = answer.json()["detail"][0]
        assert detail["field"] == "air.altitude_m" and "allowed -500 to 5000 m" in detail["message"]
        assert http.get("/v1/bay").json()["wind"]["speed_mps"] == 3.0
        assert json.loads(path.read_text())["wind"]["speed_mps"] == 3.0


def test_the_bay_needs_the_api_key_when_one_is_set(tmp_path):
    with running(create_app(ServiceSettings(api_key="k", bay_file=tmp_path / "bay.json"))) as http:
        assert http.get("/v1/bay").status_code == 401
        assert http.put("/v1/bay", json={}).status_code == 401
        assert http.get("/v1/bay", headers={"x-api-key": "k"}).status_code == 200


def test_serve_refuses_a_bad_bay_file_in_one_line(tmp_path, capsys):
    from golfflight.cli import main

    path = tmp_path / "bay.json"
    path.write_text('{"wind": {"speed_mps": -3}}')
    assert main(["serve", "--bay", str(path), "--port", str(free_port())]) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("golfflight serve: error: ") and "bay.json: not bay conditions (wind.speed_mps" in error
    assert "\n" not in error


def test_a_scripted_connector_session_flies_every_shot_in_the_bay():
    """The issue's session: a connector connects and sends a heartbeat, the operator sets the bay (1,600 m, 30 degC,
    a 10 mph headwind, a stimp-12 green), then 20 shots of mixed clubs, two of them split across writes; every
    reply's carry equals POST /v1/shots with the same conditions to the centimetre."""
    import time

    clubs = [(167.0, 11.0, 2650.0), (150.0, 12.5, 4200.0), (123.0, 16.1, 7124.0), (104.0, 23.7, 9316.0)]
    port = free_port()
    with running(create_app(ServiceSettings(connect_port=port))) as http:
        with socket.create_connection(("127.0.0.1", port), timeout=10) as connector:
            heartbeat = {**OPEN_CONNECT_SHOT, "ShotNumber": 0,
                         "ShotDataOptions": {"ContainsBallData": False, "IsHeartBeat": True}}
            connector.sendall(json.dumps(heartbeat).encode())
            bay = {"air": {"altitude_m": 1600.0, "temperature_c": 30.0},
                   "wind": {"speed_mph": 10.0, "from_deg": 0.0}, "ground": {"surface": "green", "stimp_ft": 12.0}}
            assert http.put("/v1/bay", json=bay).status_code == 200
            buffer = b""
            for number in range(1, 21):
                speed, vla, spin = clubs[number % len(clubs)]
                ball = {"Speed": speed, "VLA": vla, "HLA": (number % 5 - 2) * 0.5, "TotalSpin": spin,
                        "SpinAxis": (number % 7 - 3) * 2.0}
                message = json.dumps({**OPEN_CONNECT_SHOT, "ShotNumber": number, "BallData": ball}).encode()
                if number in (7, 13):  # split across two writes
                    connector.sendall(message[:25])
                    time.sleep(0.05)
                    connector.sendall(message[25:])
                else:
                    connector.sendall(message)
                reply = None
                while reply is None:
                    buffer += connector.recv(65536)
                    try:
                        reply, end = json.JSONDecoder().raw_decode(buffer.decode())
                    except ValueError:
                        continue  # the reply is still arriving
                    buffer = buffer[len(buffer.decode()[:end].encode()):]
                assert reply["Code"] == 200 and reply["ShotNumber"] == number, reply
                explicit = shot(http, ball_speed_mph=speed, launch_angle_deg=vla, launch_direction_deg=ball["HLA"],
                                spin_rpm=spin, spin_axis_deg=ball["SpinAxis"], **bay)
                assert reply["Flight"]["carry_m"] == pytest.approx(explicit["carry_m"], abs=0.01)
                assert reply["Flight"]["total_m"] == pytest.approx(explicit["total_m"], abs=0.01)


def test_a_shots_own_air_replaces_the_bays_quantity_by_quantity():
    """Issue 43: a shot's `{"temperature_c": 20}` discarded the bay's altitude."""
    bay = BayConditions(air=AirRequest(altitude_m=1600.0, temperature_c=30.0, humidity_pct=40.0))
    shot = ShotRequest(ball_speed_mps=60.0, launch_angle_deg=14.0, spin_rpm=5000.0, air={"temperature_f": 68.0})
    assert in_bay(shot, bay).air == AirRequest(altitude_m=1600.0, temperature_f=68.0, humidity_pct=40.0)
    pressure = shot.model_copy(update={"air": AirRequest(pressure_hpa=900.0)})
    assert in_bay(pressure, bay).air == AirRequest(pressure_hpa=900.0, temperature_c=30.0, humidity_pct=40.0)
    dense = shot.model_copy(update={"air": AirRequest(density_kg_m3=1.0)})
    assert in_bay(dense, bay).air == AirRequest(density_kg_m3=1.0)
    thin_bay = BayConditions(air=AirRequest(density_kg_m3=1.0))
    assert in_bay(shot, thin_bay).air == AirRequest(temperature_f=68.0)


def test_a_connectors_shot_carries_its_flat_figures_and_unknown_units_are_refused():
    """Issue 43: Open Connect replies left out `flat`, and `Units` "furlongs" was taken without a word."""
    with running(create_app(ServiceSettings())) as http:
        assert http.put("/v1/bay", json={"ground": {"surface": "fairway", "elevation_m": -5.0}}).status_code == 200
        reply = http.post("/v1/gspro", json=OPEN_CONNECT_SHOT).json()
        assert reply["Code"] == 200 and reply["Flight"]["flat"]["carry_m"] < reply["Flight"]["carry_m"]
        assert len(json.dumps(reply, separators=(",", ":"))) < 2048, "inside MLM2PRO-GSPro-Connector's recv(2048)"
        refused = http.post("/v1/gspro", json={**OPEN_CONNECT_SHOT, "Units": "furlongs"}).json()
        assert refused["Code"] == 500 and "Units: must be Yards or Meters" in refused["Message"]
        assert http.post("/v1/gspro", json={**OPEN_CONNECT_SHOT, "Units": "Meters"}).json()["Code"] == 200
