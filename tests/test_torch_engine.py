"""The torch engine (`flight.torch_engine`, `golfflight sweep --engine torch`) flies the shipped bundle as the
ONNX engine does: the same figures, errors and rests for mixed shots (air, uniform and log winds, grounds above and
below the tee, sloped surfaces), the engine's landing and apex rules to float64 rounding, the same sweep columns;
a device this machine lacks, a missing torch and options of other engines are refused in one line; training's
`--device` left out is the CPU, bit for bit. CPU only (CI has no GPU); `benchmarks/bench_gpu.py` measures a GPU."""

from __future__ import annotations

import sys

import numpy as np
import pytest
import torch
from conftest import random_launches
from shared_network import numpy_flyer_of
from golfflight.flight import torch_engine
from golfflight.flight.air import Air
from golfflight.flight.conditions import Conditions
from golfflight.flight.devices import DeviceError, resolve_device
from golfflight.flight.flyer import load_flyer
from golfflight.flight.ground import SURFACES, GroundSpec
from golfflight.flight.problem import FlightProblem
from golfflight.flight.torch_engine import STAGES, TorchEngine
from golfflight.flight.wind import Wind
from golfflight.model_export.training import TrainConfig, load_checkpoint, train

from golfflight.cli import main

pytestmark = pytest.mark.usefixtures("one_torch_thread")

pq = pytest.importorskip("pyarrow.parquet")

SHOTS = 300
FIGURES = ("landing_x_m", "landing_y_m", "carry_m", "apex_m", "apex_time_s", "flight_time_s", "landing_angle_deg",
           "landing_speed_mps", "landing_spin_rpm")


def mixed_shots(n: int, seed: int = 0) -> tuple[np.ndarray, list[Conditions], list[GroundSpec | None]]:
    """Wedges to drivers in air from sea level to 2,000 m, -5 to 40 degC; calm, uniform and log-profile winds from
    every side; no ground (the flight alone), level and sloped grounds 4 m below to 6 m above the tee, on four
    surfaces; and two shots whose ground is higher than they rise (they cannot land)."""
    rng = np.random.default_rng(seed)
    launches = np.stack(list(random_launches(n, seed).values()), axis=-1)
    conditions, grounds = [], []
    for i in range(n):
        air = Air.from_conditions(float(rng.uniform(-5, 40)), float(rng.choice([0.0, 800.0, 2000.0])))
        wind = Wind(float(rng.uniform(0, 12)), float(rng.uniform(0, 360)), str(rng.choice(["uniform", "log"])),
                    float(rng.choice([2.0, 10.0])))
        conditions.append(Conditions(air, wind if i % 4 else Wind()))
        surface = SURFACES[str(rng.choice(["fairway", "green", "rough", "firm_fairway"]))]
        ground = GroundSpec(surface, float(rng.choice([-4.0, 0.0, 6.0])), float(rng.choice([0.0, 0.0, 2.0])),
                            float(rng.uniform(0, 360)))
        grounds.append(None if i % 5 == 0 else ground)
    grounds[1] = grounds[2] = GroundSpec(SURFACES["fairway"], 90.0)
    return launches, conditions, grounds


@pytest.fixture(scope="module")
def shots():
    return mixed_shots(SHOTS)


@pytest.fixture(scope="module")
def onnx_flights(shots):
    return load_flyer(None).fly_batch(FlightProblem.of(*shots))


@pytest.fixture(scope="module")
def engines() -> dict[str, TorchEngine]:
    """Each precision eager, float32 with its Euler step compiled (torch.compile: seconds here), and float64 with its
    ground phase in torch (`flight.ground.phase.roll_to_rest` on tensors, a GPU's; here on the CPU)."""
    bundle = load_flyer(None).bundle_dir
    return {"float32": TorchEngine(bundle, "cpu", "float32"), "float64": TorchEngine(bundle, "cpu", "float64"),
            "float32-compiled": TorchEngine(bundle, "cpu", "float32", compile_step=True),
            "float64-ground-on-device": TorchEngine(bundle, "cpu", "float64", ground_on_device=True)}


def _deviation(got, want, name: str, landed: np.ndarray) -> float:
    return float(np.max(np.abs(getattr(got, name)[landed] - getattr(want, name)[landed])))


