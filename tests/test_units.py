"""Units a golfer uses, both ways, everywhere (issue 23, item 4): a wind in mph and a ground elevation in feet fly
exactly as the same in SI (HTTP, batch, the bay and its Open Connect shots), two forms of one quantity and an
out-of-range imperial value are refused naming their fields and the range in their own unit, and every length of a
result comes in metres and yards (the landing speed in m/s and mph) under the same names on HTTP, TCP, the flat
CSV columns and `golfflight fly`."""

from __future__ import annotations

import csv
import json
import socket

import pytest
from golfflight.contract.columns import result_columns
from golfflight.contract.results import FlatFlight, FlightResult, Landing, RestPoint
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings

from golfflight.cli import main
from tests.servers import flight_of, free_port, running, shot

SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0, "spin_axis_deg": 4.0}
TWINS = (("_m", "_yd", YARD_M), ("_mps", "_mph", MPH_TO_MPS))
NEW_FIELDS = ("lateral_yd", "roll_yd", "landing_speed_mph")


@pytest.fixture(scope="module")
def http():
    with running(create_app(ServiceSettings())) as client:
        yield client


def refused(http, **body) -> list[dict]:
    answer = http.post("/v1/shots", json=body)
    assert answer.status_code == 422, answer.text
    return answer.json()["detail"]


def imperial_twins(result: dict, where: str = "") -> int:
    """Assert that every SI length (NAME_m) and speed (NAME_mps) in `result` has its imperial twin (NAME_yd, NAME_mph)
    equal to it in that unit, nested objects included (the trajectory aside); the number of pairs checked."""
    pairs = 0
    for key, value in result.items():
        if key in ("trajectory", "conditions", "flown_in"):  # flown_in: the request's own objects, echoed
            continue
        if isinstance(value, dict):
            pairs += imperial_twins(value, f"{where}{key}.")
            continue
        for si, imperial, unit in TWINS:
            if key.endswith(si):
                twin = key.removesuffix(si) + imperial
                assert twin in result, f"{where}{key} has no {where}{twin}"
                assert result[twin] == pytest.approx(value / unit, rel=1e-12, abs=1e-12), f"{where}{twin}"
                pairs += 1
    return pairs


def test_every_si_length_and_speed_of_the_result_models_has_an_imperial_twin():
    for model in (FlightResult, FlatFlight, Landing, RestPoint):
        fields = model.model_fields
        for name in fields:
            for si, imperial, _ in TWINS:
                if name.endswith(si) and name != "reference_height_m":
                    assert name.removesuffix(si) + imperial in fields, (model.__name__, name)
    assert {"x_yd", "y_yd"} <= set(RestPoint.model_fields) and {"x_yd", "y_yd"} <= set(Landing.model_fields)


def test_a_wind_in_mph_flies_exactly_as_the_same_wind_in_mps(http):
    for wind in ({"from_deg": 0.0}, {"from_deg": 90.0, "profile": "log"}, {"from_deg": 200.0}):
        mph = shot(http, **SEVEN_IRON, wind={"speed_mph": 12.0, **wind})
        mps = shot(http, **SEVEN_IRON, wind={"speed_mps": 12.0 * MPH_TO_MPS, **wind})
        assert flight_of(mph) == flight_of(mps)
    calm = shot(http, **SEVEN_IRON)
    assert mph["carry_m"] != calm["carry_m"]
    assert flight_of(shot(http, **SEVEN_IRON, wind={"speed_mph": 0.0})) == flight_of(calm)
    batch = http.post("/v1/shots/batch", json={"shots": [{**SEVEN_IRON, "wind": {"speed_mph": 12.0, "from_deg": 200.0}},
                                                         {**SEVEN_IRON, "wind": {"speed_mps": 12.0 * MPH_TO_MPS,
                                                                                 "from_deg": 200.0}}]})
    first, second = batch.json()["results"]
    assert flight_of(first) == flight_of(second) and first["carry_m"] == pytest.approx(mph["carry_m"], abs=1e-6)


