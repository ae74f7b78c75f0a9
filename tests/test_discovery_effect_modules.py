"""Discovery: each effect describes itself in one module (`discovery.effects`), and the modules that conceal, prove
and report read it from there."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.discovery.conceal import NOMINAL_CONTEXT, conceal
from golfflight.discovery.effects import BALL, EFFECTS, KINDS, LIBRARY, REYNOLDS_SCALE, apply_all
from golfflight.discovery.model import reference
from golfflight.discovery.prove import draw_effect, fitted_as, internal, relative_error
from golfflight.discovery.report import effect_phrase, service_settings
from golfflight.discovery.schema import EffectResult
from golfflight.discovery.simulator import Setup
from golfflight.discovery.words import effect_words
from golfflight.errors import InputError
from golfflight.shots.clubs import CLUBS, straight_launches

SCALES = tuple(EFFECTS[name] for name in ("drag_scale", "lift_scale", "spin_decay"))
"""The three separate scale effects, in the order of the ball's parameters."""


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


def test_the_ball_is_three_scales_applied_together():
    rng = np.random.default_rng(4)
    launch = straight_launches([c for c in CLUBS if c.name in ("Driver", "7-iron", "PW")])
    n = len(launch["spin_rpm"])
    wind, scale = rng.normal(0, 2, (n, 2)), rng.uniform(0.9, 1.1, (n, 3))
    setup = Setup(launch, np.ones(n), np.full(n, 1.225), wind, np.zeros(n), scale)
    theta = rng.uniform(0.8, 1.2, (n, 3))
    ball, separate = BALL.apply(theta, setup), apply_all(SCALES, theta, setup)
    np.testing.assert_allclose(ball.coefficient_scale, separate.coefficient_scale, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ball.wind_xy_mps, setup.wind_xy_mps)
    model = reference()
    np.testing.assert_allclose(model.simulate(ball).outcomes(), model.simulate(separate).outcomes(), rtol=0, atol=1e-12)


@pytest.mark.parametrize("world", [None, "model"])
def test_a_ball_that_changes_only_drag_is_hidden_as_the_drag_scale(world):
    """In the reference world (its knobs) and in a model's own flights (its coefficient scales) alike."""
    model = reference() if world else None
    ball = conceal({"ball": {"drag_scale": 1.06, "lift_scale": 1.0, "spin_decay_scale": 1.0}}, 80, 5, model=model)
    drag = conceal({"drag_scale": {"scale": 1.06}}, 80, 5, model=model)
    assert ball.shots.records == drag.shots.records and ball.dropped == drag.dropped


def test_the_ball_reports_its_three_scales():
    theta, covariance = np.array([1.05, 0.93, 1.4]), np.diag([0.01, 0.02, 0.1]) ** 2
    parameters, uncertainty = BALL.describe(theta, covariance, NOMINAL_CONTEXT)
    assert parameters == {"drag_scale": 1.05, "lift_scale": 0.93, "spin_decay_scale": 1.4}
    assert uncertainty == pytest.approx({"drag_scale": 0.01, "lift_scale": 0.02, "spin_decay_scale": 0.1})
    result = EffectResult(name="ball", kind="ball", parameters=parameters, uncertainty=uncertainty)
    assert effect_phrase(result) == (
        "another ball: drag scaled by 1.050 ± 0.010 and lift by 0.930 ± 0.020 (spin decay 1.40 ± 0.10, which these "
        "outcomes do not measure)"
    )
    assert service_settings([result], NOMINAL_CONTEXT).coefficient_scales == parameters
    beside = EffectResult(name="drag_scale", kind="form", parameters={"scale": 1.1}, uncertainty={"scale": 0.01})
    assert service_settings([result, beside], NOMINAL_CONTEXT).coefficient_scales["drag_scale"] == pytest.approx(1.155)


def test_the_ball_is_found_by_name_but_is_not_in_the_single_session_library():
    assert BALL not in LIBRARY and EFFECTS["ball"] is BALL
    assert BALL.kind == "ball" and KINDS["ball"] == "another ball" and effect_words("ball") == "another ball"
    assert fitted_as("ball", {"ball": {}}) == "ball" and fitted_as("ball", {"drag_scale": {}}) is None


def test_prove_draws_a_ball_inside_its_bounds_with_a_sign_each():
    rng = np.random.default_rng(6)
    draws = [draw_effect("ball", rng) for _ in range(400)]
    sizes = {"drag_scale": (0.03, 0.08), "lift_scale": (0.04, 0.10), "spin_decay_scale": (0.1, 0.3)}
    for p in BALL.parameters:
        values = np.array([d[p.name] for d in draws])
        low, high = sizes[p.name]
        assert np.all((p.low < values) & (values < p.high))
        assert np.all((low <= abs(values - 1)) & (abs(values - 1) <= high))
        assert (values > 1).any() and (values < 1).any()
    assert relative_error("ball", draws[0], draws[0]) == 0.0
    np.testing.assert_array_equal(internal("ball", draws[0]), [draws[0][p.name] for p in BALL.parameters])
