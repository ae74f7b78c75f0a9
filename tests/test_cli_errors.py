"""Every command that reads a file answers a bad one with one error line naming it (exit 2), never a traceback;
--skip-bad-rows processes a file with a few bad rows and lists each one."""

from __future__ import annotations

import json

import pytest

from golfflight.cli import main

LAUNCH = "ball_speed_mps,launch_angle_deg,launch_direction_deg,spin_rpm,spin_axis_deg"


def bad_files(tmp_path):
    files = {
        "missing": tmp_path / "missing.csv",
        "directory": tmp_path / "folder",
        "binary": tmp_path / "binary.csv",
        "empty": tmp_path / "empty.csv",
        "nul": tmp_path / "nul.csv",
        "bad_cell": tmp_path / "bad_cell.csv",
    }
    files["directory"].mkdir()
    files["binary"].write_bytes(bytes(range(128, 256)) * 8)
    files["empty"].write_text("")
    files["nul"].write_bytes(b"a,b\x00,c\n1,2,3\n")
    files["bad_cell"].write_text(f"{LAUNCH},split\n70,11,0,2600,0,train\nfast,11,0,2600,0,val\n")
    return files


COMMANDS = {
    "simulate": lambda f, out: ["simulate", str(f)],
    "convert trackman": lambda f, out: ["convert", "trackman", str(f), "--out", str(out / "o.csv")],
    "convert tourcast": lambda f, out: ["convert", "tourcast", str(f), "--out", str(out / "o.csv")],
    "convert pbp": lambda f, out: ["convert", "pbp", str(f), "--out", str(out / "o.csv")],
    "convert garmin": lambda f, out: ["convert", "garmin", str(f), "--out", str(out / "o.csv")],
    "train": lambda f, out: ["train", "--data", str(f), "--out", str(out / "run"), "--epochs", "1"],
    "export": lambda f, out: ["export", "--checkpoint", str(f), "--out", str(out / "bundle")],
    "serve": lambda f, out: ["serve", "--model", str(f), "--port", "9"],
}


@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_bad_file_gets_one_line_naming_it(command, tmp_path, capsys):
    for kind, path in bad_files(tmp_path).items():
        assert main(COMMANDS[command](path, tmp_path)) == 2, (command, kind)
        err = capsys.readouterr().err
        first = err.splitlines()[0]
        assert first.startswith(f"golfflight {command.split()[0]}: error: "), (command, kind, err)
        assert path.name in first, (command, kind, err)
        assert "Traceback" not in err


def test_simulate_names_line_and_column_and_skips_bad_rows_on_request(tmp_path, capsys):
    source = tmp_path / "launches.csv"
    source.write_text(
        f"shot_id,{LAUNCH},wind_speed_mps\n"
        "a,55,16,0,7100,0,\n"
        "b,55,16,0,99999,0,\n"
        "c,55,16,0,7100,0,45\n"
        "a,55,16,0,7100,0,\n"
        "d,55,16,0,7100,0,,extra\n"
        "e,fast,16,0,7100,0,\n"
        "f,40,12,0,5000,0,\n"
    )
    assert main(["simulate", str(source)]) == 2
    err = capsys.readouterr().err
    assert "5 invalid values" in err
    assert "launches.csv line 3 column 'spin_rpm': " in err and "allowed 0 to 15000 rpm" in err
    assert "launches.csv line 4 column 'wind_speed_mps': " in err and "allowed 0 to 30 m/s" in err
    assert "launches.csv line 5 column 'shot_id': 'a' duplicates the shot_id of line 2" in err
    assert "launches.csv line 6: 1 cells beyond the header" in err
    assert "launches.csv line 7 column 'ball_speed_mps': " in err and "'fast'" in err
    assert main(["simulate", str(source), "--skip-bad-rows"]) == 0
    captured = capsys.readouterr()
    assert captured.err.count("golfflight simulate: skipped: ") == 5
    assert [r["shot_id"] for r in json.loads(captured.out)["results"]] == ["a", "f"]


def test_train_skips_bad_rows_on_request_and_lists_each(tiny_shots, tmp_path, capsys):
    lines = tiny_shots.read_text().splitlines()
    header = lines[0].split(",")
    broken = lines[3].split(",")
    broken[header.index("spin_rpm")] = "lots"
    data = tmp_path / "data.csv"
    data.write_text("\n".join([*lines[:3], ",".join(broken), *lines[4:]]) + "\n")
    argv = ["train", "--data", str(data), "--out", str(tmp_path / "run"), "--epochs", "1", "--variant", "phys-q",
            "--limit", "40", "--threads", "1"]
    assert main(argv) == 2
    assert "data.csv line 4 column 'spin_rpm': 'lots' is not a number" in capsys.readouterr().err
    assert main([*argv, "--skip-bad-rows"]) == 0
    out = capsys.readouterr().out
    assert "skipped bad row: " in out and "line 4 column 'spin_rpm'" in out and "'bad_rows': 1" in out
