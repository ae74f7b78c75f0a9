"""`golfflight sweep`: grids, files (CSV and Parquet) and both engines give the numbers `golfflight simulate` gives
for the same rows, streamed in chunks; bad rows are refused with their place, column and range (nothing written)
or skipped on request. Real engines throughout: spawned processes, a local Ray instance, ONNX Runtime."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from golfflight.contract.columns import TEXT_COLUMNS
from golfflight.sweep.grid import Grid, GridError, parse_axis

from golfflight.cli import main

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

CONDITIONS = ("altitude_m", "temperature_c", "wind_speed_mps", "wind_from_deg", "wind_profile", "normalized",
              "ground_elevation_m", "ground_surface")


def launch_rows(n: int, seed: int = 0) -> list[dict]:
    """Mixed launches and conditions in every form simulate's CSV takes (mph and back/side spin on some rows, blank
    cells, the canonical file's observed apex_m), wedges to drivers."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        speed = rng.uniform(30.0, 75.0)
        row = {"shot_id": f"s{i}", "ball_speed_mps": speed, "ball_speed_mph": "",
               "launch_angle_deg": rng.uniform(9.0, 25.0), "launch_direction_deg": rng.uniform(-5.0, 5.0),
               "spin_rpm": rng.uniform(2000.0, 8000.0), "spin_axis_deg": rng.uniform(-15.0, 15.0),
               "back_spin_rpm": "", "side_spin_rpm": "", "apex_m": rng.uniform(5.0, 30.0),
               "altitude_m": rng.choice([0.0, 1600.0]), "temperature_c": "", "wind_speed_mps": rng.uniform(0.0, 8.0),
               "wind_from_deg": rng.uniform(0.0, 360.0), "wind_profile": rng.choice(["uniform", "log"]),
               "normalized": "true" if i % 7 == 0 else "", "ground_elevation_m": rng.choice([0.0, -4.0, 3.0]),
               "ground_surface": rng.choice(["fairway", "green", ""])}
        if i % 5 == 1:
            row.update(ball_speed_mps="", ball_speed_mph=speed / 0.44704, spin_rpm="", spin_axis_deg="",
                       back_spin_rpm=3000.0, side_spin_rpm=-400.0, temperature_c=31.0)
        rows.append(row)
    return rows


def write_csv(path, rows: list[dict]):
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, rows[0].keys())
        writer.writeheader()
        writer.writerows(rows)
    return path


def simulated(tmp_path, source) -> list[dict]:
    """`golfflight simulate`'s CSV results for `source`, numbers as floats (words, as the echoed wind profile or
    surface, as text)."""
    out = tmp_path / "simulated.csv"
    assert main(["simulate", str(source), "--out", str(out)]) == 0
    with open(out) as handle:
        return [{k: v if k in ("shot_id", "error") or k in TEXT_COLUMNS else float(v) for k, v in r.items() if v != ""}
                for r in csv.DictReader(handle)]


def assert_same_as_simulate(swept: list[dict], expected: list[dict], sample: int = 60) -> None:
    """Every figure simulate gives for a sample of rows is in the sweep's row, equal to float rounding."""
    assert len(swept) == len(expected)
    for i in np.random.default_rng(1).choice(len(expected), min(sample, len(expected)), replace=False):
        row, want = swept[i], expected[i]
        assert row["shot_id"] == want["shot_id"] and row["row"] == i
        for key, value in want.items():
            if isinstance(value, str):
                assert row[key] == value, (i, key)
            else:
                assert row[key] == pytest.approx(value, rel=1e-9, abs=1e-9), (i, key)
        flown = {k for k, v in row.items() if v is not None and k.startswith(("normalized_", "flat_"))}
        assert flown == {k for k in want if k.startswith(("normalized_", "flat_"))}, i


@pytest.fixture(scope="module")
def launches(tmp_path_factory):
    """300 launches as CSV, and as Parquet with numbers typed, with simulate's results for them."""
    folder = tmp_path_factory.mktemp("launches")
    rows = launch_rows(300)
    source = write_csv(folder / "launches.csv", rows)
    typed = [{k: (None if v == "" else v) for k, v in row.items()} for row in rows]
    parquet = folder / "launches.parquet"
    pq.write_table(pa.Table.from_pylist(typed), parquet)
    return source, parquet, simulated(folder, source)


def sweep(*argv) -> int:
    return main(["sweep", *map(str, argv), "--no-progress"])


