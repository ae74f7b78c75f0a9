"""The HTTP service through a real uvicorn server on 127.0.0.1 (one per module) with an httpx client."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from golfflight.contract.requests import MAX_BATCH_SHOTS
from golfflight.evaluation.accuracy_flyers import model_flyer
from golfflight.evaluation.accuracy_sets import compare_clubs
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.constants import MPH_TO_MPS, YARD_M
from golfflight.service.app import create_app
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.reference_world import TOUR_AVERAGES_FILE, read_tour_averages
from golfflight.weights_schema.bundle import load_bundle
from servers import running, shot

DRIVER_MPH = {"ball_speed_mph": 171.0, "launch_angle_deg": 10.4, "back_spin_rpm": 2545.0}
SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}


@pytest.fixture(scope="module")
def client():
    with running(create_app()) as http:
        yield http


def test_health_reports_the_loaded_model_and_the_card(client):
    card, _ = load_bundle(model_dir())
    health = client.get("/healthz").json()
    assert health["status"] == "ready"
    assert health["model"]["variant"] == card.variant and health["model"]["sha256"] == card.onnx.sha256
    assert str(model_dir()) not in client.get("/healthz").text  # no key needed: where the model lives is not shown
    assert client.get("/v1/model").json()["onnx"]["sha256"] == card.onnx.sha256
    assert client.get("/docs").status_code == 200 and "/v1/shots/batch" in client.get("/openapi.json").json()["paths"]


def test_single_shot_in_both_unit_forms(client):
    si = shot(client, ball_speed_mps=171.0 * MPH_TO_MPS, launch_angle_deg=10.4, spin_rpm=2545.0, spin_axis_deg=0.0)
    monitor = shot(client, **DRIVER_MPH)
    assert monitor["carry_m"] == pytest.approx(si["carry_m"], abs=1e-6)
    assert monitor["carry_yd"] == pytest.approx(monitor["carry_m"] / YARD_M)
    assert monitor["landing"]["y_m"] == pytest.approx(monitor["carry_m"])
    expected = {
        "landing",
        "carry_m",
        "carry_yd",
        "lateral_m",
        "lateral_yd",
        "apex_m",
        "apex_yd",
        "apex_time_s",
        "flight_time_s",
        "landing_angle_deg",
        "landing_speed_mps",
        "landing_speed_mph",
        "landing_spin_rpm",
        "total_m",
        "total_yd",
        "roll_m",
        "roll_yd",
        "rest",
        "bounces",
        "flown_in",
    }
    assert set(monitor) == expected
    faded = shot(client, **SEVEN_IRON | {"spin_rpm": None}, back_spin_rpm=7000.0, side_spin_rpm=800.0)
    assert faded["lateral_m"] > 1.0


def test_pga_tour_launches_answer_what_docs_accuracy_reports(client):
    """The tour averages' launches, posted as a launch monitor would (mph, no conditions), get the numbers the
    accuracy report flies for the served bundle in its card's air; SI and imperial input agree."""
    path = shared_data_dir() / TOUR_AVERAGES_FILE
    if not path.is_file():
        pytest.skip(f"no {path}")
    clubs = read_tour_averages(path)
    expected = compare_clubs(model_flyer(model_dir()), clubs).model
    for club, (carry_yd, apex_yd, land_deg) in zip(clubs, expected):
        launch = {"launch_angle_deg": club.launch_angle_deg}
        si = shot(client, **launch, ball_speed_mps=club.ball_speed_mps, spin_rpm=club.spin_rpm)
        mph = shot(client, **launch, ball_speed_mph=club.ball_speed_mph, back_spin_rpm=club.spin_rpm)
        assert mph["carry_yd"] == pytest.approx(si["carry_yd"], abs=1e-6), club.club
        assert (si["carry_yd"], si["apex_yd"], si["landing_angle_deg"]) == pytest.approx(
            (carry_yd, apex_yd, land_deg), abs=0.01), club.club


def test_batch_returns_the_single_shot_numbers_in_order(client):
    shots = [
        SEVEN_IRON,
        DRIVER_MPH,
        {**SEVEN_IRON, "wind": {"speed_mps": 4.0, "from_deg": 45.0}},
        {**DRIVER_MPH, "air": {"altitude_m": 1500.0}},
    ]
    batch = client.post("/v1/shots/batch", json={"shots": shots})
    assert batch.status_code == 200, batch.text
    results = batch.json()["results"]
    assert len(results) == len(shots)
    for body, result in zip(shots, results, strict=True):
        single = shot(client, **body)
        for key in ("carry_m", "apex_m", "flight_time_s", "lateral_m", "landing_spin_rpm"):
            assert result[key] == pytest.approx(single[key], abs=1e-6)


def test_batch_limit_is_enforced(client):
    response = client.post("/v1/shots/batch", json={"shots": [SEVEN_IRON] * (MAX_BATCH_SHOTS + 1)})
    assert response.status_code == 422 and "shots" in response.json()["detail"][0]["field"]


