"""One landing and apex rule (`flight.events`, issue 58): on a grid of shots (wedges to drives, a launch below the
horizontal whose apex is the tee, spins from none to 9,000 rpm, both curves) the single shot's float loop, the NumPy
batch, the torch engine and training's rollout land and peak alike: the two ONNX paths within 1e-9, the three on one
torch network within its float32 graph's rounding."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import torch
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.flight.rollout import InAir, apex, euler_rollout, hard_landing
from golfflight.flight.torch_engine import TorchEngine
from shared_network import numpy_flyer_of

pytestmark = pytest.mark.usefixtures("one_torch_thread")

GRID = [Launch(*values) for values in itertools.product(
    (18.0, 45.0, 72.0), (-3.0, 9.0, 24.0, 45.0), (0.0,), (0.0, 2800.0, 9000.0), (-20.0, 0.0, 15.0)
)]
"""108 shots: speeds x launch angles x spins x spin axes."""

FIGURES = ("landing_x_m", "landing_y_m", "flight_time_s", "apex_m", "apex_time_s")


@pytest.fixture(scope="module")
def engine() -> FlightEngine:
    return FlightEngine(model_dir())


@pytest.fixture(scope="module")
def torch_engine(engine) -> TorchEngine:
    return TorchEngine(engine.bundle_dir, "cpu", "float64")


def _columns(flights) -> dict[str, np.ndarray]:
    flights = list(flights)
    return {name: np.asarray([getattr(f, name) for f in flights]) for name in FIGURES}


def _rollout_figures(network, density: float, dt: float, t_sim: float) -> dict[str, np.ndarray]:
    """Training's rollout of the grid with `network` and its landing and apex read back (`hard_landing`, `apex`)."""
    start = initial_state(*np.asarray(GRID, dtype=float).T)
    state = (torch.as_tensor(getattr(start, name)) for name in ("position", "velocity", "spin"))
    with torch.no_grad():
        trajectory = euler_rollout(*state, InAir(network, run_in=torch.float32), density, dt, t_sim)
        landing, peak = hard_landing(trajectory), apex(trajectory)
    assert bool(landing.landed.all())
    return {"landing_x_m": landing.position[:, 0].numpy(), "landing_y_m": landing.position[:, 1].numpy(),
            "flight_time_s": landing.time_s.numpy(), "apex_m": peak.height_m.numpy(),
            "apex_time_s": peak.time_s.numpy()}


def test_the_grid_holds_a_shot_whose_apex_is_its_launch_and_shots_that_climb(engine):
    flights = engine.fly(FlightProblem.of(GRID))
    tee = initial_state(*np.asarray(GRID[:1], dtype=float).T).position[0, 2]
    assert sum(f.apex_m == tee for f in flights) >= 1 and sum(f.apex_m > 10.0 for f in flights) >= 10


def test_the_single_shot_lands_and_peaks_as_the_numpy_batch(engine):
    """The float loop (the rule asked at a climb's top and at the ground) against the batch's marks (asked every
    step): the same ONNX graph, so the figures agree to its float32 rounding (one ulp of a coefficient)."""
    problem = FlightProblem.of(GRID)
    single, batch = _columns(engine.fly(problem)), _columns(engine.fly_batch(problem).shots())
    for name in FIGURES:
        np.testing.assert_allclose(single[name], batch[name], rtol=0, atol=1e-9, err_msg=name)


def test_the_numpy_batch_the_torch_engine_and_training_land_and_peak_alike(torch_engine):
    """One torch network flown in float64 by the NumPy integrator (a Flyer), by the torch engine and by training's
    rollout (over its whole horizon, read back after): every landing and apex figure within 2e-6 (m, s). The graph
    runs in float32 in each, so an input a float64 rounding away from a float32 boundary moves a coefficient by an
    ulp (up to 1.2e-6 m here); a landing or apex told one step apart would differ by centimetres to metres."""
    onnx = torch_engine.flyer
    numpy_batch = _columns(numpy_flyer_of(torch_engine).fly_batch(FlightProblem.of(GRID)).shots())
    on_torch = _columns(torch_engine.fly_batch(FlightProblem.of(GRID)).shots())
    trained = _rollout_figures(torch_engine.network, onnx.density_kg_m3, onnx.dt_s, onnx.max_flight_time_s)
    for name in FIGURES:
        np.testing.assert_allclose(on_torch[name], numpy_batch[name], rtol=0, atol=2e-6, err_msg=name)
        np.testing.assert_allclose(trained[name], numpy_batch[name], rtol=0, atol=2e-6, err_msg=name)