def test_grid_axes_ranges_lists_and_single_values():
    assert parse_axis("ball_speed_mps=30:80:11").values == tuple(30.0 + 5.0 * i for i in range(11))
    assert parse_axis("wind_from_deg=0, 90,180").values == (0.0, 90.0, 180.0)
    assert parse_axis("ground_surface=fairway,green").values == ("fairway", "green")
    assert parse_axis("altitude_m=1600").values == (1600.0,)
    grid = Grid.parse(["ball_speed_mps=40:60:3", "launch_angle_deg=10,14", "spin_rpm=3000"])
    assert len(grid) == 6 and grid.columns == ["ball_speed_mps", "launch_angle_deg", "spin_rpm"]
    rows = grid.rows(0, 6)
    assert rows["ball_speed_mps"] == [40.0, 40.0, 50.0, 50.0, 60.0, 60.0]  # the first axis varies slowest
    assert rows["launch_angle_deg"] == [10.0, 14.0] * 3
    assert grid.rows(3, 5) == {k: v[3:5] for k, v in rows.items()}
    worded = Grid.parse(["ball_speed_mps=40:60:3", "launch_angle_deg=10,14", "spin_rpm=3000", "ground_surface=green,rough"])
    assert pa.table(worded.arrays(2, 11)).equals(pa.table(worded.rows(2, 11)))  # what a sweep reads, as Arrow reads rows


@pytest.mark.parametrize(
    ("axes", "message"),
    [
        (["ball_speed_mps"], "COLUMN=START:STOP:COUNT"),
        (["club_speed_mph=1:2:3"], "not a launch or condition column"),
        (["ball_speed_mps=30:80"], "START:STOP:COUNT"),
        (["ball_speed_mps=30:80:2.5"], "whole number"),
        (["ball_speed_mps=30:fast:3"], "'fast' is not a number"),
        (["ball_speed_mps=30,30"], "listed twice"),
        (["ball_speed_mps=40", "ball_speed_mps=50", "launch_angle_deg=10", "spin_rpm=3000"], "more than once"),
        (["launch_angle_deg=10", "spin_rpm=3000"], "ball speed columns: give exactly one of"),
        (["ball_speed_mps=40:120:3", "launch_angle_deg=10", "spin_rpm=3000"],
         ("--grid ball_speed_mps=120.0: column 'ball_speed_mps': Input should be less than or equal to 100 "
          "(got 120.0); allowed 0.5 to 100 m/s")),
    ],
)
def test_grid_errors_name_the_axis_and_the_allowed_range(axes, message):
    with pytest.raises(GridError) as refused:
        Grid.parse(axes)
    assert message in str(refused.value)


def test_a_grid_is_written_in_chunks_in_order(tmp_path, capsys):
    out = tmp_path / "grid.parquet"
    axes = ["ball_speed_mps=40:70:25", "launch_angle_deg=8:20:4", "spin_rpm=2500,5000", "wind_from_deg=0,180",
            "wind_speed_mps=5", "ground_surface=green,rough"]
    assert sweep("--grid", *axes, "--out", out, "--workers", 2, "--chunk-rows", 64) == 0
    assert "800 shots written" in capsys.readouterr().out
    written = pq.ParquetFile(out)
    assert written.metadata.num_rows == 800 and written.metadata.num_row_groups == math.ceil(800 / 64)
    table = written.read()
    assert table["row"].to_pylist() == list(range(800))
    assert table.column_names[:7] == ["row", "ball_speed_mps", "launch_angle_deg", "spin_rpm", "wind_from_deg",
                                      "wind_speed_mps", "ground_surface"]
    assert table["ground_surface"].to_pylist()[:4] == ["green", "rough", "green", "rough"]
    assert table["error"].null_count == 800 and min(table["carry_m"].to_pylist()) > 50
    drives = {(r["wind_from_deg"], r["ground_surface"]): r for r in table.to_pylist()
              if r["ball_speed_mps"] == 70 and r["launch_angle_deg"] == 12 and r["spin_rpm"] == 2500}
    assert drives[0.0, "green"]["carry_m"] + 10 < drives[180.0, "green"]["carry_m"]  # 5 m/s of head and tail wind
    assert drives[180.0, "rough"]["roll_m"] < drives[180.0, "green"]["roll_m"]


def requested_columns(engine, shots):
    """The columns of the requests' engine batch (`contract.flying.batch_of`, `FlightEngine.fly_batch`,
    `columns_of`): the flat path flown from requests made one by one."""
    from golfflight.contract.flying import batch_of, columns_of

    batch = batch_of(shots)
    return columns_of(engine.fly_batch(batch.problem), batch)


