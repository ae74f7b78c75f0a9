"""Discovery: a setup flies as the flight core's integrator flies the same shots, and each library effect moves a
flight the right way."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.discovery.effects import EFFECTS, LIBRARY, apply_all, wind_from_components
from golfflight.discovery.model import reference
from golfflight.discovery.simulator import Setup, simulate_setup
from golfflight.flight.air import Air
from golfflight.flight.field import BallInAir
from golfflight.flight.flyer import Flyer
from golfflight.flight.integrator import STEP_RULES, GroundPlane, integrate
from golfflight.flight.physics import initial_state
from golfflight.flight.reference_aero import CALIBRATED, ReferenceAerodynamics
from golfflight.flight.wind import Wind, wind_vector
from golfflight.shots.clubs import CLUBS, straight_launches

CARRY_Y, CARRY_X, APEX, TIME, ANGLE = range(5)
MODEL = reference()


def launches() -> dict[str, np.ndarray]:
    """Driver, 7-iron and pitching wedge at their tour launch, straight."""
    clubs = [c for c in CLUBS if c.name in ("Driver", "7-iron", "PW")]
    return straight_launches(clubs)


def base() -> Setup:
    launch = launches()
    n = len(launch["spin_rpm"])
    return Setup(
        launch, np.ones(n), np.full(n, MODEL.flyer.density_kg_m3), np.zeros((n, 2)), np.zeros(n), np.ones((n, 3))
    )


def outcomes(name: str, **parameters: float) -> tuple[np.ndarray, np.ndarray]:
    """(without, with) the effect: outcomes [3 clubs, 5]."""
    effect = EFFECTS[name]
    if name == "wind":
        theta = wind_vector(parameters["speed_mps"], parameters["from_deg"])[:2]
    else:
        theta = np.array([parameters[p.name] for p in effect.parameters])
    conditions = base()
    changed = apply_all((effect,), np.repeat(theta[None], len(conditions), 0), conditions)
    return MODEL.simulate(conditions).outcomes(), MODEL.simulate(changed).outcomes()


@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_a_setup_flies_as_the_integrator_flies_its_shots(method):
    rng = np.random.default_rng(0)
    n = 40
    launch = {
        "ball_speed_mps": rng.uniform(30, 80, n),
        "launch_angle_deg": rng.uniform(5, 35, n),
        "launch_direction_deg": rng.uniform(-5, 5, n),
        "spin_rpm": rng.uniform(1500, 10000, n),
        "spin_axis_deg": rng.uniform(-20, 20, n),
    }
    air = Air.standard()
    wind = rng.normal(0, 3, (n, 2))
    ground = rng.uniform(-5, 5, n)
    speed, from_deg = np.hypot(wind[:, 0], wind[:, 1]), np.degrees(np.arctan2(-wind[:, 0], -wind[:, 1]))
    model = ReferenceAerodynamics(CALIBRATED, air.kinematic_viscosity_m2_s)
    field = BallInAir(model, air.density_kg_m3, Wind(speed, from_deg))
    expected = integrate(initial_state(**launch), field, 0.1, 150, STEP_RULES[method], GroundPlane(ground))
    conditions = Setup(launch, np.ones(n), np.full(n, float(air.density_kg_m3)), wind, ground, np.ones((n, 3)))
    flyer = Flyer(model, 0.1, 15.0, air.density_kg_m3, air.kinematic_viscosity_m2_s, STEP_RULES[method])
    got = simulate_setup(conditions, flyer)
    assert expected.landed.all()
    np.testing.assert_allclose(got.landing_xy, expected.landing_position[:, :2], atol=1e-9)
    np.testing.assert_allclose(got.apex_m, expected.apex_m, atol=1e-9)
    np.testing.assert_allclose(got.flight_time_s, expected.flight_time_s, atol=1e-9)
    np.testing.assert_allclose(got.landing_angle_deg, expected.landing_angle_deg, atol=1e-9)


def test_null_parameters_change_nothing():
    conditions = base()
    before = MODEL.simulate(conditions).outcomes()
    for effect in LIBRARY:
        nulls = np.repeat(effect.null[None], len(conditions), 0)
        after = MODEL.simulate(apply_all((effect,), nulls, conditions)).outcomes()
        np.testing.assert_array_equal(after, before, err_msg=effect.name)


def test_wind_direction_round_trip():
    for speed, direction in ((4.0, 0.0), (3.0, 90.0), (5.0, 200.0), (2.0, 315.0)):
        x, y = wind_vector(speed, direction)[:2]
        got_speed, got_from = wind_from_components(x, y)
        assert got_speed == pytest.approx(speed) and got_from == pytest.approx(direction)


def test_headwind_shortens_raises_and_steepens():
    before, after = outcomes("wind", speed_mps=5.0, from_deg=0.0)
    assert np.all(after[:, CARRY_Y] < before[:, CARRY_Y] - 3)
    assert np.all(after[:, APEX] > before[:, APEX])
    assert np.all(after[:, ANGLE] > before[:, ANGLE])
    before, after = outcomes("wind", speed_mps=5.0, from_deg=180.0)
    assert np.all(after[:, CARRY_Y] > before[:, CARRY_Y] + 2)


def test_wind_from_the_right_pushes_left():
    before, after = outcomes("wind", speed_mps=5.0, from_deg=90.0)
    assert np.all(after[:, CARRY_X] < before[:, CARRY_X] - 3)


def test_speed_bias_moves_carry_and_apex_the_same_way():
    before, after = outcomes("ball_speed_bias", scale=1.03)
    assert np.all(after[:, CARRY_Y] > before[:, CARRY_Y]) and np.all(after[:, APEX] > before[:, APEX])
    before, after = outcomes("ball_speed_bias", scale=0.97)
    assert np.all(after[:, CARRY_Y] < before[:, CARRY_Y]) and np.all(after[:, APEX] < before[:, APEX])


def test_thin_air_lengthens_lowers_and_flattens():
    before, after = outcomes("air_density", ratio=0.85)
    assert np.all(after[:, CARRY_Y] > before[:, CARRY_Y] + 3)
    assert np.all(after[:, APEX] < before[:, APEX])
    assert np.all(after[:, ANGLE] < before[:, ANGLE])


def test_lower_landing_ground_lengthens_without_changing_apex():
    before, after = outcomes("landing_elevation", height_m=-8.0)
    assert np.all(after[:, CARRY_Y] > before[:, CARRY_Y] + 2)
    assert np.all(after[:, TIME] > before[:, TIME])
    assert np.all(after[:, ANGLE] > before[:, ANGLE])
    np.testing.assert_allclose(after[:, APEX], before[:, APEX])


def test_launch_biases():
    before, after = outcomes("launch_angle_bias", offset_deg=2.0)
    assert np.all(after[:, APEX] > before[:, APEX])
    before, after = outcomes("launch_direction_bias", offset_deg=2.0)
    _, twice = outcomes("launch_direction_bias", offset_deg=4.0)
    straight_line = before[:, CARRY_Y] * np.sin(np.radians(2.0))
    assert np.all(after[:, CARRY_X] > 0.9 * straight_line) and np.all(after[:, CARRY_X] < 1.3 * straight_line)
    np.testing.assert_allclose(twice[:, CARRY_X], 2 * after[:, CARRY_X], rtol=0.02)
    before, after = outcomes("spin_axis_bias", offset_deg=5.0)
    assert np.all(after[:, CARRY_X] > before[:, CARRY_X] + 2)
    before, after = outcomes("spin_bias", scale=1.15)
    assert np.all(after[:, APEX] > before[:, APEX])


def test_coefficient_scales():
    before, after = outcomes("drag_scale", scale=1.1)
    assert np.all(after[:, CARRY_Y] < before[:, CARRY_Y]) and np.all(after[:, TIME] < before[:, TIME])
    before, after = outcomes("lift_scale", scale=1.1)
    assert np.all(after[:, APEX] > before[:, APEX]) and np.all(after[:, TIME] > before[:, TIME])
    before, after = outcomes("spin_decay", scale=2.0)
    assert np.all(after[:, APEX] < before[:, APEX]) and np.all(after[:, TIME] < before[:, TIME])
