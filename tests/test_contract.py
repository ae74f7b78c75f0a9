"""The input contract over HTTP: every numeric field's range, NaN and infinity, types, unknown fields, batch and
body limits, each refusal a 422 (413 for the body) naming field, value and range; a shot that cannot land fails
alone."""

from __future__ import annotations

import json
import time
from concurrent.futures import ThreadPoolExecutor

import psutil
import pytest
from golfflight.contract.flying import fly_requests
from golfflight.contract.requests import MAX_BATCH_SHOTS, MAX_BATCH_TRAJECTORIES, RANGES, ShotRequest
from golfflight.flight import limits
from golfflight.service.api.guards import MAX_BODY_BYTES
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from servers import running

SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
MONITOR = {"ball_speed_mph": 120.0, "launch_angle_deg": 16.0, "back_spin_rpm": 7000.0}

FIELDS = {
    "ball_speed_mps": ((), SEVEN_IRON),
    "ball_speed_mph": ((), MONITOR),
    "launch_angle_deg": ((), SEVEN_IRON),
    "launch_direction_deg": ((), SEVEN_IRON),
    "spin_rpm": ((), SEVEN_IRON),
    "spin_axis_deg": ((), SEVEN_IRON),
    "back_spin_rpm": ((), MONITOR),
    "side_spin_rpm": ((), {**MONITOR, "back_spin_rpm": 0.0}),
    "temperature_c": (("air",), SEVEN_IRON),
    "temperature_f": (("air",), SEVEN_IRON),
    "altitude_m": (("air",), SEVEN_IRON),
    "altitude_ft": (("air",), SEVEN_IRON),
    "pressure_hpa": (("air",), SEVEN_IRON),
    "humidity_pct": (("air",), SEVEN_IRON),
    "density_kg_m3": (("air",), SEVEN_IRON),
    "speed_mps": (("wind",), SEVEN_IRON),
    "speed_mph": (("wind",), SEVEN_IRON),
    "from_deg": (("wind",), SEVEN_IRON),
    "reference_height_m": (("wind",), SEVEN_IRON),
    "rate_hz": (("trajectory",), SEVEN_IRON),
    "stimp_ft": (("ground",), SEVEN_IRON),
    "elevation_m": (("ground",), SEVEN_IRON),
    "elevation_ft": (("ground",), SEVEN_IRON),
    "slope_deg": (("ground",), SEVEN_IRON),
    "slope_dir_deg": (("ground",), SEVEN_IRON),
}
"""Every numeric request field: where it sits in the body and a valid shot to put it in."""

SECTION_BASE = {"wind": {"speed_mps": 3.0}, "speed_mph": {}, "stimp_ft": {"surface": "green"},
                "slope_deg": {"surface": "rough"}}
"""What a field's section needs besides it to be valid (by section or field name): a stimp reading is a green's,
slopes up to 10 degrees are held by the rough, not by the fairway, and a wind speed in mph is the wind's speed."""


@pytest.fixture(scope="module")
def app():
    return create_app(ServiceSettings())


@pytest.fixture(scope="module")
def http(app):
    with running(app) as client:
        yield client


def body_with(name: str, value) -> dict:
    path, base = FIELDS[name]
    body = json.loads(json.dumps(base))
    if path:
        body[path[0]] = dict(SECTION_BASE.get(name, SECTION_BASE.get(path[0], {})))
        body[path[0]][name] = value
    else:
        body[name] = value
    return body


def post_raw(http, path: str, text: str):
    return http.post(path, content=text, headers={"content-type": "application/json"})


def test_every_numeric_field_has_a_range_from_the_limits_table():
    assert set(FIELDS) == set(RANGES)
    assert RANGES["ball_speed_mps"] == limits.BALL_SPEED_MPS == (0.5, 100.0, "m/s")
    assert (RANGES["launch_angle_deg"].low, RANGES["launch_angle_deg"].high) == (-10.0, 80.0)
    assert RANGES["spin_rpm"].high == 15000.0 and RANGES["speed_mps"].high == 30.0
    assert (RANGES["altitude_m"].low, RANGES["altitude_m"].high) == (-500.0, 5000.0)
    assert (RANGES["temperature_c"].low, RANGES["temperature_c"].high) == (-30.0, 55.0)
    assert (RANGES["humidity_pct"].low, RANGES["humidity_pct"].high) == (0.0, 100.0)
    assert RANGES["rate_hz"].high == 1000.0