def test_headwind_shortens_and_wind_from_the_right_moves_the_ball_left(client):
    calm = shot(client, **SEVEN_IRON)
    headwind = shot(client, **SEVEN_IRON, wind={"speed_mps": 6.0, "from_deg": 0.0})
    tailwind = shot(client, **SEVEN_IRON, wind={"speed_mps": 6.0, "from_deg": 180.0})
    from_right = shot(client, **SEVEN_IRON, wind={"speed_mps": 6.0, "from_deg": 90.0, "profile": "log"})
    assert headwind["carry_m"] < calm["carry_m"] - 3 < tailwind["carry_m"] - 3
    assert from_right["lateral_m"] < -1.0


def test_altitude_lengthens_carry_and_density_can_be_given(client):
    sea_level = shot(client, **DRIVER_MPH, air={"temperature_c": 15.0, "altitude_m": 0.0})
    denver = shot(client, **DRIVER_MPH, air={"temperature_c": 15.0, "altitude_m": 1609.0})
    assert denver["carry_yd"] > sea_level["carry_yd"] + 8
    thin = shot(client, **DRIVER_MPH, air={"density_kg_m3": 1.0})
    assert thin["carry_m"] > sea_level["carry_m"]
    standard = shot(client, **DRIVER_MPH)
    assert standard["carry_m"] == pytest.approx(sea_level["carry_m"])  # omitted air = ICAO standard


def test_normalized_flight_replays_in_reference_air(client):
    body = {**DRIVER_MPH, "air": {"temperature_c": 30.0, "altitude_m": 1600.0}}  # thin air: a long drive
    result = shot(client, **body, normalized=True)
    normalized = result["normalized"]
    assert normalized["conditions"]["temperature_c"] == 25.0
    trackman_air = {"temperature_c": 25.0, "humidity_pct": 50.0}
    assert normalized["carry_m"] == pytest.approx(shot(client, **DRIVER_MPH, air=trackman_air)["carry_m"])
    assert normalized["carry_m"] < result["carry_m"] - 5
    custom = shot(client, **body, normalized={"temperature_c": 15.0, "humidity_pct": 0.0})["normalized"]
    assert custom["carry_m"] == pytest.approx(shot(client, **DRIVER_MPH)["carry_m"])


def test_trajectory_as_euler_states_or_resampled(client):
    states = shot(client, **SEVEN_IRON, trajectory={})
    points = states["trajectory"]
    assert points[0] == {"t_s": 0.0, "x_m": 0.0, "y_m": 0.0, "z_m": 0.01}
    assert points[1]["t_s"] == pytest.approx(0.1)
    landing = next(p for p in points if p["t_s"] == states["flight_time_s"])
    assert landing["z_m"] == pytest.approx(0.0, abs=1e-9) and landing["y_m"] == states["landing"]["y_m"]
    rest = points[-1]
    assert (rest["x_m"], rest["y_m"]) == pytest.approx((states["rest"]["x_m"], states["rest"]["y_m"]))
    assert rest["z_m"] == pytest.approx(0.0, abs=1e-9) and rest["t_s"] > states["flight_time_s"]
    resampled = shot(client, **SEVEN_IRON, trajectory={"rate_hz": 60})["trajectory"]
    assert len(resampled) == int(rest["t_s"] * 60) + 2 and resampled[-1] == pytest.approx(rest)
    assert resampled[6]["t_s"] == pytest.approx(0.1) and resampled[6]["y_m"] == pytest.approx(points[1]["y_m"])
    assert max(p["z_m"] for p in resampled) == pytest.approx(states["apex_m"], abs=0.2)


def test_invalid_requests_name_the_field_value_and_range(client):
    too_fast = client.post("/v1/shots", json={**SEVEN_IRON, "ball_speed_mps": 150.0})
    assert too_fast.status_code == 422
    detail = too_fast.json()["detail"][0]
    assert detail["field"] == "ball_speed_mps" and detail["value"] == 150.0 and detail["allowed"] == "0.5 to 100 m/s"
    both = client.post("/v1/shots", json={**SEVEN_IRON, "ball_speed_mph": 120.0})
    assert both.status_code == 422 and "exactly one of ball_speed_mps or ball_speed_mph" in both.text
    unknown = client.post("/v1/shots", json={**SEVEN_IRON, "club_speed_mph": 90.0})
    assert unknown.status_code == 422 and unknown.json()["detail"][0]["field"] == "club_speed_mph"
    nan = client.post(
        "/v1/shots",
        content=json.dumps({**SEVEN_IRON, "launch_angle_deg": float("nan")}),
        headers={"content-type": "application/json"},
    )
    assert nan.status_code == 422 and nan.json()["detail"][0]["field"] == "launch_angle_deg"


