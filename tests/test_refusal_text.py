"""How a refusal quotes what was sent: text carrying a lone surrogate (JSON's escape \\ud800 reads as one, and no
UTF-8 text can hold it) is quoted with it escaped, so every refusal body encodes as UTF-8 instead of failing with a
500; long values and field names are cut, so a refusal never echoes a whole body."""

from __future__ import annotations

import json

import pytest
from golfflight.contract.refusals import QUOTED_CHARS, describe_errors
from golfflight.contract.requests import ShotRequest
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from pydantic import ValidationError

from tests.servers import running

SURROGATE_SHOT = '{"ball_speed_mph": "\\ud800", "launch_angle_deg": 10, "spin_rpm": 3000}'
"""A shot whose ball speed is text holding a lone surrogate (the JSON escape, as a client sends it)."""


def refusals(body: str) -> list[dict]:
    """`describe_errors` of the request model's refusal of a JSON body, read as FastAPI reads one (`json.loads`)."""
    with pytest.raises(ValidationError) as refused:
        ShotRequest.model_validate(json.loads(body))
    return describe_errors(refused.value.errors())


def utf8_body(details: list[dict]) -> bytes:
    """The 422 body as a JSON response writes it (Starlette: not ASCII-escaped, then UTF-8)."""
    return json.dumps({"detail": details}, ensure_ascii=False).encode("utf-8")


def test_a_lone_surrogate_in_a_value_is_quoted_escaped_and_the_body_encodes():
    (detail,) = refusals(SURROGATE_SHOT)
    assert detail["field"] == "ball_speed_mph" and detail["value"] == "\\ud800"
    assert detail["message"].startswith("ball_speed_mph: ") and "(got '\\ud800')" in detail["message"]
    assert json.loads(utf8_body([detail]))["detail"][0] == detail


def test_a_lone_surrogate_in_a_field_name_is_quoted_escaped_too():
    """pydantic refuses such a name at the object that holds it, quoting the name as the value sent."""
    for body, field in (('{"ball_speed_mps": 50, "launch_angle_deg": 10, "spin_rpm": 3000, "\\udfff": 1}', "body"),
                        ('{"ball_speed_mps": 50, "launch_angle_deg": 10, "spin_rpm": 3000, "air": {"\\udfff": 1}}',
                         "air")):
        (detail,) = refusals(body)
        assert detail["field"] == field and detail["value"] == "\\udfff" and "(got '\\udfff')" in detail["message"]
        utf8_body([detail])


def test_long_values_and_field_names_are_cut():
    megabyte = "x" * (1 << 20)
    (text,) = refusals(json.dumps({"ball_speed_mps": megabyte, "launch_angle_deg": 10, "spin_rpm": 3000}))
    assert text["value"] == "x" * (QUOTED_CHARS - 1) + "…" and len(text["message"]) < 200
    (number,) = refusals('{"ball_speed_mps": %s, "launch_angle_deg": 10, "spin_rpm": 3000}' % ("9" * 4000))
    assert number["value"] == "9" * (QUOTED_CHARS - 1) + "…" and len(number["message"]) < 200
    (name,) = refusals(json.dumps({"ball_speed_mps": 50, "launch_angle_deg": 10, "spin_rpm": 3000, megabyte: 1}))
    assert len(name["field"]) == QUOTED_CHARS and len(utf8_body([name])) < 1000
    (short,) = refusals(json.dumps({"ball_speed_mps": "x" * QUOTED_CHARS, "launch_angle_deg": 10, "spin_rpm": 3000}))
    assert short["value"] == "x" * QUOTED_CHARS, "a value of QUOTED_CHARS characters is quoted whole"


@pytest.fixture(scope="module")
def http():
    """A client of the real service on a loopback port."""
    with running(create_app(ServiceSettings())) as client:
        yield client


@pytest.mark.parametrize(
    ("method", "path", "body", "field"),
    [
        ("POST", "/v1/shots", SURROGATE_SHOT, "ball_speed_mph"),
        ("POST", "/v1/shots/batch", '{"shots": [%s]}' % SURROGATE_SHOT, "shots.0.ball_speed_mph"),
        ("PUT", "/v1/bay", '{"wind": {"speed_mph": "\\ud800"}}', "wind.speed_mph"),
        ("PUT", "/v1/bay", SURROGATE_SHOT, "ball_speed_mph"),
    ],
)
def test_a_lone_surrogate_is_answered_422_naming_the_field(http, method, path, body, field):
    answer = http.request(method, path, content=body.encode(), headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text
    details = answer.json()["detail"]
    named = [d for d in details if d["field"] == field]
    assert named and "'\\ud800'" in named[0]["message"] and named[0]["value"] == "\\ud800", details


def test_a_gspro_message_with_a_lone_surrogate_is_answered_in_its_own_form(http):
    body = '{"ShotNumber": 1, "BallData": {"Speed": "\\ud800", "VLA": 10, "TotalSpin": 3000}}'
    answer = http.post("/v1/gspro", content=body.encode(), headers={"content-type": "application/json"})
    assert answer.status_code == 422 and answer.json()["Code"] == 500
    assert "Speed" in answer.json()["Message"] and "\\ud800" in answer.json()["Message"]