@pytest.mark.parametrize("name", sorted(FIELDS))
def test_each_field_refuses_values_past_either_end_naming_field_value_and_range(http, name):
    allowed = RANGES[name]
    for value in (allowed.low - 0.001 * max(1.0, abs(allowed.low)) - 1e-3, allowed.high * 1.001 + 1e-3):
        response = http.post("/v1/shots", json=body_with(name, value))
        assert response.status_code == 422, (name, value, response.text)
        detail = response.json()["detail"][0]
        assert detail["field"].endswith(name) and detail["value"] == value
        assert detail["allowed"] == allowed.describe()
        message = detail["message"]
        assert name in message and allowed.describe() in message and repr(value) in message
        assert detail["loc"][0] == "body" and detail["loc"][-1] == name and detail["type"] and detail["msg"]
    for value in (allowed.low, allowed.high):  # both ends are inside
        response = http.post("/v1/shots", json=body_with(name, value))
        assert response.status_code in (200, 422), response.text
        if response.status_code == 422:  # only a flight that cannot land, never the range
            assert response.json()["detail"][0]["type"] == "flight_error"


@pytest.mark.parametrize("text", ["NaN", "Infinity", "-Infinity", "1e999"])
def test_nan_and_infinities_are_refused(http, text):
    response = post_raw(http, "/v1/shots", '{"ball_speed_mps": 55, "launch_angle_deg": %s, "spin_rpm": 7100}' % text)
    assert response.status_code == 422
    detail = response.json()["detail"][0]
    assert detail["field"] == "launch_angle_deg" and "finite" in detail["msg"]
    assert detail["value"] in ("nan", "inf", "-inf")


def test_wrong_types_unknown_fields_and_two_forms_are_refused(http):
    text = http.post("/v1/shots", json={**SEVEN_IRON, "ball_speed_mps": "55"})
    assert text.status_code == 422 and text.json()["detail"][0]["field"] == "ball_speed_mps"
    flag = http.post("/v1/shots", json={**SEVEN_IRON, "normalized": 1})
    assert flag.status_code == 422
    nested = http.post("/v1/shots", json={**SEVEN_IRON, "air": {"temperature_c": 20, "dew_point_c": 10}})
    assert nested.status_code == 422 and nested.json()["detail"][0]["field"] == "air.dew_point_c"
    both = http.post("/v1/shots", json={**SEVEN_IRON, "back_spin_rpm": 3000})
    assert both.status_code == 422 and "exactly one of spin_rpm or back_spin_rpm" in both.text
    neither = http.post("/v1/shots", json={"launch_angle_deg": 12, "spin_rpm": 3000})
    assert neither.status_code == 422 and "ball_speed_mps or ball_speed_mph" in neither.text
    too_much_spin = http.post("/v1/shots", json={**MONITOR, "back_spin_rpm": 12000, "side_spin_rpm": 12000})
    assert too_much_spin.status_code == 422 and "(got 16971); allowed 0 to 15000 rpm" in too_much_spin.text
    density_and_weather = http.post("/v1/shots", json={**SEVEN_IRON, "air": {"density_kg_m3": 1.1, "altitude_m": 9}})
    assert density_and_weather.status_code == 422


@pytest.mark.parametrize("text", ["", "{", "[]", "17", '"shot"', "null", '{"shots": 5}'])
def test_bodies_that_are_not_a_shot_are_refused(http, text):
    assert post_raw(http, "/v1/shots", text).status_code == 422
    assert post_raw(http, "/v1/shots/batch", text).status_code == 422


def test_a_batch_refusal_names_the_shot_index(http):
    shots = [SEVEN_IRON] * 5
    shots[3] = {**SEVEN_IRON, "spin_rpm": 99999.0}
    response = http.post("/v1/shots/batch", json={"shots": shots})
    assert response.status_code == 422
    detail = response.json()["detail"][0]
    assert detail["shot"] == 3 and detail["field"] == "shots.3.spin_rpm" and detail["value"] == 99999.0
    assert detail["message"].startswith("shot 3: spin_rpm:") and "allowed 0 to 15000 rpm" in detail["message"]