def test_a_ground_elevation_in_feet_flies_exactly_as_in_metres(http):
    for feet in (-20.0, 15.0):
        in_feet = shot(http, **SEVEN_IRON, ground={"elevation_ft": feet, "surface": "green"}, normalized=True)
        in_metres = shot(http, **SEVEN_IRON, ground={"elevation_m": feet * FOOT_M, "surface": "green"},
                         normalized=True)
        assert flight_of(in_feet) == flight_of(in_metres), "the same ground in feet or metres"
        assert "flat" in in_feet, "off the tee's elevation: the flat flight too"
    level = shot(http, **SEVEN_IRON, ground={"elevation_ft": 0.0})
    assert flight_of(level) == flight_of(shot(http, **SEVEN_IRON)) and "flat" not in level
    assert in_feet["carry_m"] != level["carry_m"]


@pytest.mark.parametrize(
    ("part", "both", "names"),
    [
        ("wind", {"speed_mps": 4.0, "speed_mph": 9.0}, ("speed_mps", "speed_mph")),
        ("ground", {"elevation_m": 3.0, "elevation_ft": 10.0}, ("elevation_m", "elevation_ft")),
        ("ground", {"elevation_m": 0.0, "elevation_ft": 10.0}, ("elevation_m", "elevation_ft")),
    ],
)
def test_both_forms_of_one_quantity_are_refused_naming_them(http, part, both, names):
    detail = refused(http, **SEVEN_IRON, **{part: both})
    assert len(detail) == 1 and detail[0]["field"] == part
    assert all(name in detail[0]["message"] for name in names), detail[0]["message"]


def test_a_wind_without_a_speed_is_refused_naming_both_forms(http):
    detail = refused(http, **SEVEN_IRON, wind={"from_deg": 90.0})
    assert "speed_mps or speed_mph (got none)" in detail[0]["message"]


@pytest.mark.parametrize(
    ("part", "field", "value", "allowed"),
    [
        ("wind", "speed_mph", 70.0, "0 to 67.1 mph"),
        ("wind", "speed_mph", -1.0, "0 to 67.1 mph"),
        ("wind", "speed_mps", 31.0, "0 to 30 m/s"),
        ("ground", "elevation_ft", 400.0, "-328 to 328 ft"),
        ("ground", "elevation_m", -101.0, "-100 to 100 m"),
    ],
)
def test_an_out_of_range_value_names_its_field_and_its_own_units_range(http, part, field, value, allowed):
    detail = refused(http, **SEVEN_IRON, **{part: {field: value}})
    assert detail[0]["field"] == f"{part}.{field}" and detail[0]["allowed"] == allowed
    assert detail[0]["message"].startswith(f"{part}.{field}: ") and detail[0]["message"].endswith(f"allowed {allowed}")


def test_the_imperial_limits_are_the_si_ones_converted(http):
    assert http.post("/v1/shots", json={**SEVEN_IRON, "wind": {"speed_mph": 67.1}}).status_code == 200
    assert http.post("/v1/shots", json={**SEVEN_IRON, "wind": {"speed_mph": 67.11}}).status_code == 422
    assert http.post("/v1/shots", json={**SEVEN_IRON, "ground": {"elevation_ft": -328.08}}).status_code == 200
    assert http.post("/v1/shots", json={**SEVEN_IRON, "ground": {"elevation_ft": -328.09}}).status_code == 422


