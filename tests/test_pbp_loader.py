"""pbp loader: ids, units, groups, drop reasons, refusal of malformed cells, rest positions, the CLI; on the shared
files the radar-shot counts and the sign of the launch direction."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np
import pytest
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.pbp import distance_m, load_pbp, recorded_apex, rest_positions
from golfflight.shots.records import RecordError, read_shots
from golfflight.shots.tourcast import load_tourcast

from golfflight.commands import convert

PBP = Path(__file__).parent / "fixtures" / "pbp.csv"
REAL = shared_data_dir() / "real" / "pga_tourcast_trackman"
PLAYERS = REAL / "pbp" / "pbp_2020_011_011.csv"
TOUR_CHAMPIONSHIP = REAL / "pbp" / "pbp_2020_060_688.csv"
SENTRY = REAL / "pbp" / "pbp_2021_016_656.csv"
SENTRY_TRAJECTORIES = REAL / "shot_trajectory" / "shot_trajectory_2021_016_656.csv"

A = "901-R1-H1-P11111-S1"
"""Fixture line 2: 150 mph, 12.5 deg up, 2.0 deg left, 2800 rpm, apex 90 ft; tee (1000, 2000, 50) ft, rest
(1030, 2900, 46) ft, '301 yds', ELF. Line 3 is its second shot (no radar), line 4 a spin of 0, line 5 a launch angle
'high', lines 6-7 a provisional ball (two radar rows of one key), line 8 a launch direction of 75 deg."""
PROVISIONAL = ("901-R2-H1-P11111-S1-f1", "901-R2-H1-P11111-S1-f2")


def _edited(tmp_path: Path, edit) -> Path:
    with PBP.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    path = tmp_path / PBP.name
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(edit(rows))
    return path


def _without_bad_cell(tmp_path: Path) -> Path:
    return _edited(tmp_path, lambda rows: [r for r in rows if r["radarData.verticalLaunchAngle"] != "high"])


def test_a_radar_shot_becomes_a_canonical_record_in_si_units(tmp_path):
    shots = {r.shot_id: r for r in load_pbp(_without_bad_cell(tmp_path)).records}
    shot = shots[A]
    assert shot.ball_speed_mps == pytest.approx(150 * MPH_TO_MPS)
    assert (shot.launch_angle_deg, shot.launch_direction_deg, shot.spin_rpm, shot.spin_axis_deg) == (12.5, -2.0, 2800,
                                                                                                      0.0)
    assert shot.apex_m == pytest.approx(90 * FOOT_M)
    assert (shot.flight_time_s, shot.carry_y_m, shot.club) == (None, None, None)
    assert (shot.session, shot.group) == ("901-R1", "901-R1-H1")


def test_a_provisional_ball_numbers_the_radar_rows_of_its_key(tmp_path):
    conversion = load_pbp(_without_bad_cell(tmp_path))
    assert [r.shot_id for r in conversion.records] == [A, *PROVISIONAL]
    assert {r.group for r in conversion.records[1:]} == {"901-R2-H1"}
    assert any("provisional" in note and "901-R2-H1-P11111-S1" in note for note in conversion.report.notes)


def test_a_malformed_cell_refuses_the_file_naming_line_and_column():
    with pytest.raises(RecordError, match=r"1 malformed rows .*\n  .*pbp.csv line 5 column "
                                          r"'radarData.verticalLaunchAngle': 'high': .* is not a number"):
        load_pbp(PBP)


def test_skip_bad_rows_counts_every_dropped_row_under_its_reason():
    report = load_pbp(PBP, skip_bad_rows=True).report
    assert (report.rows_in, report.kept, report.n_dropped) == (7, 3, 4)
    assert report.dropped == {
        "no radar data ('radarData.ballSpeed' is NA: not a radar-measured tee shot)": [3],
        "no spin: 'radarData.launchSpin' is 0 (missing)": [4],
        "bad row: 'radarData.verticalLaunchAngle' is not a number": [5],
        "'radarData.horizontalLaunchAngle' (launch_direction_deg) outside the allowed range -60 to 60 deg": [8],
    }
    assert report.bad_rows == [f"{PBP} line 5 column 'radarData.verticalLaunchAngle': 'high': "
                               "'radarData.verticalLaunchAngle' is not a number"]
    assert any("spin_axis_deg is 0" in note for note in report.notes)


def test_a_malformed_cell_outranks_a_drop_reason(tmp_path):
    path = _edited(tmp_path, lambda rows: [{**r, "radarData.launchSpin": "lots"} if r[""] == "7" else r for r in rows])
    report = load_pbp(path, skip_bad_rows=True).report
    assert report.dropped["bad row: 'radarData.launchSpin' is not a number"] == [8]
    assert "'radarData.horizontalLaunchAngle' (launch_direction_deg) outside" not in " ".join(report.dropped)


def test_a_malformed_key_cell_is_a_bad_row_too(tmp_path):
    path = _edited(tmp_path, lambda rows: [{**r, "holeNumber": "x"} if r[""] == "1" else r for r in rows])
    report = load_pbp(path, skip_bad_rows=True).report
    assert report.dropped["bad row: a shot key cell is not a number"] == [2]
    assert "line 2 column 'holeNumber': 'x' is not a number" in report.bad_rows[0]


def test_apex_is_left_out_on_request_and_for_the_players_2020(tmp_path):
    assert all(r.apex_m is None for r in load_pbp(PBP, apex=False, skip_bad_rows=True).records)
    players = _edited(tmp_path, lambda rows: [{**r, "seasonYear": "2020", "tournamentNumber": "011"} for r in rows])
    conversion = load_pbp(players, skip_bad_rows=True)
    assert conversion.report.kept == 3 and all(r.apex_m is None for r in conversion.records)
    assert any("THE PLAYERS 2020" in note and "docs/real_data.md" in note for note in conversion.report.notes)
    assert recorded_apex(_without_bad_cell(tmp_path))[A].height_m == pytest.approx(90 * FOOT_M)


def test_recorded_apex_keeps_every_field_in_metres():
    apex = recorded_apex(PBP)
    assert set(apex) == {A, "901-R1-H2-P22222-S1", "901-R1-H3-P33333-S1", *PROVISIONAL, "901-R2-H4-P44444-S1"}
    assert (apex[A].height_m, apex[A].range_m, apex[A].side_m) == pytest.approx((90 * FOOT_M, 520.5 * FOOT_M,
                                                                                 -12.5 * FOOT_M))


def test_rest_positions_are_relative_to_the_tee():
    rest = rest_positions(PBP)
    assert len(rest) == 6
    shot = rest[A]
    assert (shot.dx_m, shot.dy_m, shot.dz_m) == pytest.approx((30 * FOOT_M, 900 * FOOT_M, -4 * FOOT_M))
    assert (shot.distance_m, shot.lie) == (pytest.approx(301 * YARD_M), "ELF")
    assert rest["901-R1-H2-P22222-S1"].dz_m is None, "rest z is NA"


@pytest.mark.parametrize("text, metres", [("306 yds", 306 * YARD_M), ("23 ft 3 in.", 23.25 * FOOT_M),
                                          ("9 in.", 0.75 * FOOT_M), ("12 ft", 12 * FOOT_M), ("NA", None)])
def test_shotlink_distances(text, metres):
    assert distance_m(text) == (None if metres is None else pytest.approx(metres))


def test_an_unknown_distance_refuses_naming_line_and_column(tmp_path):
    path = _edited(tmp_path, lambda rows: [{**r, "distance": "300 m"} if r[""] == "1" else r for r in rows])
    with pytest.raises(RecordError, match=r"line 2 column 'distance': '300 m' is not a distance"):
        rest_positions(path)


def test_bad_files_are_refused_naming_the_problem(tmp_path):
    two_events = _edited(tmp_path, lambda rows: [{**r, "tournamentNumber": "902"} if r[""] == "2" else r
                                                 for r in rows])
    with pytest.raises(RecordError, match="several events"):
        load_pbp(two_events, skip_bad_rows=True)
    no_spin = tmp_path / "no_spin.csv"
    no_spin.write_text(PBP.read_text().replace("radarData.launchSpin", "spin"))
    with pytest.raises(RecordError, match=r"required columns \['radarData.launchSpin'\] are missing"):
        load_pbp(no_spin)


def test_convert_command_writes_records_and_prints_the_report(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    convert.register(parser.add_subparsers(dest="command"))
    out = tmp_path / "pbp_shots.csv"
    args = parser.parse_args(["convert", "pbp", str(PBP), "--out", str(out), "--skip-bad-rows", "--no-apex"])
    assert args.run(args) == 0
    printed = capsys.readouterr().out
    assert "7 in, 3 kept, 4 dropped" in printed and "skipped bad row" in printed
    shots = read_shots(out)
    assert [r.shot_id for r in shots.records] == [A, *PROVISIONAL]
    assert shots.records[0].group == "901-R1-H1" and shots.records[0].apex_m is None


def _real(*paths: Path) -> None:
    missing = [str(p) for p in paths if not p.exists()]
    if missing:
        pytest.skip(f"shared pbp files not found: {missing}")


@pytest.mark.parametrize("path, radar, spin", [(PLAYERS, 2442, 2259), (TOUR_CHAMPIONSHIP, 2134, 1948),
                                               (SENTRY, 265, 221)])
def test_real_radar_shot_counts(path, radar, spin):
    _real(path)
    report = load_pbp(path).report
    assert report.kept == spin, "SOURCE.txt: shots with spin > 0"
    assert report.rows_in - report.count("no radar data") == radar
    assert report.n_dropped == report.rows_in - spin and not report.bad_rows
    assert len(rest_positions(path)) == radar


def test_real_horizontal_launch_angle_is_positive_to_the_right():
    """The Sentry's TOURCAST polynomials (z right) give the launch direction of the same shots: the pbp
    horizontalLaunchAngle agrees with it in sign and size, so it is + = right as it stands (no sign flip)."""
    _real(SENTRY, SENTRY_TRAJECTORIES)
    pbp = {r.shot_id: r for r in load_pbp(SENTRY).records}
    polynomial = {r.shot_id: r for r in load_tourcast(SENTRY_TRAJECTORIES, SENTRY).records}
    assert len(set(polynomial) - set(pbp)) == 0, "both loaders give the same ids"
    pairs = np.array([(pbp[i].launch_direction_deg, polynomial[i].launch_direction_deg) for i in polynomial])
    assert len(pairs) > 200
    recorded, derived = pairs[:, 0], pairs[:, 1]
    assert np.median(np.abs(recorded - derived)) < 1.0
    assert np.median(np.abs(recorded + derived)) > 4.0
    assert np.mean(np.sign(recorded) == np.sign(derived)) > 0.9
    assert np.corrcoef(recorded, derived)[0, 1] > 0.9


def test_real_rest_distance_is_the_horizontal_tee_to_rest_distance():
    _real(TOUR_CHAMPIONSHIP)
    rest = rest_positions(TOUR_CHAMPIONSHIP).values()
    gaps = [math.hypot(r.dx_m, r.dy_m) - r.distance_m for r in rest]
    assert np.median(np.abs(gaps)) < 1.0
