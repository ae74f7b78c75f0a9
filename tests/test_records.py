"""The canonical shot-record CSV: round trip, and bad files refused with file, line, column and range."""

import numpy as np
import pytest
from golfflight.shots.records import (
    COLUMNS,
    RecordError,
    ShotRecord,
    read_shots,
    read_trajectories,
    trajectories_path,
    write_shots,
    write_trajectories,
)

LAUNCH = dict(ball_speed_mps=70.0, launch_angle_deg=11.0, launch_direction_deg=-1.5, spin_rpm=2600.0, spin_axis_deg=3.0)


def write_text(path, header, *rows):
    path.write_text("\n".join([",".join(header), *[",".join(r) for r in rows]]) + "\n")


def test_round_trip_keeps_values_and_blanks(tmp_path):
    records = [ShotRecord(shot_id="1", session="s1", split="train", carry_y_m=250.0, **LAUNCH),
               ShotRecord(shot_id="2", session="s1", split="val", apex_m=30.0, **LAUNCH)]
    write_shots(tmp_path / "a.csv", records)
    shots = read_shots(tmp_path / "a.csv")
    assert shots.records == records
    carry = shots.column("carry_y_m")
    assert carry[0] == 250.0 and np.isnan(carry[1])
    assert shots.launch()["spin_rpm"] == pytest.approx([2600.0, 2600.0])


def test_out_of_range_value_names_file_line_column_and_range(tmp_path):
    row = {c: "" for c in COLUMNS} | {k: str(v) for k, v in LAUNCH.items()} | {"spin_rpm": "20000"}
    write_text(tmp_path / "bad.csv", COLUMNS, [row[c] for c in COLUMNS])
    with pytest.raises(RecordError) as error:
        read_shots(tmp_path / "bad.csv")
    message = str(error.value)
    assert "bad.csv line 2 column 'spin_rpm'" in message and "0 to 15000 rpm" in message


def test_non_numeric_and_non_finite_values_are_refused(tmp_path):
    header = list(LAUNCH)
    write_text(tmp_path / "bad.csv", header, ["fast", "11", "0", "2600", "0"], ["70", "nan", "0", "2600", "0"])
    with pytest.raises(RecordError) as error:
        read_shots(tmp_path / "bad.csv")
    assert "line 2 column 'ball_speed_mps': 'fast' is not a number" in str(error.value)
    assert "line 3 column 'launch_angle_deg'" in str(error.value)


def test_missing_and_unknown_columns_are_refused(tmp_path):
    write_text(tmp_path / "a.csv", ["ball_speed_mps", "carry_yards"], ["70", "250"])
    with pytest.raises(RecordError, match=r"missing required columns .*spin_rpm.*unknown columns \['carry_yards'\]"):
        read_shots(tmp_path / "a.csv")


def test_duplicate_shot_ids_are_refused(tmp_path):
    write_shots(tmp_path / "a.csv", [ShotRecord(shot_id="7", **LAUNCH), ShotRecord(shot_id="7", **LAUNCH)])
    with pytest.raises(RecordError, match="a.csv line 3 column 'shot_id': '7' duplicates the shot_id of line 2"):
        read_shots(tmp_path / "a.csv")
    shots = read_shots(tmp_path / "a.csv", skip_bad_rows=True)
    assert len(shots) == 1 and [(p.line, p.column) for p in shots.skipped] == [(3, "shot_id")]


def test_skip_bad_rows_keeps_the_good_ones_and_reports_each_bad_one(tmp_path):
    header = list(LAUNCH)
    write_text(tmp_path / "a.csv", header, ["70", "11", "0", "2600", "0"], ["-3", "11", "0", "2600", "0"],
               ["70", "11", "0", "2600", "0"])
    shots = read_shots(tmp_path / "a.csv", skip_bad_rows=True)
    assert len(shots) == 2
    assert [(p.line, p.column) for p in shots.skipped] == [(3, "ball_speed_mps")]


def test_trajectories_companion_round_trip(tmp_path):
    path = trajectories_path(tmp_path / "session.csv")
    assert path.name == "session.trajectories.csv"
    samples = {"a": np.array([[0.0, 0.0, 0.0, 0.01], [0.1, 0.1, 7.0, 1.2]]), "b": np.array([[0.0, 0.0, 0.0, 0.01]])}
    write_trajectories(path, samples)
    read = read_trajectories(path)
    assert set(read) == {"a", "b"} and read["a"] == pytest.approx(samples["a"])