GSPRO_SHOT = {
    "DeviceID": "GSPro LM 1.1",
    "Units": "Yards",
    "ShotNumber": 13,
    "APIversion": "1",
    "BallData": {
        "Speed": 123.0,
        "SpinAxis": -4.0,
        "TotalSpin": 7124.0,
        "BackSpin": 7106.0,
        "SideSpin": -497.0,
        "HLA": 1.5,
        "VLA": 16.1,
        "CarryDistance": 176.0,
    },
    "ClubData": {
        "Speed": 92.0,
        "AngleOfAttack": -3.9,
        "FaceToTarget": 0.5,
        "Lie": 0.0,
        "Loft": 20.0,
        "Path": 1.0,
        "SpeedAtImpact": 92.0,
        "VerticalFaceImpact": 0.0,
        "HorizontalFaceImpact": 0.0,
        "ClosureRate": 0.0,
    },
    "ShotDataOptions": {
        "ContainsBallData": True,
        "ContainsClubData": True,
        "LaunchMonitorIsReady": True,
        "LaunchMonitorBallDetected": True,
        "IsHeartBeat": False,
    },
}


def test_a_body_without_a_json_content_type_is_refused_saying_so(client):
    """Issue 23: a body sent with no content type read as "Input should be a valid dictionary"."""
    shot_body, gspro_body = json.dumps(SEVEN_IRON).encode(), json.dumps(GSPRO_SHOT).encode()
    for headers, sent in (({}, "none was sent"), ({"content-type": "text/plain"}, "got 'text/plain'")):
        refused = client.post("/v1/shots", content=shot_body, headers=headers)
        assert refused.status_code == 415, refused.text
        detail = refused.json()["detail"][0]
        assert detail["field"] == "body" and "send content-type: application/json" in detail["message"]
        assert sent in detail["message"] and "valid dictionary" not in refused.text
        batch = client.post("/v1/shots/batch", content=json.dumps({"shots": [SEVEN_IRON]}), headers=headers)
        assert batch.status_code == 415 and "content-type: application/json" in batch.text
        gspro = client.post("/v1/gspro", content=gspro_body, headers=headers)
        assert gspro.status_code == 415 and gspro.json() == {
            "Code": 500,
            "Message": f"the body must be JSON: send content-type: application/json ({sent})",
        }
    assert client.post("/v1/shots", content=shot_body, headers={"content-type": "application/json"}).status_code == 200
    assert client.post("/v1/gspro", content=gspro_body, headers={"content-type": "application/json"}).json()["Code"] == 200


def test_gspro_open_connect_shot_heartbeat_and_error(client):
    reply = client.post("/v1/gspro", json=GSPRO_SHOT)
    assert reply.status_code == 200
    body = reply.json()
    assert body["Code"] == 200 and body["ShotNumber"] == 13
    same = shot(
        client,
        ball_speed_mph=123.0,
        launch_angle_deg=16.1,
        launch_direction_deg=1.5,
        spin_rpm=7124.0,
        spin_axis_deg=-4.0,
    )
    assert body["Flight"]["carry_m"] == pytest.approx(same["carry_m"], abs=1e-6)
    from_components = {**GSPRO_SHOT, "BallData": {**GSPRO_SHOT["BallData"], "TotalSpin": None}}
    assert (
        client.post("/v1/gspro", json=from_components).json()["Flight"]["lateral_m"] < body["Flight"]["lateral_m"] + 1
    )
    heartbeat = {**GSPRO_SHOT, "BallData": None, "ShotDataOptions": {"ContainsBallData": False, "IsHeartBeat": True}}
    beat = client.post("/v1/gspro", json=heartbeat)
    assert beat.status_code == 200 and beat.json() == {"Code": 200, "Message": "heartbeat received"}
    broken = client.post(
        "/v1/gspro", json={**GSPRO_SHOT, "BallData": {"Speed": 400.0, "VLA": 12.0, "TotalSpin": 3000.0}}
    )
    assert broken.status_code == 422 and broken.json()["Code"] == 500  # Open Connect's error code, HTTP's status
    assert "BallData.Speed" in broken.json()["Message"] and "1.119 to 223.6 mph" in broken.json()["Message"]
    missing = client.post("/v1/gspro", json={**GSPRO_SHOT, "BallData": {"Speed": 150.0}})
    assert missing.status_code == 422 and "VLA" in missing.json()["Message"]


def test_latency_reports_rolling_percentiles_and_a_probe(client):
    for _ in range(5):
        shot(client, **SEVEN_IRON)
    figures = client.get("/v1/latency").json()
    for kind in ("simulation", "request"):
        assert figures[kind]["count"] >= 5 and 0 < figures[kind]["p50_ms"] <= figures[kind]["p99_ms"]
    assert figures["request"]["p50_ms"] >= figures["simulation"]["p50_ms"]
    assert 0 < figures["probe"]["simulation_ms"] < 35


def test_the_service_imports_no_torch():
    code = (
        "import sys, golfflight.service.app, golfflight.flight.engine\n"
        "import golfflight.commands.serve, golfflight.commands.simulate\n"
        "golfflight.service.app.create_app()\n"
        "assert 'torch' not in sys.modules, 'torch imported on the serving path'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