def test_the_column_path_gives_fly_requests_numbers_bit_for_bit():
    """The flat path (`requested_columns`: the engine batch straight into columns) and `fly_requests` (a result
    object a shot, as simulate and the HTTP batch route) fly the same batch: every number equal, not just close,
    each column present exactly where the shot's flat row has it, the same errors (a ground the ball never reaches
    fails its shot alone), and the air density each flew in is the one simulate echoes."""
    from golfflight.commands.simulate_io import flown_air
    from golfflight.contract.columns import AIR_DENSITY, cell_value, check, flat_row, request_of_cells
    from golfflight.contract.flying import fly_requests
    from golfflight.flight.bundle_location import model_dir
    from golfflight.flight.engine import FlightEngine

    rows = launch_rows(200, seed=3)
    rows[5].update(ground_elevation_m=90.0)  # never rises that high: a FlightError for this shot only
    rows[12].update(ground_elevation_m=90.0, normalized="true")
    shots = [check(request_of_cells({k: cell_value(v) for k, v in row.items()})) for row in rows]
    assert all(not isinstance(shot, list) for shot in shots)
    engine = FlightEngine(model_dir(None), batch_threads=1)
    expected = [flat_row(result.model_dump(exclude_none=True)) for result in fly_requests(engine, shots)[0]]
    columns = requested_columns(engine, shots)
    assert columns.errors[5] is not None and columns.errors[12] is not None
    for i, want in enumerate(expected):
        assert columns.errors[i] == want.get("error"), i
        got = {name: values[i].item() for name, values in columns.values.items() if columns.present[name][i]}
        assert got.pop(AIR_DENSITY) == flown_air(shots[i])[AIR_DENSITY], i
        assert got == {k: v for k, v in want.items() if k != "error"}, i
        assert all(type(got[k]) is type(v) for k, v in want.items() if k != "error"), i


def test_local_sweep_of_csv_and_parquet_equals_simulate(launches, tmp_path):
    source, parquet, expected = launches
    for name, path in (("csv", source), ("parquet", parquet)):
        out = tmp_path / f"{name}.parquet"
        assert sweep(path, "--out", out, "--workers", 2, "--chunk-rows", 64) == 0
        table = pq.read_table(out)
        assert "observed_apex_m" in table.column_names  # the file's apex beside the flown one
        assert_same_as_simulate(table.to_pylist(), expected)


def test_a_bad_row_refuses_the_sweep_with_its_line_column_and_range(launches, tmp_path, capsys):
    rows = launch_rows(40)
    rows[3]["spin_rpm"], rows[17]["wind_speed_mps"], rows[30]["ball_speed_mps"] = 99999, 45, "fast"
    source, out = write_csv(tmp_path / "bad.csv", rows), tmp_path / "out.parquet"
    assert sweep(source, "--out", out, "--workers", 1, "--chunk-rows", 16) == 2
    err = capsys.readouterr().err
    assert "golfflight sweep: error: 1 invalid values in rows 0 to 15 (nothing written" in err
    assert "bad.csv line 5 column 'spin_rpm': " in err and "allowed 0 to 15000 rpm" in err
    assert not out.exists() and list(tmp_path.iterdir()) == [source]  # no result and no temporary file
    assert sweep(source, "--out", out, "--workers", 1, "--chunk-rows", 16, "--skip-bad-rows") == 0
    captured = capsys.readouterr()
    assert captured.err.count("golfflight sweep: skipped: ") == 3
    assert "bad.csv line 19 column 'wind_speed_mps': " in captured.err and "allowed 0 to 30 m/s" in captured.err
    assert "bad.csv line 32 column 'ball_speed_mps': " in captured.err and "'fast'" in captured.err
    assert "37 shots written" in captured.out and "3 rows skipped" in captured.out
    assert pq.read_table(out)["row"].to_pylist() == [i for i in range(40) if i not in (3, 17, 30)]


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("ball_speed_mps,launch_angle_deg,spin_rpm,club_head_mph\n55,16,7100,90\n", "unknown columns ['club_head_mph']"),
        ("", "no header row"),
    ],
)
def test_a_file_that_cannot_be_swept_gets_one_line(tmp_path, capsys, content, message):
    source = tmp_path / "launches.csv"
    source.write_text(content)
    assert sweep(source, "--out", tmp_path / "out.parquet") == 2
    assert message in capsys.readouterr().err
    assert sweep(tmp_path / "missing.csv", "--out", tmp_path / "out.parquet") == 2
    assert sweep(source, "--grid", "spin_rpm=3000", "--out", tmp_path / "out.parquet") == 2
    assert "one of the two" in capsys.readouterr().err


