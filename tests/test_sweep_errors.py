"""`golfflight sweep` fails clearly (issue 23, item 6): a file missing a launch column gets one line naming them and
the file; a chunk of which no row is valid is refused with a message that says so, or skipped and counted under
--skip-bad-rows; a NaN cell is "not a number" at its line and column; a missing extra is named in one line (exit 2);
Ray's noise line is filtered from standard error and nothing else is."""

from __future__ import annotations

import os
import sys

import pytest

from golfflight.cli import main

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

GRID = ["--grid", "ball_speed_mps=50", "launch_angle_deg=12", "spin_rpm=3000"]


def sweep(*argv) -> int:
    return main(["sweep", *map(str, argv), "--no-progress"])


@pytest.mark.parametrize("kind", ["csv", "parquet"])
def test_a_file_missing_launch_columns_gets_one_line_naming_them(tmp_path, capsys, kind):
    columns = {"ball_speed_mps": [55.0, 60.0], "launch_direction_deg": [0.0, 1.0]}
    source = tmp_path / f"launches.{kind}"
    if kind == "csv":
        source.write_text("ball_speed_mps,launch_direction_deg\n55,0\n60,1\n")
    else:
        pq.write_table(pa.table(columns), source)
    out = tmp_path / "out.parquet"
    assert sweep(source, "--out", out, "--workers", 1, "--skip-bad-rows") == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        (
            f"golfflight sweep: error: {source}: missing columns: launch_angle_deg, spin_rpm or back_spin_rpm (every row "
            "needs a ball speed, a launch angle and a spin)"
        )
    ]
    assert not out.exists()


def test_a_chunk_with_no_valid_row_is_refused_or_skipped_and_counted(tmp_path, capsys):
    """Rows 4 to 7 (the second chunk of 4) are all invalid: refused in so many words, or with --skip-bad-rows
    skipped whole and counted in the summary (it used to die unpacking an empty engine batch)."""
    lines = ["ball_speed_mps,launch_angle_deg,spin_rpm"]
    lines += [f"{50 + i},12,{99999 if 4 <= i < 8 else 3000}" for i in range(10)]
    source, out = tmp_path / "launches.csv", tmp_path / "out.parquet"
    source.write_text("\n".join(lines) + "\n")
    assert sweep(source, "--out", out, "--workers", 1, "--chunk-rows", 4) == 2
    err = capsys.readouterr().err
    assert "4 invalid values in rows 4 to 7 (none of the 4 rows is valid; nothing written" in err
    assert "launches.csv line 6 column 'spin_rpm': " in err and not out.exists()
    assert sweep(source, "--out", out, "--workers", 1, "--chunk-rows", 4, "--skip-bad-rows") == 0
    captured = capsys.readouterr()
    assert captured.err.count("golfflight sweep: skipped: ") == 4
    assert (
        "6 shots written" in captured.out
        and "(4 rows skipped, 1 of 3 chunks skipped whole for want of a valid row, 0 could not be flown)"
        in captured.out
    )
    table = pq.read_table(out)
    assert table["row"].to_pylist() == [0, 1, 2, 3, 8, 9] and table["error"].null_count == 6


def test_nan_is_not_a_number_at_its_line_and_column(tmp_path, capsys):
    """A CSV cell reading NaN was made a missing value ("Field required"); it is a number that is not one, as
    simulate reads it, and a Parquet float NaN is said the same way."""
    source, out = tmp_path / "launches.csv", tmp_path / "out.parquet"
    source.write_text(
        "ball_speed_mps,launch_angle_deg,spin_rpm,wind_speed_mps\n55,NaN,3000,\n60,12,nan,4\n55,16,3000,\n"
    )
    assert sweep(source, "--out", out, "--workers", 1) == 2
    err = capsys.readouterr().err
    assert "launches.csv line 2 column 'launch_angle_deg': not a number (got NaN)" in err
    assert "launches.csv line 3 column 'spin_rpm': not a number (got NaN)" in err
    assert "Field required" not in err and "spin: give exactly one" not in err
    from golfflight.sweep.flyer import problems_of

    assert problems_of({"ball_speed_mps": float("nan"), "launch_angle_deg": 12.0, "spin_rpm": 99999.0}) == [
        "column 'ball_speed_mps': not a number (got NaN)",
        "column 'spin_rpm': Input should be less than or equal to 15000 (got 99999.0); allowed 0 to 15000 rpm",
    ]


@pytest.mark.parametrize(
    ("hidden", "engine", "message"),
    [
        (
            "pyarrow",
            "local",
            "needs the sweep extra, which is not installed (no pyarrow): pip install 'golfflight[sweep]'",
        ),
        ("ray", "ray", "--engine ray needs the ray extra, which is not installed (no ray"),
    ],
)
def test_a_missing_extra_is_named_in_one_line(tmp_path, capfd, monkeypatch, hidden, engine, message):
    """The serving install has neither pyarrow nor Ray: a module that will not import stands for it."""
    for name in [m for m in sys.modules if m == hidden or m.startswith(hidden + ".")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, hidden, None)
    out = tmp_path / "out.parquet"
    assert sweep(*GRID, "--out", out, "--engine", engine, "--workers", 1) == 2
    err = capfd.readouterr().err
    assert len(err.splitlines()) == 1 and err.startswith(f"golfflight sweep: error: {message}"), err
    assert "Traceback" not in err and not out.exists()


def test_the_ray_noise_filter_drops_only_its_line(capfd):
    """Written to file descriptor 2 (as Ray's C++ core worker writes, in pieces): the noise line goes, a real
    core_worker error, other lines and a progress bar's carriage-return updates (brackets and all) come through, in
    order, and standard error is itself again after."""
    from golfflight.sweep.engines import RAY_NOISE, ray_noise_filtered

    noise = (
        f"[2026-11-26 05:44:54,560 E 27196 27196] core_worker.cc:2465: Actor with class name: 'MapWorker' and "
        f"ID: 'a7' {RAY_NOISE[0].decode()}. See https://github.com/ray-project/ray/issues/53727 for more details.\n"
    )
    real = "[2026-11-26 05:44:55,000 E 27196 27196] core_worker.cc:100: Failed to connect to the raylet\n"
    with ray_noise_filtered():
        os.write(2, b"\rsweep: 10% [00:01<00:09]")
        os.write(2, noise[:12].encode())
        os.write(2, noise[12:].encode() + b"\rsweep: 50% [00:05<00:05]")
        os.write(2, real.encode())
        os.write(2, b"a line\n")
    assert capfd.readouterr().err == f"\rsweep: 10% [00:01<00:09]\rsweep: 50% [00:05<00:05]{real}a line\n"
    os.write(2, noise.encode())
    assert capfd.readouterr().err == noise
