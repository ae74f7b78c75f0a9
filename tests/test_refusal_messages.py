"""Refusals say what to fix (issue 31): a body that is not valid JSON is refused saying where (line and column) and
what was expected, not as the field "22"; a limit is printed with at most four significant digits, rounded inwards,
in every refusal (HTTP 422s, GSPro's Code 500, `fly`, `simulate`, `sweep`) and field description, by one formatter
(`flight.limits.limit_text`), never as a float's 17 digits (223.69362920544023)."""

from __future__ import annotations

import pytest
from golfflight.contract.gspro import GSPRO_RANGES
from golfflight.contract.requests import RANGES
from golfflight.flight import limits
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings

from golfflight.cli import main
from tests.servers import running

JSON = {"content-type": "application/json"}
SPEED_REFUSAL = "Input should be less than or equal to 223.6 (got 600.0); allowed 1.119 to 223.6 mph"
"""The refusal of a ball speed of 600 mph, sent as the number 600.0."""


@pytest.fixture(scope="module")
def http():
    """A client of the real service on a loopback port."""
    with running(create_app(ServiceSettings())) as client:
        yield client


def significant_digits(number: str) -> int:
    """How many significant digits a printed number has (a whole number's trailing zeros not counted)."""
    return len(number.lstrip("-").replace(".", "").strip("0"))


@pytest.mark.parametrize(
    ("value", "high", "text"),
    [
        (223.69362920544023, True, "223.6"),
        (1.1184681460272012, False, "1.119"),
        (67.10808876163208, True, "67.1"),
        (16404.199475065616, True, "16400"),
        (-1640.4199475065616, False, "-1640"),
        (-328.0839895013123, False, "-328"),
        (100.0, True, "100"),
        (15000.0, True, "15000"),
        (0.5, False, "0.5"),
        (0.0, False, "0"),
        (-22.0, False, "-22"),
    ],
)
def test_a_limit_has_at_most_four_significant_digits_rounded_inwards(value, high, text):
    assert limits.limit_text(value, high) == text


@pytest.mark.parametrize("name", sorted({**RANGES, **GSPRO_RANGES}))
def test_every_range_described_holds_only_values_it_accepts(name):
    bounds = {**RANGES, **GSPRO_RANGES}[name]
    low, high = bounds.describe().removesuffix(bounds.unit).strip().split(" to ")
    assert bounds.low <= float(low) <= float(high) <= bounds.high
    assert significant_digits(low) <= 4 and significant_digits(high) <= 4


@pytest.mark.parametrize("path", ["/v1/shots", "/v1/shots/batch", "/v1/gspro"])
def test_a_body_that_is_not_json_is_refused_saying_where_and_what_was_expected(http, path):
    answer = http.post(path, content=b'{"ball_speed_mps": 60 "launch_angle_deg": 12}', headers=JSON)
    assert answer.status_code == 422, answer.text
    expected = "the body is not valid JSON: Expecting ',' delimiter at line 1 column 23"
    if path == "/v1/gspro":
        assert answer.json() == {"Code": 500, "Message": expected}
        return
    (detail,) = answer.json()["detail"]
    assert detail["message"] == expected and detail["field"] == "body" and detail["type"] == "json_invalid"


def test_the_line_of_a_json_error_in_a_body_of_many_lines_is_named(http):
    body = b'{\n  "ball_speed_mps": 60,\n  "launch_angle_deg": 12\n  "spin_rpm": 3000\n}'
    (detail,) = http.post("/v1/shots", content=body, headers=JSON).json()["detail"]
    assert detail["message"] == "the body is not valid JSON: Expecting ',' delimiter at line 4 column 3"


def test_a_body_cut_short_is_said_to_end_there(http):
    (detail,) = http.post("/v1/shots", content=b'{"ball_speed_mps": 60,', headers=JSON).json()["detail"]
    assert detail["message"] == (
        "the body is not valid JSON: Expecting property name enclosed in double quotes at the end of the body "
        "(line 1 column 23)"
    )


def test_an_http_refusal_prints_a_converted_limit_with_four_digits(http):
    answer = http.post("/v1/shots", json={"ball_speed_mph": 600.0, "launch_angle_deg": 12, "spin_rpm": 3000})
    (detail,) = answer.json()["detail"]
    assert detail["message"] == f"ball_speed_mph: {SPEED_REFUSAL}"
    assert detail["msg"] == "Input should be less than or equal to 223.6" and detail["allowed"] == "1.119 to 223.6 mph"
    answer = http.post(
        "/v1/shots",
        json={
            "ball_speed_mps": 60,
            "launch_angle_deg": 12,
            "spin_rpm": 3000,
            "wind": {"speed_mph": 300.0},
            "ground": {"elevation_ft": -3000.0},
            "air": {"altitude_ft": 1e6},
        },
    )
    messages = [d["message"] for d in answer.json()["detail"]]
    assert messages == [
        "wind.speed_mph: Input should be less than or equal to 67.1 (got 300.0); allowed 0 to 67.1 mph",
        "air.altitude_ft: Input should be less than or equal to 16400 (got 1000000.0); allowed -1640 to 16400 ft",
        "ground.elevation_ft: Input should be greater than or equal to -328 (got -3000.0); allowed -328 to 328 ft",
    ]


def test_a_gspro_refusal_prints_a_converted_limit_with_four_digits(http):
    answer = http.post("/v1/gspro", json={"ShotNumber": 1, "BallData": {"Speed": 600.0, "VLA": 11, "TotalSpin": 2650}})
    assert answer.json() == {"Code": 500, "Message": f"BallData.Speed: {SPEED_REFUSAL}", "ShotNumber": 1}


@pytest.mark.parametrize("command", ["fly", "simulate", "sweep"])
def test_the_commands_print_a_converted_limit_with_four_digits(command, tmp_path, capsys):
    source = tmp_path / "launches.csv"
    source.write_text("ball_speed_mph,launch_angle_deg,spin_rpm\n600,12,3000\n")
    if command == "sweep":
        pytest.importorskip("pyarrow")
    argv = {
        "fly": ["fly", "--ball-speed-mph", "600", "--launch-angle-deg", "12", "--spin-rpm", "3000"],
        "simulate": ["simulate", str(source)],
        "sweep": ["sweep", str(source), "--out", str(tmp_path / "out.parquet"), "--workers", "1", "--no-progress"],
    }[command]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert SPEED_REFUSAL in err and "223.69" not in err, err
