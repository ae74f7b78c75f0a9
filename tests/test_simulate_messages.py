"""`golfflight simulate` says what to fix (issue 31): a file missing a launch column is refused in one line naming
each missing column, as `golfflight sweep` refuses it (one check for both), with or without --skip-bad-rows; a run
with --skip-bad-rows of which no row is valid is refused instead of writing an empty file; every result carries the
input's row number, its launch columns as read and the air it was flown in (its air columns and the density), in
front of the result's; a canonical shot file is read as is; a shot given no spin names the spin columns, not
`column 'body'`."""

from __future__ import annotations

import csv
import json

import pytest

from golfflight.cli import main
from golfflight.contract.columns import KNOWN_COLUMNS, TEXT_COLUMNS
from golfflight.flight.air import air_density
from golfflight.flight.conditions import STANDARD
from golfflight.shots.records import COLUMNS

LAUNCHES = (
    "shot_id,ball_speed_mps,ball_speed_mph,launch_angle_deg,spin_rpm,spin_axis_deg,back_spin_rpm,side_spin_rpm\n"
    "a,60,,12,3000,2,,\n"
    "b,,140,14,,,3200,-200\n"
    "c,600,,14,3000,,,\n"
    "d,55,,16,,,,\n"
    "e,50,,20,6000,,,\n"
)
"""Five launches: three valid (lines 2, 3 and 6, rows 0, 1 and 4), one ball speed out of range, one without a spin."""


def written(path, text: str):
    path.write_text(text)
    return path


def results_csv(path) -> tuple[list[str], list[dict]]:
    with open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        return list(reader.fieldnames or []), list(reader)


@pytest.mark.parametrize("skip", [[], ["--skip-bad-rows"]])
def test_a_file_missing_the_launch_angle_column_is_refused_in_one_line_naming_it(tmp_path, capsys, skip):
    source = written(tmp_path / "launches.csv", "ball_speed_mps,spin_rpm\n" + "60,3000\n" * 2000)
    out = tmp_path / "results.csv"
    assert main(["simulate", str(source), "--out", str(out), *skip]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        (
            f"golfflight simulate: error: {source}: missing columns: launch_angle_deg (every row needs a ball speed, "
            "a launch angle and a spin)"
        )
    ]
    assert not out.exists()


def test_simulate_and_sweep_refuse_missing_columns_with_the_same_line(tmp_path, capsys):
    pytest.importorskip("pyarrow")
    source = written(tmp_path / "launches.csv", "ball_speed_mph,launch_direction_deg\n150,0\n")
    assert main(["simulate", str(source)]) == 2
    simulated = capsys.readouterr().err.removeprefix("golfflight simulate: error: ")
    assert main(["sweep", str(source), "--out", str(tmp_path / "out.parquet"), "--no-progress"]) == 2
    swept = capsys.readouterr().err.removeprefix("golfflight sweep: error: ")
    assert simulated == swept
    assert "missing columns: launch_angle_deg, spin_rpm or back_spin_rpm" in simulated


