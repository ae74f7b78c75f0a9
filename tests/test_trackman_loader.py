"""TrackMan CSV loader: units, SI conversion, carry geometry, filters and their counts, bad files, the real export."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import pytest
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import RecordError, read_shots
from golfflight.shots.trackman import load_trackman

from golfflight.commands import convert

FIXTURES = Path(__file__).parent / "fixtures"
EXPORT = FIXTURES / "trackman_export.csv"
INDOOR = ("not a measured flight: 'Last data Point - Time' < {:g} x 'Carry Flat - Time' "
          "(indoor, outcome modelled by TrackMan)")
METRIC = FIXTURES / "trackman_export_metric.csv"
REAL = shared_data_dir() / "real" / "trackman_driver_sessions" / "data.csv"


def _variant(tmp_path: Path, edit) -> Path:
    """A copy of the fixture with its rows (lists of cells) changed by `edit`."""
    with EXPORT.open(newline="") as handle:
        rows = list(csv.reader(handle))
    path = tmp_path / "variant.csv"
    with path.open("w", newline="") as handle:
        csv.writer(handle).writerows(edit(rows))
    return path


def _set_unit(rows: list[list[str]], column: str, unit: str) -> list[list[str]]:
    rows[1][rows[0].index(column)] = unit
    return rows


def test_a_malformed_row_refuses_the_file_naming_line_column_and_value():
    with pytest.raises(RecordError) as error:
        load_trackman(EXPORT)
    message = str(error.value)
    assert "1 malformed rows (--skip-bad-rows" in message
    assert "trackman_export.csv line 7 column 'Spin Rate': 'spin_rpm = -2.14748e+09'" in message
    assert "outside the allowed range 0 to 15000 rpm" in message


def test_default_filters_count_every_dropped_row_with_its_reason():
    conversion = load_trackman(EXPORT, skip_bad_rows=True)
    report = conversion.report
    assert (report.rows_in, report.kept, report.n_dropped) == (7, 3, 4)
    assert [r.shot_id for r in conversion.records] == ["3", "4", "6"]
    assert report.dropped == {
        INDOOR.format(0.9): [5],
        "bad row: 'Spin Rate' (spin_rpm) outside the allowed range 0 to 15000 rpm": [7],
        "'Spin Axis' is blank": [8],
        "no flight recorded: 'Last data Point - Time' or 'Carry Flat - Time' blank or 0": [9],
    }
    summary = report.summary()
    assert "dropped 1: bad row: 'Spin Rate' (spin_rpm) outside the allowed range 0 to 15000 rpm (lines 7)" in summary
    assert "skipped bad row: " in summary and "line 7 column 'Spin Rate'" in summary


def test_units_are_converted_to_si_and_columns_mapped():
    shot = load_trackman(EXPORT, skip_bad_rows=True).records[0]
    assert shot.ball_speed_mps == pytest.approx(150.0 * MPH_TO_MPS)
    assert (shot.launch_angle_deg, shot.launch_direction_deg) == (12.0, -1.5)
    assert (shot.spin_rpm, shot.spin_axis_deg) == (2500, 4.0)
    assert shot.apex_m == pytest.approx(90.0 * FOOT_M)
    assert (shot.flight_time_s, shot.landing_angle_deg) == (6.4, 38.0)
    assert shot.carry_x_m == pytest.approx(10.0 * YARD_M)
    assert shot.carry_y_m == pytest.approx(math.sqrt(250.0**2 - 10.0**2) * YARD_M)
    assert (shot.club, shot.session, shot.shot_id, shot.timestamp) == ("Driver", "trackman_export", "3", None)


def test_carry_flat_length_is_the_straight_line_distance():
    """Side and the along-line distance sqrt(Length² − Side²) reproduce TrackMan's Curve (offset from launch line)."""
    for shot, length_yd, curve_ft in zip(load_trackman(EXPORT, skip_bad_rows=True).records[:2], (250.0, 230.0), (49.6, -60.0)):
        assert math.hypot(shot.carry_x_m, shot.carry_y_m) / YARD_M == pytest.approx(length_yd)
        phi = math.radians(shot.launch_direction_deg)
        curve = (shot.carry_x_m * math.cos(phi) - shot.carry_y_m * math.sin(phi)) / FOOT_M
        assert curve == pytest.approx(curve_ft, abs=0.1)


