"""The air in a golfer's units: `temperature_f` instead of `temperature_c` and `altitude_ft` instead of `altitude_m`
give the same engine air as their SI forms, each quantity in at most one form (refused naming both forms, in the
request, its JSON Schema and the CSV columns of `golfflight simulate`), and an out-of-range value is refused quoting
its range in its own unit, the SI limits converted."""

from __future__ import annotations

import csv

import jsonschema
import pytest
from golfflight.contract.columns import AIR_COLUMNS, check
from golfflight.contract.inputs import air_of
from golfflight.contract.refusals import describe_errors
from golfflight.contract.requests import ALTITUDE_FT, RANGES, TEMPERATURE_F, AirRequest, ShotRequest
from golfflight.flight import limits
from golfflight.flight.constants import FOOT_M
from pydantic import ValidationError

from golfflight.cli import main

SEVEN_IRON = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}


def refusal(air: dict) -> dict:
    """The one refusal of a shot with this air, as a 422 body and `simulate` word it."""
    with pytest.raises(ValidationError) as refused:
        ShotRequest.model_validate({**SEVEN_IRON, "air": air})
    details = describe_errors(refused.value.errors())
    assert len(details) == 1, details
    return details[0]


def test_86_fahrenheit_and_5249_feet_are_30_celsius_and_1600_metres():
    """By hand: (86 - 32) * 5/9 = 30 degC exactly; 5,249.3 ft * 0.3048 = 1,599.99 m. At 1,600 m the standard
    atmosphere gives 101,325 (1 - 2.25577e-5 * 1600)^5.255876 = 83,524 Pa, so dry air at 30 degC (303.15 K) is
    83,524 / (287.05 * 303.15) = 0.9598 kg/m^3."""
    imperial = air_of(AirRequest(temperature_f=86.0, altitude_ft=5249.3))
    assert imperial == air_of(AirRequest(temperature_c=30.0, altitude_m=5249.3 * FOOT_M))
    metric = air_of(AirRequest(temperature_c=30.0, altitude_m=1600.0))
    assert imperial.density_kg_m3 == pytest.approx(metric.density_kg_m3, rel=1e-5)
    assert imperial.kinematic_viscosity_m2_s == pytest.approx(metric.kinematic_viscosity_m2_s, rel=1e-5)
    assert metric.density_kg_m3 == pytest.approx(0.9598, abs=1e-4)


@pytest.mark.parametrize(
    ("imperial", "metric"),
    [
        ({"temperature_f": 86.0}, {"temperature_c": 30.0}),
        ({"temperature_f": 32.0, "humidity_pct": 50.0}, {"temperature_c": 0.0, "humidity_pct": 50.0}),
        ({"altitude_ft": 1000.0}, {"altitude_m": 304.8}),
        ({"temperature_f": -4.0, "pressure_hpa": 900.0}, {"temperature_c": -20.0, "pressure_hpa": 900.0}),
        ({"temperature_c": 25.0, "altitude_ft": -100.0}, {"temperature_c": 25.0, "altitude_m": -30.48}),
    ],
)
def test_each_imperial_form_alone_or_with_other_weather_is_its_si_form(imperial, metric):
    assert air_of(AirRequest(**imperial)) == air_of(AirRequest(**metric))
    assert air_of(AirRequest(**imperial)) != air_of(None)


