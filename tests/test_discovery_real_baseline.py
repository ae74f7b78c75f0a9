"""`python -m golfflight.discovery.real --baseline-pairs`: real sets diagnosed against another as their baseline
session (issue 54). The driver file's ball types come from its trained lines only, with the ball column dropped;
the tour pairs use only the events one may train on, with the new event's known air concealed (skipped where
../shared/data is absent)."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from golfflight.discovery.model import reference
from golfflight.discovery.real import (
    TOUR_CHAMPIONSHIP,
    TRACKMAN,
    baseline_pairs,
    main,
    run_baseline_pairs,
    training_driver_balls,
)
from golfflight.shots.heldout import held_out_set, shot_round
from golfflight.shots.paths import shared_data_dir


def _shared():
    shared = shared_data_dir()
    if not (shared / TRACKMAN).is_file() or not (shared / TOUR_CHAMPIONSHIP).is_file():
        pytest.skip("needs the shared real data")
    return shared


def test_the_driver_balls_come_from_the_trained_lines_with_the_ball_dropped():
    balls = training_driver_balls(_shared())
    first = held_out_set(TRACKMAN).first_line
    assert set(balls) == {"Premium", "Limited Distance Soft"}  # Medium, Soft, Premium Hard: held-out lines only
    for records in balls.values():
        assert records and all(int(r.shot_id) < first and r.ball is None for r in records)


def test_the_pairs_hold_out_nothing_and_conceal_the_new_events_known_air():
    pairs = {pair.key: pair for pair in baseline_pairs(_shared())}
    assert set(pairs) == {
        "driver_premium_to_limited_distance_soft",
        "driver_limited_distance_soft_to_premium",
        "sentry_to_sony",
        "sentry_to_east_lake",
        "east_lake_to_sentry",
        "east_lake_r1_to_r2",
    }
    first = held_out_set(TRACKMAN).first_line
    for pair in pairs.values():
        for recordings in (pair.baseline, pair.new):
            if pair.key.startswith("driver"):
                assert all(int(s) < first for s in recordings.shot_id)
            elif "east_lake" in recordings.source or "pbp_2020" in recordings.source:
                assert {shot_round(s) for s in recordings.shot_id} <= {1, 2}
    assert len(pairs["driver_premium_to_limited_distance_soft"].new) == len(
        pairs["driver_limited_distance_soft_to_premium"].baseline
    )
    for key, venue in (("sentry_to_east_lake", 0.912), ("east_lake_to_sentry", 0.951)):
        assert pairs[key].baseline.density_kg_m3 is not None and pairs[key].new.density_kg_m3 is None
        assert pairs[key].venue == pytest.approx(venue, abs=0.001)
    r1, r2 = pairs["east_lake_r1_to_r2"].baseline, pairs["east_lake_r1_to_r2"].new
    assert {shot_round(s) for s in r1.shot_id} == {1} and {shot_round(s) for s in r2.shot_id} == {2}


def test_a_small_pair_is_diagnosed_and_tabulated(tmp_path):
    """East Lake's round 1 (its first 60 shots) as the baseline of its round 2's first 60, against the reference
    world: a row, the report with its baseline account, and the details."""
    pair = next(p for p in baseline_pairs(_shared()) if p.key == "east_lake_r1_to_r2")
    small = replace(pair, baseline=pair.baseline.subset(np.arange(60)), new=pair.new.subset(np.arange(60)))
    (row,) = run_baseline_pairs([small], reference(), tmp_path)
    assert row[0] == "east_lake_r1_to_r2" and row[1].endswith(": 60") and row[2].endswith(": 60")
    assert "|" in (tmp_path / "baseline_pairs.md").read_text()
    details = json.loads((tmp_path / "baseline_pairs.json").read_text())["east_lake_r1_to_r2"]
    assert details["baseline_info"]["n_shots"] == 60 and details["candidates"]
    assert (tmp_path / "east_lake_r1_to_r2" / "report.json").is_file()


def test_the_command_line_filters_the_pairs(tmp_path):
    """--baseline-pairs --only runs just the pairs whose key matches (here none: an empty table)."""
    _shared()
    assert main(["--out", str(tmp_path), "--model", "reference", "--baseline-pairs", "--only", "^no_such_pair$"]) == 0
    assert (tmp_path / "baseline_pairs.md").read_text().count("\n") == 4