def test_ball_filter_reports_each_ball_type_dropped():
    report = load_trackman(EXPORT, skip_bad_rows=True, balls=["premium"]).report
    assert report.kept == 2
    assert report.dropped["ball type 'Medium' not in ['premium']"] == [6]
    assert report.rows_in == report.kept + report.n_dropped


def test_tracked_fraction_is_configurable_and_can_be_switched_off():
    strict = load_trackman(EXPORT, skip_bad_rows=True, min_tracked_fraction=0.95)
    assert [r.shot_id for r in strict.records] == ["4"]
    assert strict.report.dropped[INDOOR.format(0.95)] == [3, 5, 6, 8]
    every = load_trackman(EXPORT, skip_bad_rows=True, min_tracked_fraction=None)
    assert [r.shot_id for r in every.records] == ["3", "4", "5", "6", "9"]
    no_flight = every.records[-1]
    assert no_flight.ball_speed_mps == pytest.approx(118.0 * MPH_TO_MPS)
    assert (no_flight.carry_y_m, no_flight.apex_m, no_flight.flight_time_s) == (None, None, None)
    assert every.report.n_dropped == 2


def test_metric_export_with_dates_gives_sessions_per_day():
    conversion = load_trackman(METRIC)
    assert conversion.report.kept == 3
    first = conversion.records[0]
    assert first.ball_speed_mps == 45.0 and first.apex_m == 28.0
    assert first.carry_x_m == -4.0 and first.carry_y_m == pytest.approx(math.sqrt(150.0**2 - 16.0))
    assert first.timestamp == "2023-08-07T19:56:18" and first.club == "7 Iron"
    assert [r.session for r in conversion.records] == ["2023-08-07", "2023-08-07", "2023-08-09"]
    assert [r.shot_id for r in conversion.records] == ["4", "5", "6"]


def test_missing_units_row_is_refused(tmp_path):
    with pytest.raises(RecordError, match="units row"):
        load_trackman(_variant(tmp_path, lambda rows: rows[:1] + rows[2:]))


def test_unexpected_unit_is_refused_naming_the_column(tmp_path):
    with pytest.raises(RecordError, match=r"column 'Ball Speed': unit \[knots\] not accepted"):
        load_trackman(_variant(tmp_path, lambda rows: _set_unit(rows, "Ball Speed", "[knots]")))
    with pytest.raises(RecordError, match=r"column 'Max Height - Height': unit \[mph\]"):
        load_trackman(_variant(tmp_path, lambda rows: _set_unit(rows, "Max Height - Height", "[mph]")))


def test_missing_required_column_is_refused_naming_it(tmp_path):
    def without_spin_axis(rows):
        index = rows[0].index("Spin Axis")
        return [row[:index] + row[index + 1:] for row in rows]

    def without_ball(rows):
        return [row[:1] + row[2:] for row in rows]

    with pytest.raises(RecordError, match="required column 'Spin Axis' is missing"):
        load_trackman(_variant(tmp_path, without_spin_axis))
    with pytest.raises(RecordError, match="column 'Ball' is missing"):
        load_trackman(_variant(tmp_path, without_ball), balls=["Premium"])


