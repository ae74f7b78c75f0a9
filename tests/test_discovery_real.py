"""`python -m golfflight.discovery.real` on a real set: the shared data are read in place, and the summary row says
how the recordings scatter and what was found (skipped where ../shared/data is absent)."""

from __future__ import annotations

import json

import pytest
from golfflight.discovery.real import HELD_OUT, TOUR_CHAMPIONSHIP, TRACKMAN, TRAINED_ON, main, real_sets
from golfflight.shots.heldout import held_out_set, shot_round
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.source_air import KNOWN_AIR


def test_real_run_writes_a_summary_row_and_a_report(tmp_path):
    if not (shared_data_dir() / TRACKMAN).is_file():
        pytest.skip("needs the shared real data")
    assert main(["--out", str(tmp_path), "--model", "reference", "--only", "pga_2023_averages$"]) == 0
    summary = (tmp_path / "summary.md").read_text().splitlines()
    assert "scatter (x assumed noise)" in summary[2] and len(summary) == 5
    assert "PGA TOUR 2023 averages" in summary[4]
    details = json.loads((tmp_path / "details.json").read_text())
    assert set(details) == {"pga_2023_averages"} and details["pga_2023_averages"]["statement"]
    assert (tmp_path / "pga_2023_averages" / "report.json").is_file()


def test_the_driver_sets_held_out_lines_are_diagnosed_on_their_own():
    """The served model was trained on the driver file's first lines (docs/training_real.md): its held-out lines
    (shots.heldout) are a set of their own, holding every measured shot from the first held-out line and no other."""
    shared = shared_data_dir()
    if not (shared / TRACKMAN).is_file():
        pytest.skip("needs the shared real data")
    sets = {item.key: item for item in real_sets(shared)}
    every, unseen = sets["trackman_driver"].recordings, sets["trackman_driver_heldout"].recordings
    first = held_out_set(TRACKMAN).first_line
    lines = [int(s) for s in unseen.shot_id]
    assert min(lines) >= first == 2943
    assert len(unseen) == sum(int(s) >= first for s in every.shot_id) > 0


def test_only_what_shots_heldout_holds_out_is_labelled_held_out():
    """shots.heldout: the driver lines from 2943 and the TOUR Championship's rounds 3-4 are held out; its rounds
    1-2 and the PGA 2023 table are trained on, and are flown in their source's air (shots.source_air)."""
    shared = shared_data_dir()
    if not (shared / TOUR_CHAMPIONSHIP).is_file() or not (shared / TRACKMAN).is_file():
        pytest.skip("needs the shared real data")
    sets = {item.key: item for item in real_sets(shared)}
    assert {k for k, item in sets.items() if item.use == HELD_OUT} == {"trackman_driver_heldout",
                                                                        "tour_championship_heldout"}
    for key, rounds in (("tour_championship_heldout", {3, 4}), ("tour_championship_trained", {1, 2})):
        recordings = sets[key].recordings
        assert {shot_round(s) for s in recordings.shot_id} == rounds
        assert recordings.density_kg_m3 is not None
        assert recordings.density_kg_m3 == pytest.approx(KNOWN_AIR["tour-championship-2020"].air().density_kg_m3)
    assert sets["tour_championship_trained"].use == sets["pga_2023_averages"].use == TRAINED_ON
    table = sets["pga_2023_averages"].recordings.density_kg_m3
    assert table is not None and table == pytest.approx(KNOWN_AIR["pga-2023-table"].air().density_kg_m3)


def test_venue_air_runs_each_set_of_known_air_with_and_without_it(tmp_path):
    """--venue-air: a set whose air is known is diagnosed as it is and with its air concealed, and venue_air.md says
    for each run whether the air was given and what air density does against the explanation."""
    if not (shared_data_dir() / TRACKMAN).is_file():
        pytest.skip("needs the shared real data")
    args = ["--out", str(tmp_path), "--model", "reference", "--only", "pga_2023_averages", "--venue-air"]
    assert main(args) == 0
    rows = (tmp_path / "venue_air.md").read_text().splitlines()[4:]
    assert len(rows) == 2 and "given (0.990 × ICAO)" in rows[0] and "not given (venue 0.990 × ICAO)" in rows[1]
    assert "not compared (air given)" in rows[0] and "air concealed" in rows[1]
    details = json.loads((tmp_path / "details.json").read_text())
    assert set(details) == {"pga_2023_averages", "pga_2023_averages_no_air"}
    assert details["pga_2023_averages"]["air_rival"] is None
