"""`flight.per_shot.PerShot`, a batch's per-shot objects given once each: read once per distinct object, spread by
shot, and flown by the engine to exactly the numbers of the same objects given one a shot."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.flight.air import Air
from golfflight.flight.conditions import STANDARD, Conditions
from golfflight.flight.flyer import load_flyer
from golfflight.flight.ground import SURFACES, GroundSpec, Surface, batch_surface
from golfflight.flight.per_shot import PerShot
from golfflight.flight.problem import FlightProblem
from golfflight.flight.wind import Wind


def test_a_column_reads_each_distinct_object_once_and_spreads_it_by_shot():
    shared = PerShot(["a", "bb", "ccc"], np.array([2, 0, 0, 2, 1]))
    reads = []
    column = shared.column(lambda word: reads.append(word) or len(word))
    assert column.tolist() == [3, 1, 1, 3, 2]
    assert reads == ["a", "bb", "ccc"]
    assert list(shared) == ["ccc", "a", "a", "ccc", "bb"] and shared[3] == "ccc" and len(shared) == 5


def test_only_objects_some_shot_has_are_kept():
    """A replay's reference where no shot asks for one is None: an engine reading every object must not see it."""
    shared = PerShot([None, "x", None, "y"], np.array([3, 1, 3]))
    assert shared.objects == ["x", "y"] and list(shared) == ["y", "x", "y"]
    assert shared.take(np.array([1])).objects == ["x"]
    assert list(shared.plus(PerShot(["z", None], np.array([0, 0])), shared.take(np.array([0])))) == [
        "y", "x", "y", "z", "z", "y"]


def test_of_takes_one_object_a_sequence_or_a_per_shot_and_names_a_wrong_length():
    assert list(PerShot.of(STANDARD, 3)) == [STANDARD] * 3
    assert PerShot.of(None, 2).objects == [None]
    listed = PerShot.of([STANDARD, STANDARD], 2)
    assert PerShot.of(listed, 2) is listed
    with pytest.raises(ValueError, match="3 grounds for 2 launches"):
        PerShot.of([None] * 3, 2, "grounds")


def test_a_batch_surface_is_the_one_shared_or_each_shots_parameters():
    fairway, green = SURFACES["fairway"], SURFACES["green"]
    one = PerShot([GroundSpec(fairway), GroundSpec(fairway, 2.0)], np.array([0, 1, 0]))
    assert batch_surface(one) is fairway
    mixed = batch_surface(PerShot([GroundSpec(fairway), GroundSpec(green)], np.array([1, 0, 1])))
    stacked = Surface.stack([green, fairway, green])
    for name in Surface.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(mixed, name), getattr(stacked, name))


def test_the_engine_flies_a_per_shot_batch_to_the_numbers_of_the_same_objects_given_one_a_shot():
    flyer = load_flyer(None)
    rng = np.random.default_rng(3)
    n = 40
    launches = np.stack([rng.uniform(40, 75, n), rng.uniform(8, 20, n), rng.normal(0, 2, n),
                         rng.uniform(2500, 7000, n), rng.normal(0, 5, n)], axis=-1)
    airs = [STANDARD, Conditions(Air.from_conditions(30.0, 1600.0), Wind(6.0, 200.0, "log")),
            Conditions(wind=Wind(4.0, 90.0))]
    grounds = [None, GroundSpec(SURFACES["green"], -3.0, 1.5, 40.0), GroundSpec(SURFACES["rough"], 2.0)]
    conditions = PerShot(airs, rng.integers(0, 3, n))
    shot_grounds = PerShot(grounds, rng.integers(0, 3, n))
    shared = flyer.fly_batch(FlightProblem.of(launches, conditions=conditions, grounds=shot_grounds))
    listed = flyer.fly_batch(FlightProblem.of(launches, conditions=list(conditions), grounds=list(shot_grounds)))
    assert shared.errors == listed.errors
    np.testing.assert_array_equal(shared.rolled, listed.rolled)
    for name in ("carry_m", "apex_m", "landing_angle_deg", "flight_time_s"):
        np.testing.assert_array_equal(getattr(shared, name), getattr(listed, name))
    np.testing.assert_array_equal(shared.rest.total_m, listed.rest.total_m)