def test_every_length_of_every_result_has_its_yards_twin(http):
    single = shot(http, **SEVEN_IRON, wind={"speed_mph": 10.0, "from_deg": 45.0}, normalized=True,
                  ground={"elevation_ft": -12.0, "surface": "rough"}, trajectory={"rate_hz": 30})
    assert imperial_twins(single) == 10 + 10 + 4  # the flight, its normalized replay, its flat flight
    assert set(NEW_FIELDS) <= set(single) and {"x_m", "y_m", "x_yd", "y_yd"} == set(single["rest"])
    assert set(single["landing"]) == {"x_m", "y_m", "x_yd", "y_yd"} and "lateral_yd" in single["flat"]
    assert single["lateral_yd"] == pytest.approx(single["lateral_m"] / 0.9144)
    assert single["rest"]["y_yd"] == pytest.approx(single["rest"]["y_m"] / 0.9144)
    batch = http.post("/v1/shots/batch", json={"shots": [SEVEN_IRON, {**SEVEN_IRON, "normalized": True}]}).json()
    for result in batch["results"]:
        assert imperial_twins(result) >= 10 and set(NEW_FIELDS) <= set(result)
    gspro = http.post("/v1/gspro", json={"ShotNumber": 3, "BallData": {"Speed": 123.0, "VLA": 16.0,
                                                                       "TotalSpin": 7100.0, "SpinAxis": 4.0}})
    flight = gspro.json()["Flight"]
    assert imperial_twins(flight) == 10 and set(flight) == set(batch["results"][0])


def test_the_bay_takes_and_echoes_mph_and_feet_and_its_shots_fly_in_them(tmp_path):
    port = free_port()
    bay = {"wind": {"speed_mph": 10.0, "from_deg": 0.0}, "ground": {"surface": "green", "stimp_ft": 12.0,
                                                                   "elevation_ft": -6.0}}
    with running(create_app(ServiceSettings(connect_port=port, bay_file=tmp_path / "bay.json"))) as http:
        assert http.put("/v1/bay", json=bay).status_code == 200
        echoed = http.get("/v1/bay").json()
        assert echoed["wind"]["speed_mph"] == 10.0 and "speed_mps" not in echoed["wind"]
        assert echoed["ground"]["elevation_ft"] == -6.0 and "elevation_m" not in echoed["ground"]
        assert json.loads((tmp_path / "bay.json").read_text())["wind"] == echoed["wind"]
        explicit = shot(http, **SEVEN_IRON, wind={"speed_mps": 10.0 * MPH_TO_MPS, "from_deg": 0.0},
                        ground={"surface": "green", "stimp_ft": 12.0, "elevation_m": -6.0 * FOOT_M})
        assert flight_of(shot(http, **SEVEN_IRON)) == flight_of(explicit)
        with socket.create_connection(("127.0.0.1", port), timeout=10) as connector:
            connector.sendall(json.dumps({"ShotNumber": 1, "BallData": {
                "Speed": 55.0 / MPH_TO_MPS, "VLA": 16.0, "TotalSpin": 7100.0, "SpinAxis": 4.0}}).encode())
            reply = json.loads(connector.recv(65536).decode())
    assert reply["Code"] == 200
    tcp = reply["Flight"]
    assert imperial_twins(tcp) == 14 and set(NEW_FIELDS) <= set(tcp)  # 4 in `flat`: the green lies 6 ft down
    assert tcp["carry_m"] == pytest.approx(explicit["carry_m"], abs=1e-6)
    assert tcp["roll_yd"] == pytest.approx(explicit["roll_yd"], abs=1e-6)