def test_batch_size_and_trajectory_limits(http):
    assert http.post("/v1/shots/batch", json={"shots": []}).status_code == 422
    over = http.post("/v1/shots/batch", json={"shots": [SEVEN_IRON] * (MAX_BATCH_SHOTS + 1)})
    assert over.status_code == 422 and over.json()["detail"][0]["field"] == "shots"
    traced = [{**SEVEN_IRON, "trajectory": {}}] * (MAX_BATCH_TRAJECTORIES + 1)
    many = http.post("/v1/shots/batch", json={"shots": traced})
    assert many.status_code == 422 and f"at most {MAX_BATCH_TRAJECTORIES}" in many.text


def test_a_body_over_the_limit_is_refused_with_413_declared_or_streamed(http):
    big = b'{"shots": [' + b" " * (MAX_BODY_BYTES + 10) + b"]}"
    declared = http.post("/v1/shots/batch", content=big, headers={"content-type": "application/json"})
    assert declared.status_code == 413 and f"{MAX_BODY_BYTES:,}" in declared.json()["detail"][0]["message"]

    def chunks():
        for start in range(0, len(big), 1 << 20):
            yield big[start : start + (1 << 20)]

    streamed = http.post("/v1/shots/batch", content=chunks(), headers={"content-type": "application/json"})
    assert streamed.status_code == 413
    assert http.post("/v1/shots", json=SEVEN_IRON).status_code == 200  # the server is fine afterwards


def test_a_batch_process_that_dies_is_replaced(http):
    """Batches fly in a child process: killed under a batch, that batch gets a 503 saying to resend; killed
    between batches, the next batch is flown by a fresh child as if nothing happened."""
    batch = {"shots": [SEVEN_IRON] * 3}
    expected = http.post("/v1/shots/batch", json=batch).json()

    def batch_process() -> psutil.Process:
        children = [c for c in psutil.Process().children() if "spawn_main" in " ".join(c.cmdline())]
        assert len(children) == 1
        return children[0]

    def kill(child: psutil.Process) -> None:
        child.kill()
        child.wait(10)

    kill(batch_process())
    assert http.post("/v1/shots/batch", json=batch).json() == expected
    big = {"shots": [SEVEN_IRON] * 10_000}
    child = batch_process()
    idle = sum(child.cpu_times()[:2])
    with ThreadPoolExecutor(1) as pool:
        in_flight = pool.submit(http.post, "/v1/shots/batch", json=big)
        deadline = time.monotonic() + 30
        while sum(child.cpu_times()[:2]) < idle + 0.02 and time.monotonic() < deadline:
            time.sleep(0.002)  # killed once it is busy with the batch, however fast this machine flies it
        kill(child)
        died = in_flight.result()
    assert died.status_code == 503 and "send the batch again" in died.json()["detail"]
    assert http.post("/v1/shots/batch", json=batch).json() == expected


def test_a_shot_that_does_not_land_in_time_fails_alone(app, http):
    engine = app.state.runtime._engine  # the served engine itself: its step limit lowered for this test
    saved = engine.flyer.max_steps
    engine.flyer.max_steps = 12  # 1.2 s: a putt-like shot lands, a 7-iron is still up
    try:
        putt = {"ball_speed_mps": 3.0, "launch_angle_deg": 5.0, "spin_rpm": 100.0}
        single = http.post("/v1/shots", json=SEVEN_IRON)
        assert single.status_code == 422
        detail = single.json()["detail"][0]
        assert detail["type"] == "flight_error" and "still in the air after 1.2 s" in detail["message"]
        shots = [ShotRequest(**shot) for shot in (putt, SEVEN_IRON, putt)]  # batches fly in a child process:
        results, _ = fly_requests(engine, shots)  # the function the child runs
        batch = [result.model_dump(exclude_none=True) for result in results]
        assert "still in the air" in batch[1]["error"]
        assert batch[0]["carry_m"] > 0 and batch[2] == batch[0]
    finally:
        engine.flyer.max_steps = saved
