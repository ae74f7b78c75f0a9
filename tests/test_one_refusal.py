"""Issue 58, item 4: an input error carries its field, the value sent and the allowed range, and reads the same on
every surface (`golfflight.errors.refusal_text`, one formatter): a real uvicorn server's 422 body (POST /v1/shots,
/v1/shots/batch) and its GSPro route, a real TCP connector's Open Connect reply, and a real `golfflight fly`
process's error line."""

from __future__ import annotations

import json
import os
import pickle
import socket
import subprocess
import sys
import time

import pytest
from golfflight.contract.refusals import RequestRefused, input_detail
from golfflight.errors import InputError, refusal_text
from golfflight.service.api.errors import failure_response
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from tests.servers import free_port, running
from tests.test_imports import ROOT

BACK_SPIN_RPM, SIDE_SPIN_RPM = 12000.0, 12000.0
"""Each inside its own range (0 to 15,000 rpm), together 16,971 rpm: over the range of the spin they make."""
TOO_MUCH_SPIN = {"field": "spin_rpm", "value": 16971, "allowed": "0 to 15000 rpm"}
MESSAGE = "spin_rpm: back and side spin make a total over the range (got 16971); allowed 0 to 15000 rpm"
"""What every surface says of that spin, word for word."""

REQUEST = {"ball_speed_mph": 150.0, "launch_angle_deg": 12.0, "back_spin_rpm": BACK_SPIN_RPM,
           "side_spin_rpm": SIDE_SPIN_RPM}
GSPRO = {
    "DeviceID": "Refusal test", "Units": "Yards", "ShotNumber": 7, "APIversion": "1",
    "BallData": {"Speed": 150.0, "VLA": 12.0, "HLA": 0.0, "BackSpin": BACK_SPIN_RPM, "SideSpin": SIDE_SPIN_RPM},
    "ShotDataOptions": {"ContainsBallData": True, "LaunchMonitorIsReady": True, "IsHeartBeat": False},
}


@pytest.fixture(scope="module")
def service():
    """(HTTP client, Open Connect TCP port) of one real server listening on both."""
    port = free_port()
    with running(create_app(ServiceSettings(connect_port=port))) as http:
        yield http, port


def open_connect_reply(port: int, message: dict, timeout_s: float = 30.0) -> dict:
    """The reply a connector reads to `message` over a fresh TCP connection (player information, Code 201, skipped)."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout_s) as connection:
        connection.sendall(json.dumps(message).encode())
        text, deadline = "", time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            text += connection.recv(8192).decode()
            while text.strip():
                try:
                    reply, end = json.JSONDecoder().raw_decode(text.lstrip())
                except json.JSONDecodeError:
                    break
                text = text.lstrip()[end:]
                if reply.get("Code") != 201:
                    return reply
    raise AssertionError("no Open Connect reply")


def fly_process(*flags: str) -> subprocess.CompletedProcess:
    """A real `golfflight fly` process with these flags."""
    environment = {key: value for key, value in os.environ.items() if not key.startswith("GOLFFLIGHT_")}
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    return subprocess.run([sys.executable, "-m", "golfflight", "fly", *flags], capture_output=True, text=True,
                          env=environment, cwd=ROOT.parent, timeout=120)


def test_the_same_bad_spin_reads_the_same_over_http_open_connect_and_the_command_line(service):
    http, port = service
    refused = http.post("/v1/shots", json=REQUEST)
    assert refused.status_code == 422
    [detail] = refused.json()["detail"]
    assert {key: detail[key] for key in TOO_MUCH_SPIN} == TOO_MUCH_SPIN and detail["message"] == MESSAGE

    reply = open_connect_reply(port, GSPRO)
    assert (reply["Code"], reply["Message"], reply["ShotNumber"]) == (500, MESSAGE, 7)
    over_http = http.post("/v1/gspro", json=GSPRO)
    assert over_http.json()["Message"] == MESSAGE

    flown = fly_process("--back-spin-rpm", str(BACK_SPIN_RPM), "--side-spin-rpm", str(SIDE_SPIN_RPM))
    assert (flown.returncode, flown.stdout) == (2, "")
    assert flown.stderr == f"golfflight fly: error: {MESSAGE}\n"


def test_a_batchs_shot_names_its_index_and_the_same_parts(service):
    http, _ = service
    refused = http.post("/v1/shots/batch", json={"shots": [{**REQUEST, "back_spin_rpm": 3000.0}, REQUEST]})
    assert refused.status_code == 422
    [detail] = refused.json()["detail"]
    assert (detail["field"], detail["shot"], detail["value"], detail["allowed"]) == (
        "shots.1.spin_rpm", 1, 16971, "0 to 15000 rpm")
    assert detail["message"] == "shot 1: " + MESSAGE


def test_a_field_given_as_is_reads_the_same_value_and_range_on_each_surface(service):
    http, port = service
    [detail] = http.post("/v1/shots", json={**REQUEST, "back_spin_rpm": 20000.0, "side_spin_rpm": 0.0}).json()["detail"]
    over_tcp = open_connect_reply(port, {**GSPRO, "BallData": {**GSPRO["BallData"], "BackSpin": 20000.0}})
    flown = fly_process("--back-spin-rpm", "20000")
    said = "(got 20000.0); allowed 0 to 15000 rpm"
    assert (detail["field"], detail["value"], detail["allowed"]) == ("back_spin_rpm", 20000.0, "0 to 15000 rpm")
    assert detail["message"] == "back_spin_rpm: Input should be less than or equal to 15000 " + said
    assert over_tcp["Message"] == "BallData.BackSpin: Input should be less than or equal to 15000 " + said
    assert flown.stderr == ("golfflight fly: error: --back-spin-rpm: Input should be less than or equal to 15000 "
                            + said + "\n")


def test_an_input_error_keeps_its_parts_when_pickled_and_reads_as_the_formatter_writes():
    error = InputError("too steep", field="ground.slope_deg", value=40.0, allowed="0 to 30 deg")
    assert str(error) == refusal_text("ground.slope_deg", "too steep", 40.0, "0 to 30 deg")
    assert str(error) == "ground.slope_deg: too steep (got 40.0); allowed 0 to 30 deg"
    back = pickle.loads(pickle.dumps(error))  # the batch process sends its refusals back pickled
    assert (str(back), back.field, back.value, back.allowed, back.problem) == (
        str(error), "ground.slope_deg", 40.0, "0 to 30 deg", "too steep")
    assert str(InputError("a plain problem")) == "a plain problem" and InputError("x").field is None
    refused = pickle.loads(pickle.dumps(RequestRefused([input_detail(error, "value_error")])))
    assert refused.details[0]["loc"] == ["body", "ground", "slope_deg"] and str(refused) == str(error)


def test_a_field_carrying_error_raised_past_validation_keeps_its_parts_in_the_422():
    error = InputError("too steep", field="ground.slope_deg", value=40.0, allowed="0 to 30 deg")
    [detail] = json.loads(failure_response("/v1/shots", error).body)["detail"]
    assert detail == {"loc": ["body", "ground", "slope_deg"], "msg": "too steep", "type": "input_error",
                      "field": "ground.slope_deg", "value": 40.0, "allowed": "0 to 30 deg", "message": str(error)}
    assert json.loads(failure_response("/v1/gspro", error).body)["Message"] == str(error)
    assert json.loads(failure_response("/v1/shots", InputError("plain")).body)["detail"][0]["field"] == "body"
