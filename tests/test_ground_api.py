"""The ground phase through the service's contract: `ground` in single, batch and normalized shots, its 422s, the
trajectory to rest, GSPro replies (HTTP and the TCP server's `fly_message`) and `golfflight simulate`; and in the
engine, every valid shot comes to rest, one shot's float path agreeing with the batch (hypothesis)."""

from __future__ import annotations

import csv
import json
import math

import pytest
from golfflight.contract.gspro import GSProMessage, fly_message
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.constants import YARD_M
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.ground import SURFACES, GroundSpec, holding_slope_deg
from golfflight.flight.limits import SLOPE_DEG
from golfflight.flight.problem import FlightProblem
from golfflight.service.app import create_app
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from servers import flight_of, running, shot

from golfflight.cli import main

DRIVER = {"ball_speed_mph": 171.0, "launch_angle_deg": 10.4, "back_spin_rpm": 2545.0}
WEDGE = {"ball_speed_mps": 40.0, "launch_angle_deg": 30.0, "spin_rpm": 10000.0}


@pytest.fixture(scope="module")
def client():
    with running(create_app()) as http:
        yield http


def test_every_shot_rolls_to_rest_on_a_level_fairway_unless_told(client):
    driver = shot(client, **DRIVER)
    assert driver["total_m"] > driver["carry_m"] and driver["total_yd"] == pytest.approx(driver["total_m"] / YARD_M)
    assert driver["roll_m"] == pytest.approx(driver["total_m"] - driver["carry_m"])
    assert driver["rest"]["y_m"] == pytest.approx(driver["total_m"]) and driver["bounces"] >= 0
    assert flight_of(shot(client, **DRIVER, ground={})) == flight_of(driver)


def test_the_carry_is_at_the_ground_elevation(client):
    flat = shot(client, **DRIVER)
    below = shot(client, **DRIVER, ground={"elevation_m": -10.0})
    above = shot(client, **DRIVER, ground={"elevation_m": 10.0})
    assert above["carry_m"] < flat["carry_m"] < below["carry_m"]
    assert above["flight_time_s"] < flat["flight_time_s"] < below["flight_time_s"]
    assert "flat" not in flat and below["flat"]["carry_m"] == pytest.approx(flat["carry_m"])
    assert above["flat"]["flight_time_s"] == pytest.approx(flat["flight_time_s"])
    assert above["flat"]["carry_yd"] == pytest.approx(flat["carry_yd"])
    too_high = client.post("/v1/shots", json={**DRIVER, "ground": {"elevation_m": 90.0}})
    assert too_high.status_code == 422 and "never rose to its landing ground" in too_high.json()["detail"][0]["message"]


def test_a_fast_green_and_heavy_spin_bring_a_steep_wedge_back_a_few_yards(client):
    """Into an 8 m/s headwind the wedge drops at 75 degrees: on a stimp-13 green its back spin pulls it back, a few
    yards and no more (docs/ground.md), and the rough holds it closer."""
    headwind = {"speed_mps": 8.0, "from_deg": 0.0, "profile": "log"}
    wedge = shot(client, **WEDGE, wind=headwind, ground={"surface": "green", "stimp_ft": 13.0})
    assert -5.0 * YARD_M < wedge["roll_m"] < 0.0 and wedge["total_m"] < wedge["carry_m"]
    soft = shot(client, **WEDGE, wind=headwind, ground={"surface": "rough"})
    assert abs(soft["roll_m"]) < abs(wedge["roll_m"])


def test_slopes_move_the_rest(client):
    level = shot(client, **DRIVER)
    uphill = shot(client, **DRIVER, ground={"slope_deg": 3.0, "slope_dir_deg": 180.0})
    downhill = shot(client, **DRIVER, ground={"slope_deg": 3.0, "slope_dir_deg": 0.0})
    right = shot(client, **DRIVER, ground={"slope_deg": 3.0, "slope_dir_deg": 90.0})
    assert uphill["total_m"] < level["total_m"] < downhill["total_m"] and right["rest"]["x_m"] > 0.1


@pytest.mark.parametrize(
    ("ground", "words"),
    [
        ({"surface": "green", "slope_deg": 8.0}, ["slope_deg", "allowed 0 to 4.47 deg"]),
        ({"surface": "fairway", "stimp_ft": 10.0}, ["stimp_ft", "a green's reading"]),
        ({"surface": "carpet"}, ["ground.surface", "fairway"]),
        ({"stimp_ft": 30.0, "surface": "green"}, ["ground.stimp_ft", "4 to 16 ft"]),
        ({"slope_dir_deg": -1.0}, ["ground.slope_dir_deg", "0 to 360 deg"]),
    ],
)
def test_a_bad_ground_is_a_422_naming_the_field(client, ground, words):
    response = client.post("/v1/shots", json={**DRIVER, "ground": ground})
    assert response.status_code == 422, response.text
    message = response.json()["detail"][0]["message"]
    assert all(word in message for word in words), message