def test_ray_sweep_with_two_actors_equals_simulate(launches, tmp_path, capfd, recwarn):
    """The command starts a local Ray instance (2 actors, a CPU for the read task) and stops it after. Both engines
    read every source through the same `pieces()` and fly it with the same `SweepWorker`, so one CSV of 300 rows in 5
    chunks over 2 actors stands for the sources here. No deprecated Ray argument (`ray_remote_args`, gone in Ray
    2.64) and no `E ... core_worker` line about Ray Data's own actors on standard error."""
    ray = pytest.importorskip("ray")
    source, _, expected = launches
    out = tmp_path / "csv.parquet"
    assert sweep(source, "--out", out, "--engine", "ray", "--workers", 2, "--chunk-rows", 64) == 0
    assert not ray.is_initialized()
    err = capfd.readouterr().err
    assert "core_worker" not in err and "max_restarts" not in err, err
    assert not [w for w in recwarn if "ray_remote_args" in str(w.message)]
    assert_same_as_simulate(pq.read_table(out).to_pylist(), expected)


def assert_columnar_flights_equal_requested(table) -> int:
    """The columnar path (`sweep.rows`: checked in bulk, launches in arrays, conditions once each) flies a chunk's
    valid rows to the very numbers `requested_columns` gives for their requests made one by one: bit for bit, each
    column present where it was, the same errors. Returns the rows flown."""
    from golfflight.contract.columns import cell_value
    from golfflight.flight.bundle_location import model_dir
    from golfflight.flight.engine import FlightEngine
    from golfflight.contract.columns import check_cells
    from golfflight.sweep.rows import check_rows, fly_checked

    shots = [check_cells({k: cell_value(v) for k, v in row.items()}) for row in table.to_pylist()]
    shots = [shot for shot in shots if not isinstance(shot, list)]
    engine = FlightEngine(model_dir(None), batch_threads=1)
    want, got = requested_columns(engine, shots), fly_checked(engine, check_rows(table))
    assert got.errors == want.errors
    assert got.values.keys() == want.values.keys()
    for name, values in want.values.items():
        assert np.array_equal(got.present[name], want.present[name]), name
        assert got.values[name].dtype == values.dtype and np.array_equal(got.values[name], values, equal_nan=True), name
    return len(shots)


def test_the_columnar_path_flies_every_valid_row_as_its_request():
    """Launch-monitor forms (mph, back and side spin, a -0.0 axis), random winds, airs, grounds off the tee's height
    (their flat flights), normalized replays, a shot that never reaches its ground, text cells as a CSV reads them
    and numbers typed as Parquet holds them (integers among them), invalid rows among the valid; and a grid, whose
    rows share one condition."""
    rows = launch_rows(300, seed=4)
    rows[5].update(ground_elevation_m=90.0)
    rows[10].update(spin_axis_deg=-0.0, launch_direction_deg="", normalized="yes")
    rows[7].update(ball_speed_mps="", ball_speed_mph=140.0, spin_rpm="", spin_axis_deg="", back_spin_rpm=2500.0,
                   side_spin_rpm=-0.0)
    rows[8].update(spin_rpm=99999)  # refused: not flown, and not in the requests flown one by one
    text = pa.table({k: [None if r[k] == "" else str(r[k]) for r in rows] for k in rows[0]})
    assert assert_columnar_flights_equal_requested(text) == 299
    typed = pa.Table.from_pylist([{k: None if v == "" else v for k, v in r.items()} for r in rows])
    typed = typed.set_column(typed.column_names.index("spin_rpm"), "spin_rpm",
                             pa.array([None if r["spin_rpm"] == "" else int(r["spin_rpm"]) for r in rows], pa.int64()))
    assert assert_columnar_flights_equal_requested(typed) == 299
    odd = typed.set_column(typed.column_names.index("ground_surface"), "ground_surface",
                           typed["ground_surface"].dictionary_encode())  # a pandas category in Parquet
    for name in ("launch_direction_deg", "wind_from_deg"):  # decimals, which the model takes as floats
        odd = odd.set_column(odd.column_names.index(name), name, odd[name].cast(pa.decimal128(12, 6), safe=False))
    odd = odd.set_column(odd.column_names.index("normalized"), "normalized",
                         pa.array([r["normalized"] == "true" for r in rows]))
    assert assert_columnar_flights_equal_requested(odd) == 299
    grid = Grid.parse(["ball_speed_mps=40:70:8", "launch_angle_deg=8:20:4", "spin_rpm=2500,5000", "altitude_m=1600",
                       "wind_speed_mps=5", "ground_elevation_m=-2"])
    assert assert_columnar_flights_equal_requested(pa.table(grid.rows(0, len(grid)))) == 64


