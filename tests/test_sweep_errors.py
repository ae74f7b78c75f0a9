"""`golfflight sweep` fails clearly (issue 23, item 6): a file missing a launch column gets one line naming them and
the file; a chunk of which no row is valid is refused with a message that says so, or skipped and counted under
--skip-bad-rows; a NaN cell is "not a number" at its line and column; a missing extra is named in one line (exit 2);
Ray's noise line is filtered from standard error and nothing else is."""

from __future__ import annotations

import os
import sys

import numpy as np
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
    from golfflight.contract.columns import check_cells

    assert check_cells({"ball_speed_mps": float("nan"), "launch_angle_deg": 12.0, "spin_rpm": 99999.0}) == [
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


def per_row(table) -> list:
    """Each row of `table` through the request model on its own (`check_cells`): its request, or its problem lines."""
    from golfflight.contract.columns import cell_value
    from golfflight.contract.columns import check_cells

    return [check_cells({k: cell_value(v) for k, v in row.items()}) for row in table.to_pylist()]


def assert_checked_as_per_row(table) -> None:
    """The columnar check (`sweep.rows.check_rows`) gives every row the per-row verdict and, for a refused row, the
    same problem lines (each naming its column and range)."""
    from golfflight.sweep.rows import check_rows

    checked = check_rows(table)
    for i, want in enumerate(per_row(table)):
        assert bool(checked.valid[i]) == (not isinstance(want, list)), (i, table.slice(i, 1).to_pylist(), want)
        assert checked.problems.get(i) == (want if isinstance(want, list) else None), i


POOLS = {
    "ball_speed_mps": ["55", "0.5", "100", "100.00001", "0.49", "NaN", "nan", "inf", "-inf", "fast", "", " 60 ", "1_0"],
    "ball_speed_mph": ["", "", "", "120", "300", "1e9"],
    "launch_angle_deg": ["12", "-0", "-0.0", "", "90", "91", "-91", "abc"],
    "launch_direction_deg": ["", "3", "-46", "45"],
    "spin_rpm": ["3000", "", "15000", "15001", "-1", "NaN"],
    "spin_axis_deg": ["", "-0.0", "10", "90", "91"],
    "back_spin_rpm": ["", "", "14000", "3000", "15000"],
    "side_spin_rpm": ["", "", "9000", "-400", "-0.0"],
    "altitude_m": ["", "1600", "-600", "6000", "x"],
    "altitude_ft": ["", "", "5000"],
    "pressure_hpa": ["", "", "850"],
    "density_kg_m3": ["", "", "", "1.1", "9"],
    "temperature_c": ["", "31", "-60"],
    "wind_speed_mps": ["", "4", "30", "31"],
    "wind_speed_mph": ["", "", "10"],
    "wind_from_deg": ["", "90", "361"],
    "wind_profile": ["", "log", " log ", "uniform", "gusty", "1"],
    "ground_surface": ["", "green", "fairway", "bunker", "sand", " rough"],
    "stimp_ft": ["", "", "12", "30"],
    "ground_elevation_m": ["", "-3", "0", "90"],
    "ground_elevation_ft": ["", "", "10"],
    "slope_deg": ["", "0", "2", "5", "45"],
    "slope_dir_deg": ["", "90"],
    "normalized": ["", "true", "1", "no", "YES"],
    "shot_id": ["a", ""],
}
"""Cells of a launches CSV, valid and not, for every request column: the edges of each range and just past them,
NaN, infinities, words, blanks, whitespace, both forms of a quantity at once, cross-field rules (back and side spin
over the total, a stimp reading off the green, a slope steeper than its surface holds, density with weather)."""


@pytest.mark.parametrize("form", ["text", "typed"])
def test_the_columnar_check_gives_every_row_the_models_verdict_and_lines(form):
    """2,000 random rows drawn from POOLS, as a CSV reads them (text) and as a Parquet file holds them (numbers typed,
    a few words left in number columns, booleans and integers): the same verdict and problem lines as the request
    model on each row alone. Most rows are refused, for one reason or several."""
    from golfflight.contract.columns import TEXT_COLUMNS, cell_value

    rng = np.random.default_rng(7)
    rows = [{column: str(rng.choice(cells)) for column, cells in POOLS.items()} for _ in range(2000)]
    for row in rows[::2]:  # half the rows valid but for three cells drawn from the pools
        drawn = {c: row[c] for c in rng.choice(list(POOLS), 3, replace=False)}
        row.update({c: "" for c in POOLS})
        row.update(ball_speed_mps=str(rng.uniform(1, 99)), launch_angle_deg="11", spin_rpm=str(rng.uniform(0, 15000)))
        row.update(drawn)
    if form == "text":
        table = pa.table({c: [None if r[c] == "" else r[c] for r in rows] for c in POOLS})
    else:
        def typed(column, cell):
            value = cell_value(cell)
            if column in TEXT_COLUMNS or value is None or column == "normalized":
                return None if value is None else cell
            return float(value) if isinstance(value, float) else None
        columns = {c: [typed(c, r[c]) for r in rows] for c in POOLS}
        columns["launch_direction_deg"] = [None if v is None else int(v) for v in columns["launch_direction_deg"]]
        table = pa.table(columns)
        table = table.append_column("wind_reference_height_m", pa.array([True if i % 50 == 0 else None for i in range(2000)]))
    assert_checked_as_per_row(table)
    from golfflight.sweep.rows import check_rows

    valid = check_rows(table).valid
    assert 100 < valid.sum() < 1900  # both verdicts well represented


def test_the_cross_field_rules_read_only_presence_and_the_value_rule_columns():
    """The columnar check groups rows by which columns they give and by VALUE_RULE_COLUMNS' values, and lets one row a
    group decide for it: that holds while the request models' validators read no other field's value. Read from
    their source: a field read as `self.NAME` other than `is (not) None` must be a value-rule column; helpers called
    with the model, and a before-validator's data, test presence only."""
    import inspect
    import re

    from golfflight.contract import requests
    from golfflight.contract.columns import SECTION_COLUMNS
    from golfflight.sweep.rows import VALUE_RULE_COLUMNS

    def column(model, field: str) -> str:
        for section, columns in SECTION_COLUMNS.items():
            if model is getattr(requests, f"{section.capitalize()}Request", None):
                return {name: c for c, name in columns.items()}[field]
        return field

    models = [requests.ShotRequest, requests.AirRequest, requests.WindRequest, requests.GroundRequest]
    for model in models:
        for decorator in model.__pydantic_decorators__.model_validators.values():
            source = inspect.getsource(decorator.func)
            for name in re.findall(r"self\.(\w+)\b(?! is (?:not )?None)", source):
                assert column(model, name) in VALUE_RULE_COLUMNS, (model.__name__, name)
            assert re.findall(r"getattr\(self, \w+\)(?! is not None)", source) == [], model.__name__
            for helper in set(re.findall(r"(?<!def )\b(\w+)\(self\b", source)) - {"getattr"}:
                body = inspect.getsource(getattr(requests, helper))
                assert re.findall(r"getattr\(model, \w+\)(?! is not None)", body) == [], helper
                assert "model." not in body, helper
            for read in re.findall(r"data(?:\.get\([^)]*\)|\[[^]]*\])( is not None)?", source):
                assert read, (model.__name__, source)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (
            ["--engine", "ray", "--device", "cuda:1"],
            "--device cuda:1: with --engine ray, Ray gives each actor its own GPU; give --device cuda (or cpu)",
        ),
        (
            ["--engine", "ray", "--threads", "2"],
            "--threads goes with --engine ray only beside --device (cuda or cpu): the torch engine",
        ),
        (["--engine", "local", "--device", "cuda"], "--device goes with --engine torch, or --engine ray"),
        (["--engine", "local", "--dtype", "float64"], "--dtype goes with --engine torch, or --engine ray with --device"),
        (["--engine", "ray", "--device", "cpu", "--actors-per-gpu", "2"],
         "--actors-per-gpu goes with --engine ray --device cuda"),
        (["--engine", "torch", "--actors-per-gpu", "2"], "--actors-per-gpu goes with --engine ray --device cuda"),
        (["--engine", "ray", "--device", "cuda", "--actors-per-gpu", "0"],
         "--actors-per-gpu takes a whole number of at least 1"),
    ],
)
def test_torch_options_that_do_not_go_with_the_engine_are_refused(tmp_path, capsys, options, message):
    pytest.importorskip("ray")
    assert sweep(*GRID, "--out", tmp_path / "out.parquet", *options) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [f"golfflight sweep: error: {message}"], err