def test_a_misspelt_column_is_named_beside_the_one_it_leaves_missing(tmp_path, capsys):
    source = written(tmp_path / "launches.csv", "ball_speed_mps,launch_angle,spin_rpm\n60,12,3000\n")
    assert main(["simulate", str(source)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert "missing columns: launch_angle_deg" in line and "unknown columns ['launch_angle']" in line


@pytest.mark.parametrize("suffix", [".csv", ".json"])
def test_skipping_every_row_is_refused_and_writes_nothing(tmp_path, capsys, suffix):
    source = written(tmp_path / "launches.csv", "ball_speed_mps,launch_angle_deg,spin_rpm\n600,12,3000\n60,95,3000\n")
    out = tmp_path / f"results{suffix}"
    assert main(["simulate", str(source), "--out", str(out), "--skip-bad-rows"]) == 2
    err = capsys.readouterr().err
    assert "none of its 2 shots is valid; nothing written" in err
    assert "--skip-bad-rows flies the rest" not in err
    assert not out.exists()


def test_a_json_input_with_no_valid_shot_is_refused_under_skip_bad_rows_too(tmp_path, capsys):
    source = written(tmp_path / "shots.json", json.dumps([{"ball_speed_mps": 60, "launch_angle_deg": 12}]))
    assert main(["simulate", str(source), "--skip-bad-rows"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "none of its 1 shots is valid" in captured.err


def test_csv_results_start_with_the_row_number_and_the_launch_as_read(tmp_path, capsys):
    source = written(tmp_path / "launches.csv", LAUNCHES)
    out = tmp_path / "results.csv"
    assert main(["simulate", str(source), "--out", str(out), "--skip-bad-rows"]) == 0
    capsys.readouterr()
    header, rows = results_csv(out)
    launch = [
        "ball_speed_mps",
        "ball_speed_mph",
        "launch_angle_deg",
        "spin_rpm",
        "spin_axis_deg",
        "back_spin_rpm",
        "side_spin_rpm",
    ]
    assert header[: 4 + len(launch)] == ["row", "shot_id", *launch, "air_density_kg_m3", "landing_x_m"]
    assert [(r["row"], r["shot_id"]) for r in rows] == [("0", "a"), ("1", "b"), ("4", "e")]  # the data row, from 0
    assert {k: rows[1][k] for k in launch} == {
        "ball_speed_mps": "",
        "ball_speed_mph": "140.0",
        "launch_angle_deg": "14.0",
        "spin_rpm": "",
        "spin_axis_deg": "",
        "back_spin_rpm": "3200.0",
        "side_spin_rpm": "-200.0",
    }
    assert float(rows[2]["ball_speed_mps"]) == 50.0 and float(rows[2]["carry_m"]) > 0


def test_json_results_start_with_the_row_number_and_the_launch_as_read(tmp_path, capsys):
    shots = [
        {"ball_speed_mph": 171, "launch_angle_deg": 10.4, "back_spin_rpm": 2545},
        {"ball_speed_mps": 500, "launch_angle_deg": 16, "spin_rpm": 7100},
        {"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "wind": {"speed_mps": 3}},
    ]
    source = written(tmp_path / "shots.json", json.dumps({"shots": shots}))
    assert main(["simulate", str(source), "--skip-bad-rows"]) == 0
    results = json.loads(capsys.readouterr().out)["results"]
    assert [list(r)[:4] for r in results] == [
        ["row", "ball_speed_mph", "launch_angle_deg", "back_spin_rpm"],
        ["row", "ball_speed_mps", "launch_angle_deg", "spin_rpm"],
    ]
    assert [r["row"] for r in results] == [0, 2] and results[0]["ball_speed_mph"] == 171
    assert "wind" not in results[1] and results[1]["carry_m"] > 0


def test_every_result_says_the_air_it_was_flown_in(tmp_path, capsys):
    """The air columns as given, then the density flown: the weather's, the one given, or ICAO standard air."""
    source = written(
        tmp_path / "launches.csv",
        "ball_speed_mps,launch_angle_deg,spin_rpm,temperature_c,pressure_hpa,humidity_pct,density_kg_m3\n"
        "60,12,3000,30,900,50,\n"
        "60,12,3000,,,,1.05\n"
        "60,12,3000,,,,\n",
    )
    out = tmp_path / "results.csv"
    assert main(["simulate", str(source), "--out", str(out)]) == 0
    header, (hot, given, standard) = results_csv(out)
    air = ["temperature_c", "pressure_hpa", "humidity_pct", "density_kg_m3", "air_density_kg_m3"]
    assert header[4 : 4 + len(air)] == air and header[4 + len(air)] == "landing_x_m"
    assert float(hot["air_density_kg_m3"]) == pytest.approx(float(air_density(30.0, 90000.0, 50.0)), rel=1e-12)
    assert (given["temperature_c"], float(given["air_density_kg_m3"])) == ("", 1.05)
    assert float(standard["air_density_kg_m3"]) == STANDARD.air.density_kg_m3 == pytest.approx(1.225, abs=1e-4)
    assert len({hot["carry_m"], given["carry_m"], standard["carry_m"]}) == 3
    assert main(["simulate", str(source)]) == 0
    flown = json.loads(capsys.readouterr().out)["results"]
    written_out = [float(row["air_density_kg_m3"]) for row in (hot, given, standard)]
    assert [r["air_density_kg_m3"] for r in flown] == written_out
    assert "temperature_c" in flown[0] and "temperature_c" not in flown[2]


def test_a_canonical_shot_file_is_read_as_is():
    """Every canonical column is one simulate and sweep take: identity and outcome ones are passed over."""
    assert set(COLUMNS) <= KNOWN_COLUMNS and {"source", "group", "ball"} <= TEXT_COLUMNS


def test_a_csv_input_written_as_json_carries_row_and_shot_id(tmp_path, capsys):
    source = written(tmp_path / "launches.csv", LAUNCHES)
    assert main(["simulate", str(source), "--skip-bad-rows"]) == 0
    results = json.loads(capsys.readouterr().out)["results"]
    assert [(r["row"], r["shot_id"], r["launch_angle_deg"]) for r in results] == [
        (0, "a", 12.0),
        (1, "b", 14.0),
        (4, "e", 20.0),
    ]


def test_a_shot_without_a_spin_names_the_spin_columns(tmp_path, capsys):
    source = written(tmp_path / "launches.csv", LAUNCHES)
    assert main(["simulate", str(source)]) == 2
    err = capsys.readouterr().err
    assert "column 'body'" not in err
    assert f"{source} line 5 spin columns: give exactly one of spin_rpm or back_spin_rpm (neither given)" in err
    assert f"{source} line 4 column 'ball_speed_mps': " in err


def test_a_json_shot_without_a_spin_names_the_spin_fields(tmp_path, capsys):
    source = written(tmp_path / "shots.json", json.dumps([{"ball_speed_mps": 60, "launch_angle_deg": 12}, 7]))
    assert main(["simulate", str(source)]) == 2
    err = capsys.readouterr().err
    assert "field 'body'" not in err
    assert f"{source} shot 0 spin fields: give exactly one of spin_rpm or back_spin_rpm (got none)" in err
    assert f"{source} shot 1 as a whole: Input should be a valid dictionary" in err
