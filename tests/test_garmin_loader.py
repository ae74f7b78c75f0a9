"""Garmin Golf app export loader: units to SI against hand-worked numbers, the carry's geometry, spin signs, skipped
and malformed rows, the recorded air (and --no-air), and `golfflight convert garmin` read by `golfflight simulate`.
Every export is a small CSV written here, in the app's columns."""

from __future__ import annotations

import csv
import math

import pytest
from golfflight.cli import main
from golfflight.flight.air import air_density
from golfflight.flight.conditions import STANDARD
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.shots.garmin import load_garmin
from golfflight.shots.records import RecordError, read_shots

COLUMNS = (
    "Date", "Club Type", "Club Speed (mph)", "Attack Angle (deg)", "Club Path (deg)", "Club Face (deg)",
    "Face to Path (deg)", "Ball Speed (mph)", "Smash Factor", "Launch Angle (deg)", "Launch Direction (deg)",
    "Backspin (rpm)", "Sidespin (rpm)", "Spin Rate (rpm)", "Spin Rate Type", "Spin Axis (deg)", "Apex Height (ft)",
    "Total Distance (yards)", "Total Deviation Angle (deg)", "Total Deviation Distance (yards)", "Air Density (g/L)",
    "Temperature (F)", "Air Pressure (kPA)", "Carry Distance (yards)", "Carry Deviation Angle (deg)",
    "Carry Deviation Distance (yards)",
)
SHOT = dict(zip(COLUMNS, (
    "2024-05-12 10:31:22", "Driver", "100", "1", "0.5", "1", "0.5", "150", "1.5", "12", "1.5", "3000", "0", "3000",
    "Measured", "0", "90", "230", "3", "12", "1.2038", "68", "101.3", "200", "3", "10.467191",
), strict=True))
"""A driver: 150 mph, carry 200 yd landing 3 deg right (deviation 200 sin 3 deg yd), 68 F, 101.3 kPa."""


def export(tmp_path, *rows: dict, columns=COLUMNS, name="garmin.csv"):
    """A Garmin export of `rows`, each SHOT with the given cells changed."""
    path = tmp_path / name
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, columns, extrasaction="ignore")
        writer.writeheader()
        writer.writerows({**SHOT, **row} for row in rows)
    return path


def test_units_become_si_as_worked_by_hand(tmp_path):
    (shot,) = load_garmin(export(tmp_path, {})).records
    assert shot.ball_speed_mps == pytest.approx(67.056, abs=1e-12)  # 150 mph x 0.44704
    assert (shot.launch_angle_deg, shot.launch_direction_deg) == (12.0, 1.5)
    assert shot.carry_y_m == pytest.approx(182.629369, abs=1e-6)  # 200 yd x 0.9144 x cos 3 deg, down the line
    assert shot.carry_x_m == pytest.approx(9.571200, abs=1e-6)  # 10.467191 yd x 0.9144, + right
    assert math.hypot(shot.carry_x_m, shot.carry_y_m) == pytest.approx(200 * 0.9144, abs=1e-6)  # one landing point
    assert shot.apex_m == pytest.approx(27.432, abs=1e-12)  # 90 ft x 0.3048
    assert shot.temperature_c == pytest.approx(20.0, abs=1e-12)  # (68 - 32) x 5/9
    assert shot.pressure_hpa == pytest.approx(1013.0, abs=1e-9)  # 101.3 kPa, station pressure
    assert (shot.altitude_m, shot.humidity_pct) == (None, None)
    assert (shot.wind_speed_mps, shot.wind_from_deg) == (0.0, 0.0)  # the monitor's computed carry: still air
    assert (shot.shot_id, shot.session, shot.timestamp, shot.club) == ("2", "2024-05-12", "2024-05-12T10:31:22",
                                                                      "Driver")


def test_a_landing_left_of_the_line_is_negative_x(tmp_path):
    (shot,) = load_garmin(export(tmp_path, {"Carry Deviation Angle (deg)": "-3",
                                            "Carry Deviation Distance (yards)": "-10.467191"})).records
    assert shot.carry_x_m == pytest.approx(-9.571200, abs=1e-6) and shot.carry_y_m == pytest.approx(182.629369)


def test_spin_axis_keeps_its_sign_and_sidespin_flips(tmp_path):
    path = export(
        tmp_path,
        {"Spin Axis (deg)": "5", "Sidespin (rpm)": "-262"},  # axis as recorded: Garmin's + is golfflight's + (right)
        {"Spin Rate (rpm)": "", "Spin Axis (deg)": "", "Backspin (rpm)": "3000", "Sidespin (rpm)": "500"},
        {"Spin Rate (rpm)": "3100", "Spin Axis (deg)": "", "Backspin (rpm)": "3000", "Sidespin (rpm)": "-500"},
    )
    recorded, derived, mixed = load_garmin(path).records
    assert (recorded.spin_rpm, recorded.spin_axis_deg) == (3000.0, 5.0)
    assert derived.spin_rpm == pytest.approx(3041.381265, abs=1e-6)  # hypot(3000, 500)
    assert derived.spin_axis_deg == pytest.approx(-9.462322, abs=1e-6)  # Garmin's + sidespin curves left
    assert mixed.spin_rpm == 3100.0 and mixed.spin_axis_deg == pytest.approx(9.462322, abs=1e-6)