def test_a_grid_sweep_equals_simulate_row_for_row(tmp_path):
    """Every row of a grid with conditions swept (columnar checking and flying) against `golfflight simulate` on the
    same rows written as a CSV."""
    axes = ["ball_speed_mps=40:70:4", "launch_angle_deg=8,16", "spin_rpm=2500,6000", "wind_speed_mph=0,12",
            "wind_from_deg=90", "temperature_f=50,95", "ground_surface=green,rough", "ground_elevation_ft=0,-10",
            "normalized=true,false"]
    grid = Grid.parse(axes)
    rows = grid.rows(0, len(grid))
    source = write_csv(tmp_path / "grid.csv", [{"shot_id": f"s{i}", **{k: v[i] for k, v in rows.items()}}
                                                for i in range(len(grid))])
    out = tmp_path / "grid.parquet"
    assert sweep("--grid", *axes, "--out", out, "--workers", 1, "--chunk-rows", 100) == 0
    swept = pq.read_table(out).to_pylist()
    for i, row in enumerate(swept):
        row["shot_id"] = f"s{i}"
    assert_same_as_simulate(swept, simulated(tmp_path, source), sample=len(grid))


def test_ray_actors_fly_the_torch_engine_as_engine_torch_does(tmp_path, capsys):
    """`--engine ray --device cpu`: each actor builds the torch engine itself (`TorchEngineMaker`, sent by Ray) and
    the Parquet file holds the numbers of `--engine torch --device cpu`, every column equal. On the same Ray
    instance (started here once with one GPU declared, which Ray takes on trust; the sweep leaves it running): an
    actor asking Ray for that GPU (`WorkerEngine(gpus=1)`, what `--device cuda` asks; here it flies on the CPU) is
    placed and gives the same file, one actor for the one GPU listed, as do two actors asking for half of it each
    (`--actors-per-gpu 2`); and `--device cuda`, whose engine no worker here can
    build (no CUDA, as on a GPU node without its driver), is refused in one line before any actor starts."""
    ray = pytest.importorskip("ray")
    pytest.importorskip("torch")
    from golfflight.flight.torch_engine import TorchEngineMaker
    from golfflight.sweep.run import WorkerEngine, run_sweep
    from golfflight.sweep.sources import open_source

    axes = ["ball_speed_mps=40:70:5", "launch_angle_deg=8,16", "spin_rpm=2500,6000", "wind_speed_mps=0,6",
            "ground_elevation_m=0,-3", "normalized=true,false"]
    outs = {name: tmp_path / f"{name}.parquet" for name in ("torch", "ray", "ray_gpu", "ray_half_gpu")}
    assert sweep("--grid", *axes, "--out", outs["torch"], "--engine", "torch", "--device", "cpu", "--threads", 1,
                 "--chunk-rows", 32) == 0
    ray.init(num_cpus=3, num_gpus=1, include_dashboard=False, logging_level="WARNING")
    try:
        assert sweep("--grid", *axes, "--out", outs["ray"], "--engine", "ray", "--device", "cpu", "--workers", 1,
                     "--chunk-rows", 32) == 0
        assert "on ray with 1 workers (torch on cpu, float32)" in capsys.readouterr().out
        run_sweep(open_source(None, axes, 32), str(outs["ray_gpu"]), "ray", None, progress=False,
                  worker_engine=WorkerEngine(TorchEngineMaker("cpu", threads=1), gpus=1))
        run_sweep(open_source(None, axes, 32), str(outs["ray_half_gpu"]), "ray", None, progress=False,
                  worker_engine=WorkerEngine(TorchEngineMaker("cpu", threads=1, parts_at_once=2), gpus=0.5))
        assert sweep("--grid", *axes, "--out", tmp_path / "cuda.parquet", "--engine", "ray", "--device", "cuda") == 2
        err = capsys.readouterr().err
        ours = [line for line in err.splitlines() if line.startswith("golfflight")]  # Ray may log its own lines
        assert len(ours) == 1 and ours[0].startswith(
            "golfflight sweep: error: --engine ray: a worker of the Ray cluster cannot build the torch engine "
            "(DeviceError: --device cuda: this machine has no CUDA GPU"), err
        assert not (tmp_path / "cuda.parquet").exists()
    finally:
        ray.shutdown()
    expected = pq.read_table(outs["torch"])
    assert expected.num_rows == 160
    for name in ("ray", "ray_gpu", "ray_half_gpu"):
        assert pq.read_table(outs[name]).equals(expected), name
