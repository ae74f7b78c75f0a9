"""Venue air on recordings that carry none (issue 32, item 1): thinner air concealed in apex-only recordings is named,
or listed first among the rivals the data cannot separate, with the venue air it implies and the unrecorded
observable that would separate them; with the air given in the recordings, air is not named; a drag concealed where
the data do separate them rules air out."""

from __future__ import annotations

import pytest
from golfflight.discovery.conceal import NOMINAL_CONTEXT, conceal
from golfflight.discovery.diagnose import diagnose
from golfflight.discovery.effects import equivalent_altitude_m
from golfflight.discovery.model import from_bundle, reference
from golfflight.discovery.recordings import from_shot_set
from golfflight.discovery.schema import Report
from golfflight.shots.records import ShotSet

RATIO = 0.91
"""The concealed air: about East Lake's (0.912 of ICAO density)."""

APEX_ONLY = {"carry_y_m": None, "carry_x_m": None, "flight_time_s": None, "landing_angle_deg": None}


def _apex_only(hidden: dict, seed: int, air_given: bool = False) -> list:
    """200 concealed shots with only the apex recorded (as the TOUR Championship's radar tee shots), optionally with
    the concealed air in their condition columns."""
    records = [r.model_copy(update=APEX_ONLY) for r in conceal(hidden, 200, seed=seed).shots.records]
    if air_given:
        altitude = equivalent_altitude_m(hidden["air_density"]["ratio"], NOMINAL_CONTEXT)
        air = {"temperature_c": 15.0, "altitude_m": altitude, "humidity_pct": 0.0}
        records = [r.model_copy(update=air) for r in records]
    return records


def _diagnose(records: list, model) -> Report:
    return diagnose(from_shot_set(ShotSet(records)), model, seed=0, with_correction=False, progress=False).report


@pytest.fixture(scope="module")
def bundle():
    """The served model: its own error against the reference world (the card's own_error) is what lets more drag
    and thinner air both explain a lower apex."""
    return from_bundle()


def test_concealed_thin_air_taken_for_drag_is_an_inseparable_rival_with_what_would_separate_it(bundle):
    """Thin air in reference-world flights, apex only, against the served model: drag is chosen here (seed 2, as on
    East Lake's held-out rounds), and air is listed first among the rivals with its ratio, its altitude and the
    unrecorded carry and landing angle that would separate them."""
    report = _diagnose(_apex_only({"air_density": {"ratio": RATIO}}, seed=2), bundle)
    rival = report.air_rival
    assert report.systematic and rival is not None
    assert rival.ratio == pytest.approx(RATIO, abs=0.02)
    assert rival.equivalent_altitude_m == pytest.approx(equivalent_altitude_m(rival.ratio, NOMINAL_CONTEXT), abs=1)
    assert [e.name for e in report.effects] == ["drag_scale"] and not rival.named and not rival.separable
    assert report.ambiguities[0].effects == ("drag_scale", "air_density")
    assert rival.separating_measurement in {"carry_y_m", "landing_angle_deg"}
    assert "recording either" in rival.note and "would separate them" in rival.note
    assert "model's own error" in rival.note, "held-out shots prefer drag by less than the model's own apex error"
    assert "cannot firmly tell drag_scale from air_density" in report.statement


def test_concealed_thin_air_is_named_against_a_perfect_model():
    """Against the reference world itself (no own error) the apex alone names the concealed air."""
    report = _diagnose(_apex_only({"air_density": {"ratio": RATIO}}, seed=3), reference())
    assert [e.name for e in report.effects] == ["air_density"]
    rival = report.air_rival
    assert rival is not None and rival.named and rival.separating_measurement is None
    assert rival.ratio == report.effects[0].parameters["ratio"] == pytest.approx(RATIO, abs=0.02)


def test_with_the_air_given_air_is_not_named(bundle):
    """The same shots carrying the concealed air: the model flies it, so air is neither named nor compared."""
    report = _diagnose(_apex_only({"air_density": {"ratio": RATIO}}, seed=2, air_given=True), bundle)
    assert report.air_rival is None
    assert "air_density" not in {e.name for e in report.effects}
    assert all("air_density" not in a.effects[1] for a in report.ambiguities)
    assert report.service_settings.air is None


def test_a_concealed_drag_rules_the_air_out_where_the_data_separate_them():
    """Against the reference world (no own error) a drag concealed in apex-only shots is told from thin air on
    held-out shots: air is compared, found worse beyond doubt, and the statement says it is ruled out."""
    report = _diagnose(_apex_only({"drag_scale": {"scale": 1.07}}, seed=1), reference())
    assert [e.name for e in report.effects] == ["drag_scale"]
    rival = report.air_rival
    assert rival is not None and not rival.named and rival.separable and rival.difference_ci[0] > 0
    assert all("air_density" not in a.effects[1] for a in report.ambiguities)
    assert "ruled out" in report.statement