def test_the_trajectory_runs_on_through_the_bounces_to_rest(client):
    result = shot(client, **WEDGE, ground={"surface": "green"}, trajectory={"rate_hz": 30})
    points = result["trajectory"]
    assert points[-1]["y_m"] == pytest.approx(result["rest"]["y_m"]) and points[-1]["z_m"] == pytest.approx(0.0)
    after = [p for p in points if p["t_s"] > result["flight_time_s"]]
    assert after and all(p["z_m"] >= -1e-9 for p in after)
    assert result["bounces"] >= 1 and max(p["z_m"] for p in after) > 0.01


def test_batch_and_normalized_carry_the_ground_phase(client):
    shots = [
        {**DRIVER, "normalized": True},
        {**WEDGE, "ground": {"surface": "green", "stimp_ft": 12.0}},
        {**DRIVER, "ground": {"elevation_m": -5.0, "slope_deg": 2.0, "slope_dir_deg": 45.0}, "normalized": True},
    ]
    results = client.post("/v1/shots/batch", json={"shots": shots}).json()["results"]
    for body, result in zip(shots, results, strict=True):
        single = shot(client, **body)
        assert result["total_m"] == pytest.approx(single["total_m"], abs=1e-6)
        assert result["bounces"] == single["bounces"]
        assert result.get("flat", {}).get("carry_m") == pytest.approx(single.get("flat", {}).get("carry_m"))
        assert result.get("normalized", {}).get("total_m") == pytest.approx(single.get("normalized", {}).get("total_m"))
    assert results[0]["normalized"]["total_m"] > results[0]["normalized"]["carry_m"]


def test_gspro_replies_carry_the_total(client):
    message = {"ShotNumber": 3, "APIversion": "1", "BallData": {"Speed": 167.0, "VLA": 11.0, "TotalSpin": 2650.0}}
    reply = client.post("/v1/gspro", json=message).json()
    assert reply["Code"] == 200 and reply["Flight"]["total_yd"] > reply["Flight"]["carry_yd"]
    tcp = fly_message(FlightEngine(model_dir()), GSProMessage.model_validate(message))
    assert tcp.Flight.total_m == pytest.approx(reply["Flight"]["total_m"])


def test_simulate_takes_ground_columns_and_writes_the_rest(tmp_path):
    source, out = tmp_path / "launches.csv", tmp_path / "results.csv"
    with open(source, "w", newline="") as handle:
        columns = ["ball_speed_mps", "launch_angle_deg", "spin_rpm", "ground_surface", "stimp_ft", "ground_elevation_m"]
        writer = csv.DictWriter(handle, columns)
        writer.writeheader()
        writer.writerow({"ball_speed_mps": 40, "launch_angle_deg": 30, "spin_rpm": 10000, "ground_surface": "green",
                         "stimp_ft": 12})
        writer.writerow({"ball_speed_mps": 40, "launch_angle_deg": 30, "spin_rpm": 10000, "ground_surface": "rough",
                         "ground_elevation_m": -3})
    assert main(["simulate", str(source), "--out", str(out)]) == 0
    with open(out) as handle:
        rows = list(csv.DictReader(handle))
    assert {"total_m", "roll_m", "rest_x_m", "rest_y_m", "bounces", "flat_carry_m"} <= set(rows[0])
    assert abs(float(rows[1]["roll_m"])) < abs(float(rows[0]["roll_m"])) and rows[0]["flat_carry_m"] == ""
    assert float(rows[1]["flat_carry_m"]) < float(rows[1]["carry_m"])
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps([{**WEDGE, "ground": {"surface": "green", "slope_deg": 9.0}}]))
    assert main(["simulate", str(bad)]) == 2



@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    launch=st.tuples(st.floats(5.0, 90.0), st.floats(-5.0, 60.0), st.floats(-20.0, 20.0), st.floats(0.0, 12000.0),
                     st.floats(-60.0, 60.0)),
    name=st.sampled_from(list(SURFACES)),
    slope_share=st.floats(0.0, 0.95),
    slope_dir=st.floats(0.0, 360.0),
    elevation=st.floats(-20.0, 0.0),
)
def test_every_shot_comes_to_rest_finite_and_the_batch_agrees(engine, launch, name, slope_share, slope_dir,
                                                                elevation):
    where = SURFACES[name]
    steepest = min(float(holding_slope_deg(where.rolling_resistance)), SLOPE_DEG.high)
    ground = GroundSpec(where, elevation, slope_share * steepest, slope_dir)
    one = engine.fly(FlightProblem.of([Launch(*launch)], grounds=ground))[0]
    batch = engine.fly_batch(FlightProblem.of([Launch(*launch)] * 2, grounds=ground)).shots()[1]
    rest = one.rest
    assert all(math.isfinite(v) for v in (rest.x_m, rest.y_m, rest.total_m, rest.roll_m, rest.ground_time_s))
    assert rest.bounces >= 0 and rest.ground_time_s >= 0.0
    assert (rest.x_m, rest.y_m) == pytest.approx((batch.rest.x_m, batch.rest.y_m), rel=1e-9, abs=1e-6)
    assert rest.bounces == batch.rest.bounces