@pytest.mark.parametrize("dtype, carry_m, figures", [
    ("float32", 1e-3, 2e-2), ("float64", 2e-5, 2e-4), ("float32-compiled", 1e-3, 2e-2),
    ("float64-ground-on-device", 2e-5, 2e-4),
])
def test_the_torch_engine_flies_mixed_shots_as_the_onnx_engine(engines, shots, onnx_flights, dtype, carry_m, figures):
    """Carries within 1 mm in float32, eager or with the step compiled. In float64 the physics agree to rounding and
    what is left is the network's float32 arithmetic (torch's and ONNX Runtime's sums differ by an ulp: about 1e-7
    in a coefficient), some 10 um of carry (the rules themselves are held to 1e-6 m below), with the ground phase in
    NumPy or in torch. The other figures (degrees, rpm, s) and the rests after the ground phase follow."""
    got = engines[dtype].fly_batch(FlightProblem.of(*shots))
    assert got.errors == onnx_flights.errors and {1, 2} <= set(got.errors)
    assert "never rose to its landing ground" in got.errors[1]
    np.testing.assert_array_equal(got.rolled, onnx_flights.rolled)
    landed = np.array([i not in got.errors for i in range(SHOTS)])
    assert _deviation(got, onnx_flights, "carry_m", landed) < carry_m
    for name in FIGURES:
        assert _deviation(got, onnx_flights, name, landed) < figures, name
    rolled = got.rolled
    np.testing.assert_array_equal(got.rest.bounces[rolled], onnx_flights.rest.bounces[rolled])
    assert np.max(np.abs(got.rest.total_m[rolled] - onnx_flights.rest.total_m[rolled])) < 20 * carry_m


def test_in_float64_the_landing_and_apex_rules_are_the_integrators(engines, shots):
    """The same network flown by the NumPy integrator (the engine's Flyer) and by the torch engine in float64: every
    figure within 1e-6 (m, s, deg; the landing spin within 1e-5 rpm): the landing interpolated into the crossing
    step, the apex's parabola, each shot's ground, its air's Reynolds scale, the log profile at the ball's height,
    the failures. (An input a float64 rounding away from a float32 boundary can still move a coefficient by an ulp.)"""
    engine = engines["float64"]
    problem = FlightProblem.of(*shots)
    want, got = numpy_flyer_of(engine).fly_batch(problem), engine.fly_batch(problem)
    assert got.errors == want.errors
    landed = np.array([i not in got.errors for i in range(SHOTS)])
    for name in FIGURES:
        assert _deviation(got, want, name, landed) < (1e-5 if name == "landing_spin_rpm" else 1e-6), name
    rolled = got.rolled
    assert np.max(np.abs(got.rest.total_m[rolled] - want.rest.total_m[rolled])) < 1e-6


def test_a_batch_split_into_parts_flies_the_same_numbers(shots):
    """Parts of a batch (the device's memory) are flown apart and joined in order: the same figures, to the float32
    network's ulp (a matrix product's row can round differently beside other rows: the shots flying with it)."""
    small = TorchEngine(load_flyer(None).bundle_dir, "cpu", "float64", part_shots=64)
    whole = TorchEngine(load_flyer(None).bundle_dir, "cpu", "float64")
    launches, conditions, grounds = (part[:150] for part in shots)
    problem = FlightProblem.of(launches, conditions, grounds)
    split, joined = small.fly_batch(problem), whole.fly_batch(problem)
    assert split.errors == joined.errors
    for name in FIGURES:
        np.testing.assert_allclose(getattr(split, name), getattr(joined, name), rtol=1e-8, atol=1e-6)
    assert all(small.seconds[stage] > 0 for stage in STAGES)



def test_shots_set_aside_as_they_land_fly_the_same_numbers(shots):
    """Shots that have come down are set aside while the rest fly on (`flight.integrator.SetAside`, every ten steps
    once an eighth are down): the same figures, errors and rests as when every shot flies to the part's last step (a
    share of 1: never set aside), to the float32 network's ulp (a row of a matrix product can round differently
    beside other rows), and fewer shot-steps flown."""
    bundle = load_flyer(None).bundle_dir

    def counted(engine: TorchEngine) -> list[int]:
        flown, rule = [], engine.rule

        def step(state, field, dt):
            flown.append(len(state.position))
            return rule(state, field, dt)

        engine.rule = step
        return flown

    aside_engine = TorchEngine(bundle, "cpu", "float64")
    together_engine = TorchEngine(bundle, "cpu", "float64", set_aside_share=1.0)
    aside_flown, together_flown = counted(aside_engine), counted(together_engine)
    problem = FlightProblem.of(*shots)
    aside, together = aside_engine.fly_batch(problem), together_engine.fly_batch(problem)
    assert aside.errors == together.errors and {1, 2} <= set(aside.errors)
    for name in FIGURES:
        np.testing.assert_allclose(getattr(aside, name), getattr(together, name), rtol=1e-8, atol=1e-6, err_msg=name)
    np.testing.assert_allclose(aside.rest.total_m, together.rest.total_m, rtol=1e-8, atol=1e-6)
    np.testing.assert_array_equal(aside.rest.bounces, together.rest.bounces)
    assert sum(together_flown) == SHOTS * load_flyer(None).max_steps  # two shots never land: every step flown
    assert sum(aside_flown) < 0.6 * sum(together_flown)
    with pytest.raises(ValueError, match="set_aside_share 0: must be more than 0 and at most 1"):
        TorchEngine(bundle, "cpu", set_aside_share=0)


