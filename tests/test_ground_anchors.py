"""The ground phase against its anchors (docs/ground.md, scripts/ground_anchors.py): the tour tables' clubs flown
through the shipped engine onto greens of stimp 8-14, the fitted fairway and the rough, calm and in 8 m/s of head-
or tailwind. A few representative shots per bound: the steepest, spinniest wedges for spin-back, both tours' drivers
for the run on a green, the calm PGA 7-iron and PW on every green of the grid."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
from golfflight.flight.ground import SURFACES, surface

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "ground_anchors.py"
spec = importlib.util.spec_from_file_location("ground_anchors", SCRIPT)
anchors = importlib.util.module_from_spec(spec)
spec.loader.exec_module(anchors)

GREENS = {"green 8": surface("green", 8.0), "green 14": surface("green", 14.0)}


def clubs(tour: str, *names: str) -> tuple:
    return tuple(club for club in anchors.TOURS[tour] if club.name in names)


def test_no_tour_wedge_spins_back_more_than_five_yards(engine):
    """Into an 8 m/s headwind the wedges drop at 70-80 degrees with 8,000-9,000 rpm: the most back spin meets the
    least forward speed. On the fastest green they check or come back a few yards, not thirty."""
    wedges = {"PGA": clubs("PGA", "PW", "GW", "SW", "LW"), "LPGA": clubs("LPGA", "9-iron", "PW")}
    grid = anchors.fly_grid(engine, wedges, {"head": anchors.WINDS["head"], "calm": anchors.WINDS["calm"]}, GREENS)
    worst = min(run.run_yd for run in grid.values())
    assert -5.0 <= worst < 0.0, "the headwind wedges should come back a little, and no more than five yards"


def test_a_driver_runs_at_most_forty_yards_on_a_green(engine):
    drivers = {tour: clubs(tour, "Driver") for tour in anchors.TOURS}
    grid = anchors.fly_grid(engine, drivers, anchors.WINDS, GREENS)
    assert max(run.run_yd for run in grid.values()) <= 40.0
    assert min(run.run_yd for key, run in grid.items() if key[2] == "tail") > 15.0, "downwind, a drive still runs"


def test_the_rough_never_runs_a_landing_further_than_the_fairway(engine):
    shown = {tour: clubs(tour, "Driver", "5-wood", "7-iron", "PW") for tour in anchors.TOURS}
    where = {"fairway": SURFACES["fairway"], "rough": SURFACES["rough"]}
    grid = anchors.fly_grid(engine, shown, anchors.WINDS, where)
    for (tour, club, wind, ground), run in grid.items():
        if ground == "rough":
            assert abs(run.run_yd) <= abs(grid[tour, club, wind, "fairway"].run_yd), (tour, club, wind)


@pytest.mark.parametrize(("club", "low", "high"), [("Driver", 13.0, 22.0), ("7-iron", 4.0, 10.0), ("PW", 1.0, 6.0)])
def test_a_calm_level_fairway_runs_what_the_tour_tables_say(engine, club, low, high):
    """Tour radar seasons put driving distance about 15 yd past the carry and TrackMan's 2023 PGA table 20; the same
    table's 7-iron runs 7 yd and its PW 4 (docs/ground.md)."""
    grid = anchors.fly_grid(engine, {"PGA": clubs("PGA", club)}, {"calm": anchors.WINDS["calm"]},
                            {"fairway": SURFACES["fairway"]})
    assert low <= grid["PGA", club, "calm", "fairway"].run_yd <= high


GRID_GREENS = {f"green {stimp:g}": surface("green", stimp) for stimp in anchors.STIMPS_FT}


@pytest.mark.parametrize(("club", "low", "high"), [("7-iron", -5.0, 7.0), ("PW", -5.0, 5.0)])
def test_a_calm_green_holds_a_tour_approach_as_well_as_a_fairway(engine, club, low, high):
    """TrackMan's 2023 PGA table runs the 7-iron 7 yd past its carry and the PW 4, on a fairway; a green of any speed
    from stimp 8 to 14 holds the same steep, spinning landing at least as well: the 7-iron checks within 7 yd, the PW
    within 5 either way (a little spin-back allowed, no more than the wedges' bound)."""
    grid = anchors.fly_grid(engine, {"PGA": clubs("PGA", club)}, {"calm": anchors.WINDS["calm"]}, GRID_GREENS)
    runs = [run.run_yd for run in grid.values()]
    assert len(runs) == len(anchors.STIMPS_FT) and low <= min(runs) and max(runs) <= high, runs


def test_the_checks_read_the_grid():
    """`checks` on a grid worked by hand: the worst spin-back, the longest driver on a green, the rough's excess."""
    run = anchors.AnchorRun
    grid = {
        ("PGA", "Driver", "calm", "green 8"): run(280.0, 30.0),
        ("PGA", "Driver", "tail", "green 14"): run(300.0, 35.0),
        ("PGA", "PW", "head", "green 14"): run(110.0, -3.0),
        ("PGA", "Driver", "calm", "fairway"): run(280.0, 15.0),
        ("PGA", "7-iron", "calm", "fairway"): run(175.0, 7.0),
        ("PGA", "PW", "calm", "fairway"): run(135.0, 4.0),
        ("PGA", "Driver", "calm", "rough"): run(280.0, 9.0),
        ("PGA", "7-iron", "calm", "rough"): run(175.0, 8.0),
        ("PGA", "PW", "calm", "rough"): run(135.0, -2.0),
        ("PGA", "7-iron", "calm", "green 8"): run(175.0, 4.5),
        ("PGA", "7-iron", "calm", "green 14"): run(175.0, 5.5),
        ("PGA", "PW", "calm", "green 8"): run(135.0, 3.0),
        ("PGA", "PW", "calm", "green 14"): run(135.0, -1.0),
    }
    found = anchors.checks(grid)
    assert found.worst_spin_back_yd == -3.0 and found.longest_green_driver_yd == 35.0
    assert found.rough_over_fairway_yd == pytest.approx(1.0)
    assert found.fairway_calm_yd == {"Driver": 15.0, "7-iron": 7.0, "PW": 4.0}
    assert found.green_calm_yd == {"7-iron": (4.5, 5.5), "PW": (-1.0, 3.0)}
    text = anchors.checks_table(found)
    assert "| worst spin-back" in text and "| PGA PW on greens of stimp 8-14, calm | -5 to 5 | -1.0 to +3.0 |" in text
