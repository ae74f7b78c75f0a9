"""Discovery: each effect describes itself in one module (`discovery.effects`), and the modules that conceal, prove
and report read it from there."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.discovery.conceal import NOMINAL_CONTEXT, conceal
from golfflight.discovery.effects import EFFECTS, KINDS, LIBRARY, REYNOLDS_SCALE
from golfflight.discovery.model import reference
from golfflight.discovery.prove import draw_effect, fitted_as, internal
from golfflight.discovery.report import effect_phrase, service_settings
from golfflight.discovery.schema import EffectResult
from golfflight.discovery.words import effect_words
from golfflight.errors import InputError


def fitted(name: str) -> EffectResult:
    """The effect at one typical size from no effect, with a third of it as the uncertainty, as reported."""
    effect = EFFECTS[name]
    theta = effect.null + np.array([p.typical for p in effect.parameters])
    covariance = np.diag([(p.typical / 3) ** 2 for p in effect.parameters])
    parameters, uncertainty = effect.describe(theta, covariance, NOMINAL_CONTEXT)
    return EffectResult(name=name, kind=effect.kind, parameters=parameters, uncertainty=uncertainty)


@pytest.mark.parametrize("name", list(EFFECTS))
def test_every_effect_carries_its_words_kind_and_phrase(name):
    effect = EFFECTS[name]
    assert effect.kind in KINDS and effect.words and effect_words(name) == effect.words
    phrase = effect_phrase(fitted(name))
    assert phrase == effect.phrase(fitted(name).parameters, fitted(name).uncertainty) and "±" in phrase


@pytest.mark.parametrize("effect", LIBRARY, ids=lambda e: e.name)
def test_every_library_effect_is_hidden_at_a_size_inside_its_bounds(effect):
    """What `prove` draws is inside the bounds the fit may reach, away from no effect, and maps back to internal
    parameters through the effect itself."""
    rng = np.random.default_rng(3)
    low, high = (np.array([getattr(p, side) for p in effect.parameters]) for side in ("low", "high"))
    for _ in range(200):
        truth = internal(effect.name, draw_effect(effect.name, rng))
        assert np.all((low < truth) & (truth < high)) and np.any(truth != effect.null)


def test_each_effect_gives_its_own_service_setting():
    settings = service_settings([fitted(e.name) for e in LIBRARY], NOMINAL_CONTEXT).model_dump(exclude_none=True)
    assert set(settings) == {"wind", "air", "air_as_altitude", "ground_height_m", "launch_corrections",
                             "coefficient_scales"}
    assert set(settings["launch_corrections"]) == {"launch_angle_deg_add", "launch_direction_deg_add",
                                                   "ball_speed_scale", "spin_rpm_scale", "spin_axis_deg_add"}
    assert settings["coefficient_scales"] == {"spin_decay_scale": 1.3, "drag_scale": 1.05, "lift_scale": 1.05}
    assert service_settings([fitted(REYNOLDS_SCALE.name)], NOMINAL_CONTEXT) == service_settings([], NOMINAL_CONTEXT)


def test_either_air_variant_stands_for_the_other():
    assert fitted_as("air_density_only", {"air_density": {}}) == "air_density"
    assert fitted_as("air_density", {"air_density_only": {}}) == "air_density_only"
    assert fitted_as("drag_scale", {"air_density": {}}) is None and fitted_as("critical_reynolds", {}) is None


def test_an_effect_that_says_nothing_of_hiding_is_refused_in_a_models_flights():
    assert REYNOLDS_SCALE.hiding is None
    with pytest.raises(InputError, match="reynolds_scale"):
        conceal({REYNOLDS_SCALE.name: {"scale": 1.1}}, 20, 0, model=reference())


def test_a_launch_bias_is_recorded_and_not_flown():
    """A launch bias changes what the monitor records, not the flight: the launches of a biased set are the clean
    set's minus the offset, shot for shot, and the outcomes are the clean set's."""
    clean = conceal({}, 60, 2, model=reference()).shots.records
    biased = conceal({"launch_angle_bias": {"offset_deg": 1.5}}, 60, 2, model=reference()).shots.records
    assert [r.shot_id for r in biased] == [r.shot_id for r in clean]
    for a, b in zip(clean, biased):
        assert b.launch_angle_deg == pytest.approx(a.launch_angle_deg - 1.5, abs=1e-9)
        assert b.carry_y_m == a.carry_y_m and b.apex_m == a.apex_m