def test_ray_on_gpus_without_torch_is_refused_in_one_line(tmp_path, capfd, monkeypatch):
    """The driver needs torch to send the actors their engine: without the train extra, one line saying so."""
    pytest.importorskip("ray")
    for name in [m for m in sys.modules if m == "torch" or m.startswith("torch.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "torch", None)
    assert sweep(*GRID, "--out", tmp_path / "out.parquet", "--engine", "ray", "--device", "cuda") == 2
    assert capfd.readouterr().err.splitlines() == [
        (
            "golfflight sweep: error: --engine ray --device needs the train extra, which is not installed (no torch): "
            "pip install 'golfflight[train]'"
        )
    ]


def test_gpu_actors_are_what_the_gpus_hold_and_never_more_than_the_cluster_lists():
    from golfflight.sweep.engines import gpu_actors

    assert gpu_actors({"CPU": 16.0, "GPU": 4.0}, None, 1) == 4
    assert gpu_actors({"CPU": 16.0, "GPU": 4.0}, 2, 1) == 2
    assert gpu_actors({"CPU": 16.0, "GPU": 4.0}, None, 1 / 3) == 12
    assert gpu_actors({"CPU": 3.0, "GPU": 1.0}, None, 0.5) == 2
    with pytest.raises(ValueError, match=r"--workers 5: the Ray cluster lists 4 GPUs, and each actor takes 1 "
                                         r"\(leave --workers out for 4 actors\)"):
        gpu_actors({"CPU": 16.0, "GPU": 4.0}, 5, 1)
    with pytest.raises(ValueError, match=r"--workers 3: the Ray cluster lists 1 GPUs, and each actor takes 0.5"):
        gpu_actors({"CPU": 16.0, "GPU": 1.0}, 3, 0.5)
    # A GPU actor takes a CPU too, and reading one more: two actors on 2 CPUs would wait for ever.
    assert gpu_actors({"CPU": 2.0, "GPU": 1.0}, None, 0.5) == 1
    with pytest.raises(ValueError, match=r"--workers 2: the Ray cluster lists 2 CPUs, and each actor takes one "
                                         r"beside the one that reads \(leave --workers out for 1 actors\)"):
        gpu_actors({"CPU": 2.0, "GPU": 1.0}, 2, 0.5)
    with pytest.raises(ValueError, match=r"lists 1 CPUs; each GPU actor takes one and reading the launches one more"):
        gpu_actors({"CPU": 1.0, "GPU": 1.0}, None, 1)
    with pytest.raises(ValueError, match=r"the Ray cluster lists no GPU \(ray.cluster_resources\(\) has none\)"):
        gpu_actors({"CPU": 16.0}, None, 1)


@pytest.mark.parametrize("collide", [False, True], ids=["hashed", "every hash equal: grouped by the keys"])
def test_rows_are_grouped_by_equal_keys_whatever_their_hashes(monkeypatch, collide):
    """`sweep.rows._groups`: rows with equal values in every part share a group and no others do, each group's row
    the first of its rows; where hashes collide (forced here: every row's hash equal) the keys themselves decide."""
    from golfflight.sweep import rows

    if collide:
        monkeypatch.setattr(rows, "MIX", np.uint64(0))
    rng = np.random.default_rng(5)
    parts = [rng.integers(0, 3, 500).astype(np.int64), rng.integers(-2, 2, 500).astype(np.int64) * 2**40,
             np.where(rng.random(500) < 0.5, np.float64(1.5).view(np.int64), 0)]
    chosen = np.flatnonzero(rng.random(500) < 0.8)
    firsts, group = rows._groups(parts, chosen)
    keys = [tuple(int(part[i]) for part in parts) for i in chosen.tolist()]
    expected_first = {}
    for row, key in zip(chosen.tolist(), keys, strict=True):
        expected_first.setdefault(key, row)
    assert sorted(firsts.tolist()) == sorted(expected_first.values())
    for row, key, g in zip(chosen.tolist(), keys, group.tolist(), strict=True):
        assert firsts[g] == expected_first[key], row