def test_rows_without_a_launch_angle_or_a_carry_are_listed_and_skipped(tmp_path):
    path = export(tmp_path, {}, {"Launch Angle (deg)": ""}, {"Carry Distance (yards)": "0"},
                  {"Carry Distance (yards)": ""}, {"Spin Rate Type": "Estimated"})
    conversion = load_garmin(path)
    report = conversion.report
    assert (report.rows_in, report.kept, report.n_dropped) == (5, 2, 3)
    assert [r.shot_id for r in conversion.records] == ["2", "6"]
    assert report.dropped == {
        "no launch angle: 'Launch Angle (deg)' is blank": [3],
        "no flight recorded: 'Carry Distance (yards)' blank or 0": [4, 5],
    }
    summary = report.summary()
    assert "5 in, 2 kept, 3 dropped" in summary and "(lines 4, 5)" in summary
    assert "1 rows' spin is Garmin's estimate ('Spin Rate Type' Estimated), not measured (lines 6)" in summary


def test_a_bad_value_refuses_the_file_naming_line_column_and_range(tmp_path):
    path = export(tmp_path, {}, {"Ball Speed (mph)": "250"}, {"Temperature (F)": "150"}, {"Backspin (rpm)": "fast"},
                  {"Ball Speed (mph)": ""})
    with pytest.raises(RecordError) as refused:
        load_garmin(path)
    message = str(refused.value)
    assert "4 malformed rows (--skip-bad-rows" in message
    assert ("line 3 column 'Ball Speed (mph)': '250 = 111.76 m/s': 'Ball Speed (mph)' (ball_speed_mps) outside the "
            "allowed range 0.5 to 100 m/s") in message
    assert ("line 4 column 'Temperature (F)': '150 = 65.5556 degC': 'Temperature (F)' (temperature_c) outside the "
            "allowed range -30 to 55 degC") in message
    assert "line 5 column 'Backspin (rpm)': 'fast': 'Backspin (rpm)' is not a number" in message
    assert "line 6 column 'Ball Speed (mph)': '': 'Ball Speed (mph)' is blank" in message
    skipped = load_garmin(path, skip_bad_rows=True)
    assert [r.shot_id for r in skipped.records] == ["2"]  # never clamped: the fast one is left out, not slowed
    assert len(skipped.report.bad_rows) == 4 and skipped.report.count("bad row: ") == 4


def test_no_air_leaves_the_air_blank_and_reads_no_air_cell(tmp_path):
    conversion = load_garmin(export(tmp_path, {}, {"Temperature (F)": "150", "Air Density (g/L)": "n/a"}), air=False)
    assert [(r.temperature_c, r.pressure_hpa) for r in conversion.records] == [(None, None)] * 2
    assert "air left blank (--no-air): the shots fly in ICAO standard air" in conversion.report.summary()


def test_a_recorded_density_off_by_more_than_one_percent_is_noted(tmp_path):
    computed = float(air_density(20.0, 101300.0))  # 1.2038 kg/m^3: what the kept temperature and pressure make
    path = export(tmp_path, {}, {"Air Density (g/L)": f"{computed * 1.009:.4f}"},
                  {"Air Density (g/L)": f"{computed * 0.97:.4f}"})
    summary = load_garmin(path).report.summary()
    assert ("1 rows' 'Air Density (g/L)' differs from the density of their temperature and pressure by more than 1% "
            "(largest 3.0%, line 4; lines 4)") in summary
    assert "Air Density" not in load_garmin(path, air=False).report.summary()


def test_a_deviation_that_is_not_the_carrys_is_noted(tmp_path):
    summary = load_garmin(export(tmp_path, {}, {"Carry Deviation Distance (yards)": "-10.5"})).report.summary()
    assert ("1 rows' 'Carry Deviation Distance (yards)' differs from carry x sin('Carry Deviation Angle (deg)') by "
            "more than 1 yd (largest 21.0 yd, line 3; lines 3)") in summary


def test_a_file_without_the_launch_or_the_spin_columns_is_refused(tmp_path):
    no_angle = export(tmp_path, {}, columns=[c for c in COLUMNS if c != "Launch Angle (deg)"])
    with pytest.raises(RecordError, match=r"line 1 \(header\): a Garmin Golf export needs the columns "
                                          r"\['Launch Angle \(deg\)'\]"):
        load_garmin(no_angle)
    spin_only = export(tmp_path, {}, columns=[c for c in COLUMNS if c not in ("Spin Axis (deg)", "Sidespin (rpm)")])
    with pytest.raises(RecordError, match=r"Spin Rate \(rpm\) and Spin Axis \(deg\), or Backspin"):
        load_garmin(spin_only)
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(RecordError, match="empty.csv: empty"):
        load_garmin(empty)