def sweep(*argv) -> int:
    return main(["sweep", *map(str, argv), "--no-progress"])


GRID = ["--grid", "ball_speed_mps=35:75:5", "launch_angle_deg=10,16", "spin_rpm=2500,6000",
        "wind_speed_mps=0,7", "wind_profile=uniform,log", "ground_elevation_m=0,-3", "normalized=true"]


def test_the_sweep_on_torch_writes_the_local_engines_columns_and_numbers(tmp_path, capsys):
    """A tiny grid (normalized replays and flat flights riding along) through both engines, the torch engine's in
    pieces of 32 rows flown two at a time: the same schema, the same rows in order, errors and bounces, lengths
    within 2 mm and the other figures within 0.02 (deg, s, m/s, mph, rpm)."""
    local, flown = tmp_path / "local.parquet", tmp_path / "torch.parquet"
    assert sweep(*GRID, "--out", local, "--workers", 1) == 0
    assert sweep(*GRID, "--out", flown, "--engine", "torch", "--device", "cpu", "--threads", 1, "--chunk-rows", 32) == 0
    out = capsys.readouterr().out
    assert "160 shots written" in out and "on torch (cpu, float32)" in out
    assert "the ground phase" in out and "summed over the 2 pieces flown at once" in out
    want, got = pq.read_table(local), pq.read_table(flown)
    assert got.schema == want.schema
    for name, field in zip(want.column_names, want.schema, strict=True):
        if field.type == "double":
            tolerance = 2e-3 if name.endswith(("_m", "_yd")) else 2e-2
            np.testing.assert_allclose(got[name].to_numpy(), want[name].to_numpy(), rtol=0, atol=tolerance,
                                       err_msg=name)
        else:
            assert got[name].to_pylist() == want[name].to_pylist(), name


def test_the_torch_engine_in_a_pool_of_processes_writes_the_in_process_engines_file(tmp_path, capsys):
    """`--engine torch --workers 2`: two processes here, each with its own torch engine (one thread), fly the
    pieces and the driver writes them in order: the file of the torch engine in this process, to the float32
    network's rounding. A device this machine lacks is refused in the driver."""
    alone, pooled = tmp_path / "alone.parquet", tmp_path / "pooled.parquet"
    assert sweep(*GRID, "--out", alone, "--engine", "torch", "--device", "cpu", "--threads", 1, "--chunk-rows", 32) == 0
    assert sweep(*GRID, "--out", pooled, "--engine", "torch", "--workers", 2, "--chunk-rows", 32) == 0  # cpu
    assert "on torch with 2 workers (torch on cpu, float32)" in capsys.readouterr().out
    assert sweep(*GRID, "--out", tmp_path / "none.parquet", "--engine", "torch", "--device", "tpu", "--workers", 2) == 2
    assert "--device 'tpu': not a device name" in capsys.readouterr().err  # in one line, before any worker starts
    assert not (tmp_path / "none.parquet").exists()
    want, got = pq.read_table(alone), pq.read_table(pooled)
    assert got.schema == want.schema and got.num_rows == 160
    for name, field in zip(want.column_names, want.schema, strict=True):
        if field.type == "double":
            np.testing.assert_allclose(got[name].to_numpy(), want[name].to_numpy(), rtol=1e-9, atol=1e-9,
                                       err_msg=name)
        else:
            assert got[name].to_pylist() == want[name].to_pylist(), name