@pytest.mark.parametrize(
    "both",
    [
        {"temperature_c": 30.0, "temperature_f": 86.0},
        {"altitude_m": 1600.0, "altitude_ft": 5249.3},
        {"altitude_m": 0.0, "altitude_ft": 0.0},
        {"altitude_ft": 5249.3, "pressure_hpa": 840.0},
        {"density_kg_m3": 1.1, "temperature_f": 86.0},
        {"density_kg_m3": 1.1, "altitude_ft": 5249.3},
    ],
)
def test_two_forms_or_sources_together_are_refused_naming_both_in_the_model_and_the_schema(both):
    detail = refusal(both)
    assert detail["field"] == "air" and all(name in detail["message"] for name in both), detail["message"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(both, AirRequest.model_json_schema())
    one = dict([next(iter(both.items()))])
    jsonschema.validate(one, AirRequest.model_json_schema())
    AirRequest.model_validate(one)


def test_the_imperial_ranges_are_the_si_limits_converted():
    assert RANGES["temperature_f"] == TEMPERATURE_F == (-22.0, 131.0, "degF")
    assert (TEMPERATURE_F.low - 32) * 5 / 9 == limits.TEMPERATURE_C.low
    assert (TEMPERATURE_F.high - 32) * 5 / 9 == limits.TEMPERATURE_C.high
    assert RANGES["altitude_ft"] == ALTITUDE_FT and ALTITUDE_FT.unit == "ft"
    assert ALTITUDE_FT.low * FOOT_M == pytest.approx(limits.ALTITUDE_M.low, abs=1e-9)
    assert ALTITUDE_FT.high * FOOT_M == pytest.approx(limits.ALTITUDE_M.high, abs=1e-9)
    assert ALTITUDE_FT.describe() == "-1640 to 16400 ft"


@pytest.mark.parametrize(
    ("field", "value", "allowed"),
    [
        ("temperature_f", 131.1, "-22 to 131 degF"),
        ("temperature_f", -22.1, "-22 to 131 degF"),
        ("altitude_ft", 16404.21, "-1640 to 16400 ft"),
        ("altitude_ft", -1640.43, "-1640 to 16400 ft"),
    ],
)
def test_an_out_of_range_value_is_refused_quoting_its_range_in_its_own_unit(field, value, allowed):
    detail = refusal({field: value})
    assert detail["field"] == f"air.{field}" and detail["value"] == value and detail["allowed"] == allowed
    assert detail["message"].startswith(f"air.{field}: ") and detail["message"].endswith(f"allowed {allowed}")


@pytest.mark.parametrize(("field", "value"), [("temperature_f", 131.0), ("temperature_f", -22.0),
                                              ("altitude_ft", 16404.19), ("altitude_ft", -1640.41)])
def test_the_ends_of_the_imperial_ranges_are_inside(field, value):
    AirRequest.model_validate({field: value})


def test_simulate_reads_fahrenheit_and_feet_columns(tmp_path):
    assert {"temperature_f", "altitude_ft"} <= set(AIR_COLUMNS)
    source, out = tmp_path / "launches.csv", tmp_path / "results.csv"
    rows = [
        {**SEVEN_IRON, "temperature_f": 86.0, "temperature_c": "", "altitude_ft": 1000.0, "altitude_m": ""},
        {**SEVEN_IRON, "temperature_f": "", "temperature_c": 30.0, "altitude_ft": "", "altitude_m": 304.8},
        {**SEVEN_IRON, "temperature_f": "", "temperature_c": "", "altitude_ft": "", "altitude_m": ""},
    ]
    with open(source, "w", newline="") as handle:
        writer = csv.DictWriter(handle, rows[0].keys())
        writer.writeheader()
        writer.writerows(rows)
    assert main(["simulate", str(source), "--out", str(out)]) == 0
    with open(out) as handle:
        imperial, metric, standard = csv.DictReader(handle)
    assert [imperial.pop("row"), metric.pop("row")] == ["0", "1"]
    given = ("temperature_f", "altitude_ft", "temperature_c", "altitude_m")  # echoed as given, in front
    assert [imperial.pop(c) for c in given] == ["86.0", "1000.0", "", ""]
    assert [metric.pop(c) for c in given] == ["", "", "30.0", "304.8"]
    assert imperial == metric and imperial["carry_m"] != standard["carry_m"]


def test_a_row_with_both_forms_names_the_columns():
    problems = check({**SEVEN_IRON, "air": {"temperature_c": 30.0, "temperature_f": 86.0}})
    assert problems == ["air columns: air temperature: give temperature_c or temperature_f, not both"]
    (problem,) = check({**SEVEN_IRON, "air": {"altitude_ft": 20000.0}})
    assert problem.startswith("column 'altitude_ft': ")
    assert problem.endswith("(got 20000.0); allowed -1640 to 16400 ft")
