"""Issue 58, item 1: a flight problem (`flight.problem.FlightProblem`), built once from a request and read back once.

A request with every branch (a normalized replay, a sloped green above the tee and so a flat flight, a trajectory, a
log-profile wind) is one problem of three rows, flown by one call of the single-shot engine, and each of its flights
is the engine's own flight of that shot in that air and on that ground; what only a batch flies is refused by the
single shot and the torch engine with the fields named; a launches array of another width is refused; and the full
request's ball speed takes at most 5 moves and 1 climb back between folders (`scripts/trace_path.py`, the issue's
bound; 8 and 3 before)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from golfflight.contract.flying import batch_of, fly_request
from golfflight.contract.inputs import air_of, conditions_of, ground_of, launch_of, reference_of
from golfflight.contract.requests import ShotRequest
from golfflight.errors import InputError
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.conditions import BatchAir, Conditions
from golfflight.flight.engine import FlightEngine
from golfflight.flight.problem import FlightProblem, Launch
from golfflight.flight.wind import CALM

FULL = {
    "ball_speed_mph": 150.0, "launch_angle_deg": 10.4, "back_spin_rpm": 2545.0, "normalized": True,
    "trajectory": {"rate_hz": 30}, "wind": {"speed_mps": 4.0, "from_deg": 200.0, "profile": "log"},
    "ground": {"surface": "green", "elevation_m": 3.0, "slope_deg": 2.0, "slope_dir_deg": 45.0},
}
"""A request that takes every branch (scripts/trace_path.py's `--journey http-full`)."""
SEVEN_IRON = Launch(55.0, 16.0, 0.0, 7100.0, 0.0)


@pytest.fixture(scope="module")
def engine():
    return FlightEngine(model_dir())


def test_a_full_request_is_one_problem_of_its_own_replay_and_flat_flight(engine):
    shot = ShotRequest.model_validate(FULL)
    batch = batch_of([shot])
    assert len(batch.problem) == 3 and batch.replays.tolist() == [0] and batch.flats.tolist() == [0]
    assert batch.problem.keep_states.tolist() == [True, True, False]  # a trajectory: own and replay, never the flat
    result, flight = fly_request(engine, shot)
    launch, ground = [launch_of(shot)], ground_of(shot.ground)
    reference = Conditions(air_of(reference_of(shot)), CALM)
    own, = engine.fly(FlightProblem.of(launch, conditions_of(shot), ground))
    replay, = engine.fly(FlightProblem.of(launch, reference, ground))
    flat, = engine.fly(FlightProblem.of(launch, conditions_of(shot)))
    assert flight.carry_m == own.carry_m and result.carry_m == own.carry_m
    assert result.normalized.carry_m == replay.carry_m and result.flat.carry_m == flat.carry_m
    assert result.rest.y_m == own.rest.y_m and result.normalized.apex_m == replay.apex_m
    assert len({own.carry_m, replay.carry_m, flat.carry_m}) == 3
    assert len(result.trajectory) > 10 and len(result.normalized.trajectory) > 10


def test_the_single_shot_refuses_what_only_a_batch_flies_naming_it(engine):
    start = FlightProblem.of([SEVEN_IRON]).start
    asked = FlightProblem(start, BatchAir(1.2, 1.5e-5), coefficient_scale=np.ones((1, 3)), max_time_s=3.0)
    with pytest.raises(InputError) as refused:
        engine.fly(asked)
    message = str(refused.value)
    for field in ("air as columns", "grounds as heights", "coefficient_scale", "max_time_s", "fly_batch"):
        assert field in message, field
    assert engine.fly_batch(FlightProblem(start, BatchAir(1.2, 1.5e-5))).carry_m[0] > 100.0  # the batch flies it


def test_the_torch_engine_refuses_kept_states_and_scales_naming_them():
    torch_engine = pytest.importorskip("golfflight.flight.torch_engine")
    engine = torch_engine.TorchEngine(model_dir())
    problem = FlightProblem.of([SEVEN_IRON], keep_states=True)
    scaled = FlightProblem(problem.start, problem.air, problem.grounds, coefficient_scale=np.ones((1, 3)))
    for asked, field in ((problem, "keep_states"), (scaled, "coefficient_scale")):
        with pytest.raises(InputError, match=field):
            engine.fly_batch(asked)


def test_launches_of_another_width_are_refused():
    with pytest.raises(InputError, match="launches: an array"):
        FlightProblem.of(np.zeros((2, 4)))
    with pytest.raises(InputError, match="1 conditions for 2 launches"):
        FlightProblem.of([SEVEN_IRON] * 2, [Conditions()])


def _trace_path():
    script = Path(__file__).resolve().parents[1] / "scripts" / "trace_path.py"
    spec = importlib.util.spec_from_file_location("trace_path", script)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_a_full_request_takes_at_most_5_moves_and_1_climb_back():
    journey = _trace_path().http_journey(full=True)
    moves, climbs = journey.counts
    assert journey.answer["carry_m"] > 100.0
    assert moves <= 5 and climbs <= 1, (moves, climbs, [call.folder for call in journey.calls])


def test_a_sweep_row_takes_at_most_5_moves_and_1_climb_back():
    """Held, not fixed here: the row's cells become the batch's one problem (`contract.flying.Batch.of`) once."""
    journey = _trace_path().sweep_journey()
    moves, climbs = journey.counts
    assert journey.answer["written"] == 1
    assert moves <= 5 and climbs <= 1, (moves, climbs, [call.folder for call in journey.calls])