def test_the_csv_columns_carry_the_results_names(tmp_path):
    source, out = tmp_path / "launches.csv", tmp_path / "results.csv"
    rows = [
        {**SEVEN_IRON, "wind_speed_mph": 10.0, "wind_speed_mps": "", "ground_elevation_ft": -10.0,
         "ground_elevation_m": ""},
        {**SEVEN_IRON, "wind_speed_mph": "", "wind_speed_mps": 10.0 * MPH_TO_MPS, "ground_elevation_ft": "",
         "ground_elevation_m": -10.0 * FOOT_M},
    ]
    with open(source, "w", newline="") as handle:
        writer = csv.DictWriter(handle, rows[0].keys())
        writer.writeheader()
        writer.writerows(rows)
    assert main(["simulate", str(source), "--out", str(out)]) == 0
    with open(out) as handle:
        reader = csv.DictReader(handle)
        header, results = reader.fieldnames, list(reader)
    launch = ["ball_speed_mps", "launch_angle_deg", "spin_rpm", "spin_axis_deg"]
    results_named = (c for c in result_columns(normalized=False, flat=True) if c != "error")
    echoed = ["wind_speed_mps", "wind_speed_mph", "ground_elevation_m", "ground_elevation_ft"]  # as read (issue 43)
    assert header == ["row", *launch, *echoed, "air_density_kg_m3", *results_named]
    assert {"lateral_yd", "roll_yd", "landing_speed_mph", "rest_x_yd", "rest_y_yd", "landing_x_yd",
            "flat_lateral_yd"} <= set(header)
    assert results[0].pop("row") == "0" and results[1].pop("row") == "1"
    for result in results:  # the echoed inputs differ, as they were written; the flights are the same
        for name in echoed:
            result.pop(name)
    assert results[0] == results[1], "mph and feet cells fly as m/s and metre cells"
    numbers = {k: float(v) for k, v in results[0].items()}
    for name in header:
        if name.endswith("_m") and name not in echoed:
            assert numbers[name.removesuffix("_m") + "_yd"] == pytest.approx(numbers[name] / YARD_M), name


def test_a_bad_pair_of_cells_names_the_columns(tmp_path, capsys):
    source = tmp_path / "bad.csv"
    source.write_text("ball_speed_mps,launch_angle_deg,spin_rpm,wind_speed_mps,wind_speed_mph,ground_elevation_ft\n"
                      "55,16,7100,4,9,\n55,16,7100,,90,\n55,16,7100,,,500\n")
    assert main(["simulate", str(source)]) == 2
    error = capsys.readouterr().err
    assert "line 2 wind columns: wind speed: give exactly one of wind_speed_mps or wind_speed_mph" in error
    assert "line 3 column 'wind_speed_mph'" in error and "allowed 0 to 67.1 mph" in error
    assert "line 4 column 'ground_elevation_ft'" in error and "allowed -328 to 328 ft" in error


def test_a_sweep_with_feet_has_the_flat_columns_and_the_same_names(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "grid.parquet"
    assert main(["sweep", "--grid", "ball_speed_mps=55", "launch_angle_deg=16", "spin_rpm=7100",
                 "wind_speed_mph=0,10", "ground_elevation_ft=-10,0", "--out", str(out), "--workers", "1",
                 "--no-progress"]) == 0
    table = pq.read_table(out)
    assert [c for c in result_columns(normalized=False, flat=True)] == table.column_names[-len(result_columns(
        normalized=False, flat=True)):]
    rows = table.to_pylist()
    assert [r["flat_carry_m"] is None for r in rows] == [r["ground_elevation_ft"] == 0.0 for r in rows]
    for row in rows:
        assert row["roll_yd"] == pytest.approx(row["roll_m"] / YARD_M) and row["rest_y_yd"] > 0


def test_fly_prints_and_gives_the_results_names(http, capsys):
    assert main(["fly", "--club", "7i", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    flight = out["flight"]
    assert flight == flight_of(http.post("/v1/shots", json=out["request"]).json())
    assert set(NEW_FIELDS) <= set(flight) and imperial_twins(flight) == 10
    assert main(["fly", "--club", "7i", "--reference", "--json"]) == 0
    reference = json.loads(capsys.readouterr().out)["flight"]
    assert set(reference) == set(flight) and imperial_twins(reference) == 10
    assert main(["fly", "--club", "7i", "--launch-direction-deg", "3"]) == 0
    table = capsys.readouterr().out
    shifted = http.post("/v1/shots", json={**out["request"], "launch_direction_deg": 3.0}).json()
    assert f"{shifted['lateral_m']:8.1f} m {shifted['lateral_yd']:8.1f} yd" in table
    assert f"{shifted['roll_m']:8.1f} m {shifted['roll_yd']:8.1f} yd" in table
    assert f"{shifted['landing_speed_mph']:6.1f} mph" in table