def test_without_a_date_the_session_is_given_or_the_file_name(tmp_path):
    path = export(tmp_path, {}, columns=[c for c in COLUMNS if c != "Date"], name="range_day.csv")
    assert load_garmin(path).records[0].session == "range_day"
    assert load_garmin(path, session="bay 3").records[0].session == "bay 3"


def test_convert_garmin_writes_a_file_that_simulate_flies_in_its_air(tmp_path, capsys):
    straight = {name: "0" for name in ("Launch Direction (deg)", "Carry Deviation Angle (deg)",
                                       "Carry Deviation Distance (yards)")}
    source = export(tmp_path, {**straight, "Spin Axis (deg)": "10"},
                    {**straight, "Spin Rate (rpm)": "", "Spin Axis (deg)": "", "Sidespin (rpm)": "500"},
                    {"Launch Angle (deg)": ""})
    shots, results = tmp_path / "shots.csv", tmp_path / "results.csv"
    assert main(["convert", "garmin", str(source), "--out", str(shots)]) == 0
    printed = capsys.readouterr().out
    assert "3 in, 2 kept, 1 dropped" in printed and f"wrote 2 shots to {shots}" in printed
    assert len(read_shots(shots)) == 2
    assert main(["simulate", str(shots), "--out", str(results)]) == 0
    with results.open(newline="") as handle:
        right, left = csv.DictReader(handle)
    assert (right["shot_id"], right["temperature_c"], right["pressure_hpa"]) == ("2", "20.0", "1013.0")
    assert float(right["air_density_kg_m3"]) == pytest.approx(float(air_density(20.0, 101300.0)), rel=1e-12)
    assert float(right["landing_x_m"]) > 1.0 > -1.0 > float(left["landing_x_m"])  # + axis fades, + sidespin draws

    assert main(["convert", "garmin", str(source), "--out", str(shots), "--no-air"]) == 0
    assert main(["simulate", str(shots), "--out", str(results)]) == 0
    with results.open(newline="") as handle:
        flown = list(csv.DictReader(handle))
    assert [float(row["air_density_kg_m3"]) for row in flown] == [STANDARD.air.density_kg_m3] * 2
    assert "temperature_c" not in flown[0]


def _as_garmin_row(record, day: str) -> dict:
    """A canonical record written back in the export's columns and units, rounded as the app rounds them."""
    carry_m = math.hypot(record.carry_x_m, record.carry_y_m)
    return {
        **SHOT,
        "Date": f"{day} 10:00:00",
        "Ball Speed (mph)": f"{record.ball_speed_mps / MPH_TO_MPS:.1f}",
        "Launch Angle (deg)": f"{record.launch_angle_deg:.1f}",
        "Launch Direction (deg)": f"{record.launch_direction_deg:.1f}",
        "Spin Rate (rpm)": f"{record.spin_rpm:.0f}",
        "Spin Axis (deg)": f"{record.spin_axis_deg:.1f}",
        "Apex Height (ft)": f"{record.apex_m / FOOT_M:.1f}",
        "Carry Distance (yards)": f"{carry_m / YARD_M:.1f}",
        "Carry Deviation Angle (deg)": f"{math.degrees(math.atan2(record.carry_x_m, record.carry_y_m)):.1f}",
        "Carry Deviation Distance (yards)": f"{record.carry_x_m / YARD_M:.1f}",
        "Temperature (F)": "59", "Air Pressure (kPA)": "80.9", "Air Density (g/L)": "0.951",
    }


def test_a_thin_air_venue_exported_by_the_app_is_found_with_its_air_concealed(tmp_path):
    """The user's path end to end: a venue at about 1,900 m whose monitor flies density alone (0.776 x ICAO), its shots
    written in the Garmin export's columns (carry, deviation and apex only, rounded as the app rounds them),
    converted with --no-air (the air concealed; the wind recorded calm) and diagnosed: air alone is named, within
    0.03, and no wind is fitted."""
    from golfflight.discovery.conceal import conceal
    from golfflight.discovery.diagnose import diagnose
    from golfflight.discovery.effects import DENSITY_ONLY
    from golfflight.discovery.model import load_model
    from golfflight.discovery.recordings import from_shot_set
    from golfflight.shots.records import ShotSet

    model = load_model(None)
    records = conceal({DENSITY_ONLY: {"ratio": 0.776}}, 200, 5, model=model).shots.records
    days = {session: f"2024-05-{10 + i:02d}" for i, session in enumerate(sorted({r.session for r in records}))}
    source = tmp_path / "venue.csv"
    with source.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, COLUMNS)
        writer.writeheader()
        writer.writerows(_as_garmin_row(r, days[r.session]) for r in records)
    converted = load_garmin(source, air=False).records
    assert len(converted) == len(records) and all(r.wind_speed_mps == 0.0 for r in converted)
    report = diagnose(from_shot_set(ShotSet(converted)), model, progress=False).report
    assert not any("wind" in c.name.split("+") for c in report.candidates)
    assert [e.name for e in report.effects] == [DENSITY_ONLY]
    assert report.effects[0].parameters["ratio"] == pytest.approx(0.776, abs=0.03)
