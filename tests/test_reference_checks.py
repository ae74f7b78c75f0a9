"""The reference world's altitude and wind checks (shots.reference_checks): the directions physics demands and the
sizes the rules of thumb give (+24 yd at 7,800 ft, about -13 yd into a 10 mph wind), within what
docs/reference_world.md reports."""

import pytest
from golfflight.shots.reference_checks import altitude_check, render_checks_markdown, wind_check


def test_thin_air_carries_farther_flies_lower_and_lands_shallower():
    sea, high = altitude_check()
    assert high.carry_yd > sea.carry_yd + 15  # the rule of thumb: +24 yd at 7,800 ft
    assert high.apex_yd < sea.apex_yd and high.land_deg < sea.land_deg - 3
    assert sea.side_yd == pytest.approx(0.0, abs=1e-9) == high.side_yd


def test_wind_shortens_into_it_lengthens_with_it_and_pushes_across():
    calm, windy = wind_check()
    assert 230 < calm.carry_yd < 270  # the rule's "250 yd drive"
    for profile in ("uniform", "log"):
        head, tail = windy[("headwind", profile)], windy[("tailwind", profile)]
        cross = windy[("crosswind from the right", profile)]
        assert -25 < head.carry_yd - calm.carry_yd < -10  # the rule of thumb: about -13 yd
        assert 6 < tail.carry_yd - calm.carry_yd < 18  # about +9 yd
        assert calm.carry_yd - head.carry_yd > tail.carry_yd - calm.carry_yd  # a headwind costs more than a tailwind gives
        assert cross.side_yd < -5  # blown to the left


def test_checks_render_as_two_tables():
    lines = render_checks_markdown()
    assert sum(line.startswith("|---") for line in lines) == 2
    assert any(line.startswith("| headwind |") for line in lines)
