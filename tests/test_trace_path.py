"""scripts/trace_path.py on one HTTP shot: the tracer finds the ball speed in the flight core and in the service, and
its moves and climbs are what the recorded sequence of folders gives (the issue's targets are not asserted here)."""

from __future__ import annotations

import importlib.util
import itertools
import sys
from pathlib import Path

import numpy as np
import pytest
from golfflight.flight.bundle_location import model_dir

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "trace_path.py"
spec = importlib.util.spec_from_file_location("trace_path", SCRIPT)
trace_path = importlib.util.module_from_spec(spec)
sys.modules[spec.name] = trace_path  # its dataclasses look their module up
spec.loader.exec_module(trace_path)


@pytest.fixture(scope="module")
def http_journey():
    try:
        model_dir()
    except FileNotFoundError as missing:
        pytest.skip(str(missing))
    return trace_path.http_journey()


def test_the_matcher_finds_the_speed_in_either_unit_and_inside_containers():
    find = trace_path.SpeedMatcher(150.123).find
    assert find(150.123) == "" and find(np.float32(150.123 * 0.44704)) == ""
    assert find({"launch": [1.0, np.array([2.0, 150.123])]}) == "['launch'][1]"
    assert find(150.2) is None and find("150.123") is None and find(np.arange(2_000_000, dtype=float)) is None
    assert find([[[[150.123]]]]) is None  # deeper than three levels


def test_moves_and_climbs_of_a_sequence():
    """contract -> service is a climb back (the speed goes down again, to flight); flight -> sweep is the way back
    up to the caller, a move up but not a climb back; sweep -> discovery is a move on one floor."""
    path = ["contract", "service", "service", "flight", "sweep", "discovery"]
    assert trace_path.moves_and_climbs(path) == (4, 1) and trace_path.ups(path) == 2
    bounce = ["service", "contract", "flight", "contract", "flight", "contract", "service"]
    assert trace_path.moves_and_climbs(bounce) == (6, 1) and trace_path.ups(bounce) == 3


def test_the_http_shot_carries_the_speed_through_service_and_flight(http_journey):
    folders = [call.folder for call in http_journey.calls]
    assert "flight" in folders and "service" in folders
    assert http_journey.answer["carry_m"] > 100.0
    assert all(call.function for call in http_journey.calls)


def test_moves_and_climbs_are_those_of_the_recorded_sequence(http_journey):
    folders = [call.folder for call in http_journey.calls]
    moves = [(a, b) for a, b in itertools.pairwise(folders) if a != b]
    assert http_journey.counts[0] == len(moves) and http_journey.counts[1] <= trace_path.ups(folders) <= len(moves)
    runs = trace_path.runs(http_journey.calls)
    assert len(runs) == len(moves) + 1 and sum(run["calls"] for run in runs) == len(folders)
    document = http_journey.to_json()
    assert (document["moves"], document["climbs"]) == http_journey.counts and document["ups"] == trace_path.ups(folders)