@pytest.mark.parametrize("argv, message", [
    (["--device", "cpu"], "--device goes with --engine torch"),
    (["--threads", "1"], "--threads goes with --engine torch"),
    (["--compile"], "--compile goes with --engine torch"),
    (["--engine", "torch", "--device", "tpu"], "--device 'tpu': not a device name"),
    (["--engine", "torch", "--device", "meta"], "only cpu and cuda are supported"),
])
def test_options_of_other_engines_and_unknown_devices_are_refused(tmp_path, capsys, argv, message):
    out = tmp_path / "out.parquet"
    assert sweep("--grid", "ball_speed_mps=50", "launch_angle_deg=12", "spin_rpm=3000", "--out", out, *argv) == 2
    assert message in capsys.readouterr().err and not out.exists()


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has a GPU")
def test_cuda_without_a_gpu_is_refused_in_one_line(tmp_path, capsys):
    """By the sweep, and by train, train-real and finetune before they read anything."""
    with pytest.raises(DeviceError, match="no CUDA GPU"):
        resolve_device("cuda")
    out = tmp_path / "out.parquet"
    assert sweep("--grid", "ball_speed_mps=50", "launch_angle_deg=12", "spin_rpm=3000", "--out", out,
                 "--engine", "torch", "--device", "cuda") == 2
    assert capsys.readouterr().err.splitlines() == [
        (f"golfflight sweep: error: --device cuda: this machine has no CUDA GPU that torch {torch.__version__} can use "
         "(torch.cuda.is_available() is False); use --device cpu")
    ]
    assert not out.exists()
    missing = str(tmp_path / "missing.csv")
    for command in (["train", "--data", missing, "--out", str(tmp_path / "run")],
                    ["train-real", "--work", str(tmp_path / "work"), "--data-root", str(tmp_path)],
                    ["finetune", "--model", "models/default", "--data", missing, "--out", str(tmp_path / "ft")]):
        assert main([*command, "--device", "cuda", "--quiet"]) == 2, command
        assert "--device cuda: this machine has no CUDA GPU" in capsys.readouterr().err, command


class NoTorch:
    """An import finder that finds no torch, as in an install without the train extra."""

    def find_spec(self, name: str, path=None, target=None) -> None:
        if name == "torch" or name.startswith("torch."):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)


def test_the_torch_engine_without_torch_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys, "meta_path", [NoTorch(), *sys.meta_path])
    monkeypatch.delitem(sys.modules, "torch")
    out = tmp_path / "out.parquet"
    assert sweep("--grid", "ball_speed_mps=50", "launch_angle_deg=12", "spin_rpm=3000", "--out", out,
                 "--engine", "torch") == 2
    assert capsys.readouterr().err.splitlines() == [
        ("golfflight sweep: error: --engine torch needs the train extra, which is not installed (no torch): "
         "pip install 'golfflight[train]'")
    ]


def test_training_on_the_default_device_is_training_on_the_cpu_bit_for_bit(tiny_shots, tmp_path):
    """`--device` left out (train, finetune and train-real's joint training) is the CPU, and a CPU run moved through
    the device plumbing gives the same history and weights, bit for bit (the numbers from before the option)."""
    config = TrainConfig(variant="phys-nn+", hidden=(16,), epochs=1, batch_size=32, limit=64)
    default = train(tiny_shots, tmp_path / "default", config, progress=False)
    on_cpu = train(tiny_shots, tmp_path / "cpu", config, progress=False, device="cpu")
    assert [_numbers(row) for row in default.history] == [_numbers(row) for row in on_cpu.history]
    weights = [load_checkpoint(run / "last.pt")["model"] for run in (tmp_path / "default", tmp_path / "cpu")]
    assert all(torch.equal(weights[0][name], weights[1][name]) for name in weights[0])


def _numbers(row: dict) -> dict:
    """An epoch's history row less its timings."""
    return {k: v for k, v in row.items() if "seconds" not in k}


def test_on_glibc_the_torch_engine_keeps_freed_memory_for_its_next_step():
    """Each step frees the network's activations; glibc's default hands them back to the kernel once twice the largest
    block freed lies free, and the next step takes them back page by page (docs/benchmarks.md). mallopt raises the
    threshold, and answers 1 where it took the setting."""
    import ctypes.util
    import platform

    from golfflight.flight.devices import keep_freed_memory

    if platform.libc_ver()[0] != "glibc" or ctypes.util.find_library("c") is None:
        pytest.skip("not glibc: the engine leaves the C library's allocator as it is")
    assert keep_freed_memory() is True


def test_marks_kept_as_on_a_gpu_give_the_same_figures(shots, monkeypatch):
    """On a GPU the integrator asks nothing mid-step (`flight.xp.answers_now` False): every step merges each ball's
    peak and landing by `where` instead of writing the rows that rose or landed. Forced here on the CPU, the same
    figures, errors and rests, bit for bit."""
    from golfflight.flight import xp

    bundle = load_flyer(None).bundle_dir
    launches, conditions, grounds = (part[:120] for part in shots)
    problem = FlightProblem.of(launches, conditions, grounds)
    asked = TorchEngine(bundle, "cpu", "float64").fly_batch(problem)
    monkeypatch.setattr(xp, "answers_now", lambda flags: isinstance(flags, np.ndarray))
    merged = TorchEngine(bundle, "cpu", "float64").fly_batch(problem)
    assert merged.errors == asked.errors
    for name in FIGURES:
        np.testing.assert_array_equal(getattr(merged, name), getattr(asked, name), err_msg=name)
    np.testing.assert_array_equal(merged.rest.total_m, asked.rest.total_m)
