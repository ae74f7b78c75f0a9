"""TOURCAST loader: launch from the polynomials, landing root, apex, samples, pbp spin join, derived spin axis."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np
import pytest
from golfflight.flight.constants import (
    BALL_AREA_M2,
    BALL_MASS_KG,
    BALL_RADIUS_M,
    FOOT_M,
    GRAVITY_MPS2,
    MPH_TO_MPS,
    RPM_TO_RADPS,
)
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import RecordError, read_shots, read_trajectories, trajectories_path
from golfflight.shots.tourcast import load_tourcast, spin_axis_deg

from golfflight.commands import convert

FIXTURES = Path(__file__).parent / "fixtures"
TRAJECTORY = FIXTURES / "tourcast_shot_trajectory.csv"
PBP = FIXTURES / "tourcast_pbp.csv"
TRUNCATED = FIXTURES / "tourcast_truncated.csv"
REAL = shared_data_dir() / "real" / "pga_tourcast_trackman"
REAL_016 = REAL / "shot_trajectory" / "shot_trajectory_2021_016_656.csv"
REAL_006 = REAL / "shot_trajectory" / "shot_trajectory_2021_006_006.csv"
REAL_PBP = REAL / "pbp" / "pbp_2021_016_656.csv"

A = "901-R1-H1-P11111-S1"
"""Fixture shot A (TrackMan axes): x = 0.5 + 60t − 3t² + 0.05t³, y = 24t − 3.4t² − 0.1t³ = −0.1 t (t − 6)(t + 40),
z = −1 + 1.5t + 0.4t²: lands at t = 6 s, 262.8 m down the line and 23.4 m right; pbp spin 2800 rpm."""


def _edited(tmp_path: Path, source: Path, edit) -> Path:
    with source.open(newline="") as handle:
        rows = list(csv.reader(handle))
    path = tmp_path / source.name
    with path.open("w", newline="") as handle:
        csv.writer(handle).writerows(edit(rows))
    return path


def _by_id(conversion):
    return {r.shot_id: r for r in conversion.records}


def test_launch_landing_and_apex_follow_from_the_polynomials():
    shot = _by_id(load_tourcast(TRAJECTORY, PBP))[A]
    assert shot.ball_speed_mps == pytest.approx(math.sqrt(1.5**2 + 60**2 + 24**2))
    assert shot.launch_angle_deg == pytest.approx(math.degrees(math.atan2(24, math.hypot(1.5, 60))))
    assert shot.launch_direction_deg == pytest.approx(math.degrees(math.atan2(1.5, 60)))
    assert shot.flight_time_s == pytest.approx(6.0)
    assert shot.carry_y_m == pytest.approx(60 * 6 - 3 * 36 + 0.05 * 216)
    assert shot.carry_x_m == pytest.approx(1.5 * 6 + 0.4 * 36)
    down, ahead, side = 24 - 6.8 * 6 - 0.3 * 36, 60 - 6 * 6 + 0.15 * 36, 1.5 + 0.8 * 6
    assert shot.landing_angle_deg == pytest.approx(math.degrees(math.atan2(-down, math.hypot(ahead, side))))
    top = (-6.8 + math.sqrt(6.8**2 + 4 * 0.3 * 24)) / 0.6
    assert shot.apex_m == pytest.approx(24 * top - 3.4 * top**2 - 0.1 * top**3)
    assert (shot.spin_rpm, shot.session, shot.club) == (2800, "901-R1", None)


def test_spin_axis_is_derived_from_the_initial_lift():
    shot = _by_id(load_tourcast(TRAJECTORY, PBP))[A]
    velocity = np.array([1.5, 60.0, 24.0])
    aero = np.array([0.8, -6.0, -6.8 + GRAVITY_MPS2])
    lift = aero - aero @ velocity / (velocity @ velocity) * velocity
    assert shot.spin_axis_deg == pytest.approx(math.degrees(math.atan2(lift[0], lift[2])))
    assert shot.spin_axis_deg > 0


@pytest.mark.parametrize("lateral, expected", [(1.0, 11.309932), (-1.0, -11.309932), (0.0, 0.0)])
def test_lateral_lift_to_the_right_gives_a_positive_axis(lateral, expected):
    coefficients = np.array([[0.0, 0.0, 0.0], [0.0, 70.0, 0.0], [lateral / 2, -3.0, (5.0 - GRAVITY_MPS2) / 2]])
    assert spin_axis_deg(coefficients) == pytest.approx(expected)


def test_pbp_join_and_the_counts_of_shots_without_spin():
    conversion = load_tourcast(TRAJECTORY, PBP)
    report = conversion.report
    assert (report.rows_in, report.kept, report.n_dropped) == (5, 3, 2)
    spins = {r.shot_id: r.spin_rpm for r in conversion.records}
    assert spins == {A: 2800, "901-R2-H1-P11111-S1-f1": 3100, "901-R2-H1-P11111-S1-f2": 2600}
    hint = " (spin is required; --estimate-spin estimates it from the lift)"
    assert report.dropped == {
        "no spin: pbp launchSpin is 0 (missing)" + hint: [9],
        "no spin: no radar-measured pbp row for this shot" + hint: [30],
    }
    assert any("DERIVED" in note for note in report.notes)


def test_a_key_with_two_flights_is_split_and_the_first_interval_end_rescaled():
    shots = _by_id(load_tourcast(TRAJECTORY, PBP))
    first, second = shots["901-R2-H1-P11111-S1-f1"], shots["901-R2-H1-P11111-S1-f2"]
    assert first.flight_time_s == pytest.approx(4.0)
    assert second.flight_time_s == pytest.approx(5.5)
    assert first.carry_y_m == pytest.approx(58 * 4 - 3.5 * 16)
    assert second.carry_y_m == pytest.approx(61 * 5.5 - 3.8 * 5.5**2 + 0.02 * 5.5**3)


def test_estimated_spin_inverts_ferguson_lift_and_landing_is_relative_to_the_start_height():
    conversion = load_tourcast(TRAJECTORY, PBP, estimate_spin=True)
    assert conversion.report.kept == 5 and conversion.report.n_dropped == 0
    assert any("ESTIMATE" in note and "2 kept shots" in note for note in conversion.report.notes)
    shots = _by_id(conversion)
    left = shots["901-R1-H2-P22222-S1"]
    velocity = np.array([-1.0, 62.0, 22.5])
    aero = np.array([-1.0, -8.0, -8.0 + GRAVITY_MPS2])
    lift = aero - aero @ velocity / (velocity @ velocity) * velocity
    speed = np.linalg.norm(velocity)
    lift_coefficient = 2 * BALL_MASS_KG * np.linalg.norm(lift) / (1.19 * BALL_AREA_M2 * speed**2)
    ratio = BALL_RADIUS_M * left.spin_rpm * RPM_TO_RADPS / speed
    assert 0.0504 + 1.2031 * ratio - 1.1490 * ratio**2 == pytest.approx(lift_coefficient)
    assert left.spin_axis_deg < 0
    assert left.flight_time_s == pytest.approx(5.0)
    raised = shots["901-R2-H3-P33333-S1"]
    assert raised.flight_time_s == pytest.approx((-25 + math.sqrt(25**2 + 800)) / 2)


def test_trajectory_is_sampled_from_launch_to_landing():
    conversion = load_tourcast(TRAJECTORY, PBP)
    samples = conversion.trajectories[A]
    shot = _by_id(conversion)[A]
    assert samples.shape == (601, 4)
    assert np.allclose(samples[0], 0.0)
    assert np.allclose(np.diff(samples[:, 0]), 0.01)
    assert np.allclose(samples[-1], [6.0, shot.carry_x_m, shot.carry_y_m, 0.0], atol=1e-9)
    assert samples[1:-1, 3].min() > 0
    assert samples[:, 3].max() == pytest.approx(shot.apex_m, abs=0.01)
    assert set(conversion.trajectories) == {r.shot_id for r in conversion.records}


def test_truncated_polynomials_give_launch_and_flight_time_only():
    conversion = load_tourcast(TRUNCATED, estimate_spin=True)
    (shot,) = conversion.records
    assert shot.ball_speed_mps == pytest.approx(math.sqrt(1 + 70**2 + 15**2))
    assert shot.launch_angle_deg == pytest.approx(math.degrees(math.atan2(15, math.hypot(1, 70))))
    assert shot.flight_time_s == 6.5
    assert (shot.carry_x_m, shot.carry_y_m, shot.apex_m, shot.landing_angle_deg) == (None, None, None, None)
    assert conversion.trajectories == {}
    assert any("fewer than 7 coefficients" in note for note in conversion.report.notes)
    assert load_tourcast(TRUNCATED).report.kept == 0


def test_a_landing_time_far_from_the_height_root_drops_the_shot(tmp_path):
    def late(rows):
        rows[7][rows[0].index("timeInterval")] = "7"
        return rows

    report = load_tourcast(_edited(tmp_path, TRAJECTORY, late), PBP).report
    assert report.dropped["no descending crossing of the start height within 0.5 s of timeInterval end"] == [2]


def test_incomplete_coefficient_rows_refuse_the_file_or_drop_the_shot(tmp_path):
    edited = _edited(tmp_path, TRAJECTORY, lambda rows: rows[:4] + rows[5:])
    with pytest.raises(RecordError, match=r"line 2 column 'row': .*incomplete"):
        load_tourcast(edited, PBP)
    report = load_tourcast(edited, PBP, skip_bad_rows=True).report
    assert report.count("bad row: rows 'row' = 1..'max_row' incomplete") == 1
    assert report.rows_in == report.kept + report.n_dropped
    assert "skipped bad row: " in report.summary()


def test_a_non_number_cell_is_refused_naming_its_line_and_column(tmp_path):
    def corrupt(rows):
        rows[3][rows[0].index("xFit")] = "1.2.3"
        return rows

    with pytest.raises(RecordError, match=r"line 4 column 'xFit': '1.2.3': 'xFit' is not a number"):
        load_tourcast(_edited(tmp_path, TRAJECTORY, corrupt), PBP)


def test_bad_files_are_refused_naming_the_column(tmp_path):
    with pytest.raises(RecordError, match="zFit"):
        load_tourcast(_edited(tmp_path, TRAJECTORY, lambda rows: [row[:-2] + row[-1:] for row in rows]))

    def other_event(rows):
        rows[1][1] = "016"
        return rows

    with pytest.raises(RecordError, match="line 2 column 'tournamentNumber'"):
        load_tourcast(TRAJECTORY, _edited(tmp_path, PBP, other_event))

    def wild_spin(rows):
        rows[1][rows[0].index("radarData.launchSpin")] = "99999"
        return rows

    with pytest.raises(RecordError, match=r"column 'radarData.launchSpin': 99999 outside the allowed range 0 to 15000"):
        load_tourcast(TRAJECTORY, _edited(tmp_path, PBP, wild_spin))


def test_convert_command_writes_records_and_trajectories(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    convert.register(parser.add_subparsers(dest="command"))
    out = tmp_path / "tour.csv"
    args = parser.parse_args(["convert", "tourcast", str(TRAJECTORY), "--pbp", str(PBP), "--out", str(out)])
    assert args.run(args) == 0
    assert "5 in, 3 kept, 2 dropped" in capsys.readouterr().out
    shots = read_shots(out)
    trajectories = read_trajectories(trajectories_path(out))
    assert set(trajectories) == {r.shot_id for r in shots.records}
    assert trajectories[A][-1, 0] == pytest.approx(6.0)
    args = parser.parse_args(["convert", "tourcast", str(TRAJECTORY), "--out", str(tmp_path / "none.csv")])
    assert args.run(args) == 1
    assert not (tmp_path / "none.csv").exists()


def _pbp_radar(path: Path) -> dict[tuple[str, str, str, str], list[dict[str, str]]]:
    rows: dict[tuple[str, str, str, str], list[dict[str, str]]] = {}
    with path.open(newline="") as handle:
        for row in csv.DictReader(handle):
            if row["radarData.ballSpeed"] not in ("", "NA"):
                key = (row["roundNumber"], row["holeNumber"], row["playerId"], row["shotNumber"])
                rows.setdefault(key, []).append(row)
    return rows


def _source_row(radar, shot_id: str) -> dict[str, str]:
    parts = shot_id.split("-")
    key = (parts[1][1:], parts[2][1:], parts[3][1:], parts[4][1:])
    return radar[key][int(parts[5][1:]) - 1 if len(parts) > 5 else 0]


@pytest.fixture(scope="module")
def real_016():
    if not (REAL_016.exists() and REAL_PBP.exists()):
        pytest.skip(f"shared TOURCAST files not found under {REAL}")
    return load_tourcast(REAL_016, REAL_PBP), _pbp_radar(REAL_PBP)


def test_real_launch_values_agree_with_the_pbp_radar_columns(real_016):
    conversion, radar = real_016
    assert conversion.report.rows_in == conversion.report.kept + conversion.report.n_dropped
    assert conversion.report.kept > 200
    diffs = {"speed": [], "angle": [], "direction": [], "apex": [], "tracked": []}
    for shot in conversion.records:
        source = _source_row(radar, shot.shot_id)
        assert shot.spin_rpm == float(source["radarData.launchSpin"])
        diffs["speed"].append(shot.ball_speed_mps / MPH_TO_MPS - float(source["radarData.ballSpeed"]))
        diffs["angle"].append(shot.launch_angle_deg - float(source["radarData.verticalLaunchAngle"]))
        diffs["direction"].append(shot.launch_direction_deg - float(source["radarData.horizontalLaunchAngle"]))
        diffs["apex"].append(shot.apex_m / FOOT_M - float(source["radarData.apexHeight"]))
        diffs["tracked"].append(shot.flight_time_s - float(source["radarData.actualFlightTime"]) / 1000)
    median = {name: float(np.median(np.abs(values))) for name, values in diffs.items()}
    assert median["speed"] < 1.0
    assert median["angle"] < 0.5
    assert median["direction"] < 1.0
    assert median["apex"] < 1.0
    assert 0.1 < np.median(diffs["tracked"]) < 1.5, "landing is after the radar's last point"


def test_real_conversion_writes_readable_canonical_files(real_016, tmp_path):
    conversion, _ = real_016
    parser = argparse.ArgumentParser()
    convert.register(parser.add_subparsers(dest="command"))
    out = tmp_path / "016.csv"
    args = parser.parse_args(["convert", "tourcast", str(REAL_016), "--pbp", str(REAL_PBP), "--out", str(out),
                              "--sample-interval", "0.05"])
    assert args.run(args) == 0
    shots = read_shots(out)
    assert len(shots) == conversion.report.kept
    assert np.allclose(shots.column("ball_speed_mps"), [r.ball_speed_mps for r in conversion.records], rtol=1e-5)
    trajectories = read_trajectories(trajectories_path(out))
    assert len(trajectories) == len(shots)


def test_real_derived_spin_axis_matches_the_side_of_the_curve():
    if not REAL_006.exists():
        pytest.skip(f"shared TOURCAST files not found under {REAL}")
    conversion = load_tourcast(REAL_006, estimate_spin=True)
    assert conversion.report.kept > 500
    curve = [r.carry_x_m - r.carry_y_m * math.tan(math.radians(r.launch_direction_deg)) for r in conversion.records]
    agree = np.sign([r.spin_axis_deg for r in conversion.records]) == np.sign(curve)
    assert np.mean(agree) > 0.9