def test_a_non_number_is_refused_or_skipped_naming_the_column(tmp_path):
    def corrupt(rows):
        rows[2][rows[0].index("Launch Angle")] = "12.0 deg"
        return rows

    with pytest.raises(RecordError, match=r"line 3 column 'Launch Angle': '12.0 deg': 'Launch Angle' is not a number"):
        load_trackman(_variant(tmp_path, corrupt), min_tracked_fraction=None, balls=["Premium"])
    report = load_trackman(_variant(tmp_path, corrupt), skip_bad_rows=True).report
    assert report.dropped["bad row: 'Launch Angle' is not a number"] == [3]


def test_convert_command_writes_canonical_csv_and_prints_the_report(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    convert.register(parser.add_subparsers(dest="command"))
    out = tmp_path / "shots.csv"
    args = parser.parse_args(["convert", "trackman", str(EXPORT), "--out", str(out), "--ball", "Premium", "--skip-bad-rows"])
    assert args.run(args) == 0
    printed = capsys.readouterr().out
    assert "7 in, 2 kept, 5 dropped" in printed and "ball type 'Medium'" in printed
    shots = read_shots(out)
    assert [r.shot_id for r in shots.records] == ["3", "4"]
    assert shots.records[0].ball_speed_mps == pytest.approx(150.0 * MPH_TO_MPS, rel=1e-6)


@pytest.fixture(scope="module")
def real_rows() -> dict[int, dict[str, str]]:
    if not REAL.exists():
        pytest.skip(f"shared TrackMan export not found at {REAL}")
    with REAL.open(newline="") as handle:
        reader = csv.reader(handle)
        header = next(reader)
        next(reader)
        return {line: dict(zip(header, cells)) for line, cells in enumerate(reader, start=3)}


def _agree(records, rows, tolerance: float) -> None:
    for shot in records:
        source = rows[int(shot.shot_id)]
        expected = {
            "ball_speed_mps": float(source["Ball Speed"]) * MPH_TO_MPS,
            "launch_angle_deg": float(source["Launch Angle"]),
            "launch_direction_deg": float(source["Launch Direction"]),
            "spin_rpm": float(source["Spin Rate"]),
            "spin_axis_deg": float(source["Spin Axis"]),
            "apex_m": float(source["Max Height - Height"]) * FOOT_M,
            "flight_time_s": float(source["Carry Flat - Time"]),
        }
        for column, value in expected.items():
            assert getattr(shot, column) == pytest.approx(value, rel=tolerance, abs=1e-9), (shot.shot_id, column)
        length = float(source["Carry Flat - Length"]) * YARD_M
        assert math.hypot(shot.carry_x_m, shot.carry_y_m) == pytest.approx(length, rel=tolerance)


def test_real_export_launch_values_agree_exactly_with_the_source(real_rows, tmp_path):
    conversion = load_trackman(REAL, skip_bad_rows=True)
    report = conversion.report
    assert report.rows_in == len(real_rows) == report.kept + report.n_dropped
    assert 900 < report.kept < 1200
    assert report.count("not a measured flight") > 8000
    assert report.count("bad row: 'Spin Rate' (spin_rpm) outside") >= 1
    _agree(conversion.records, real_rows, 1e-12)
    out = tmp_path / "real.csv"
    parser = argparse.ArgumentParser()
    convert.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["convert", "trackman", str(REAL), "--out", str(out), "--skip-bad-rows"])
    assert args.run(args) == 0
    written = read_shots(out)
    assert len(written) == report.kept
    _agree(written.records, real_rows, 1e-5)


def test_real_export_curve_confirms_carry_geometry(real_rows):
    """TrackMan's Curve column is reproduced to 1e-3 ft by carry_x cos φ − carry_y sin φ on every converted shot."""
    for shot in load_trackman(REAL, skip_bad_rows=True).records:
        curve = real_rows[int(shot.shot_id)]["Curve"]
        if curve:
            phi = math.radians(shot.launch_direction_deg)
            derived = (shot.carry_x_m * math.cos(phi) - shot.carry_y_m * math.sin(phi)) / FOOT_M
            assert derived == pytest.approx(float(curve), abs=1e-3), shot.shot_id
