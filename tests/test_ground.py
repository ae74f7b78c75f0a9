"""The ground phase (flight.ground) against hand-worked cases and published numbers: a dead drop, back spin, slopes,
the stimpmeter, shallow driver landings, energy at every impact (hypothesis), batch against one by one."""

from __future__ import annotations

import math

import numpy as np
import pytest
from golfflight.flight.constants import (
    BALL_INERTIA_KG_M2,
    BALL_MASS_KG,
    BALL_RADIUS_M,
    FOOT_M,
    GRAVITY_MPS2,
    RPM_TO_RADPS,
)
from golfflight.flight.ground import SURFACES, Surface, ground_phase, ground_phase_one, holding_slope_deg, surface
from golfflight.flight.ground.impact import impact
from golfflight.flight.ground.phase import plane_normals
from golfflight.flight.ground.surfaces import STIMPMETER_EXIT_SPEED_MPS, green_rolling_resistance
from hypothesis import given, settings
from hypothesis import strategies as st

ORIGIN = np.zeros((1, 3))


def landing(speed: float, angle_deg: float, back_spin_rpm: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and spin [1,3] of a ball coming down the target line at `angle_deg` below the horizontal."""
    a = math.radians(angle_deg)
    velocity = np.array([[0.0, speed * math.cos(a), -speed * math.sin(a)]])
    return velocity, np.array([[back_spin_rpm * RPM_TO_RADPS, 0.0, 0.0]])


def rest_y(speed, angle_deg, back_spin_rpm, where: Surface, **slope) -> float:
    velocity, spin = landing(speed, angle_deg, back_spin_rpm)
    return float(ground_phase(ORIGIN, velocity, spin, where, **slope).rest_position[0, 1])


def test_a_dead_drop_on_a_green_bounces_lower_each_time_and_stops_where_it_fell():
    phase = ground_phase(ORIGIN, np.array([[0.0, 0.0, -10.0]]), np.zeros((1, 3)), surface("green"), keep_path=True)
    path = phase.paths[0]
    take_offs = path.velocities[1::2, 2][: phase.bounces[0]]
    heights = take_offs**2 / (2 * GRAVITY_MPS2)
    assert phase.bounces[0] >= 2 and np.all(np.diff(heights) < 0) and np.all(take_offs > 0)
    np.testing.assert_allclose(phase.rest_position, ORIGIN, atol=1e-12)
    np.testing.assert_allclose(path.velocities[-1], 0.0)
    assert phase.time_s[0] == pytest.approx(path.times_s[-1])


def test_back_spin_shortens_the_roll_and_pulls_a_wedge_back():
    rests = [rest_y(20.0, 50.0, rpm, surface("green")) for rpm in (0, 2000, 4000, 6000, 8000)]
    assert np.all(np.diff(rests) < 0)
    assert rests[0] > 5.0
    assert rest_y(20.0, 50.0, 8000, surface("green")) < -0.5
    assert rest_y(25.0, 40.0, 5000, SURFACES["fairway"]) < rest_y(25.0, 40.0, 2000, SURFACES["fairway"])


def test_a_roll_uphill_is_shorter_and_downhill_longer():
    level = rest_y(22.0, 38.0, 2500, surface("green"))
    uphill = rest_y(22.0, 38.0, 2500, surface("green"), slope_deg=2.0, slope_dir_deg=180.0)
    downhill = rest_y(22.0, 38.0, 2500, surface("green"), slope_deg=2.0, slope_dir_deg=0.0)
    assert uphill < level < downhill


def test_a_slope_falling_right_bends_the_roll_right():
    velocity, spin = landing(22.0, 38.0, 2500)
    rest = ground_phase(ORIGIN, velocity, spin, surface("green"), slope_deg=2.0, slope_dir_deg=90.0).rest_position
    assert rest[0, 0] > 0.5


def test_the_stimp_reading_is_the_distance_a_ball_rolls_off_the_stimpmeter():
    """The stimpmeter rolls a ball onto the green at 6.00 ft/s (1.83 m/s, the USGA device's published exit speed);
    the green's speed is how many feet it then rolls."""
    assert STIMPMETER_EXIT_SPEED_MPS == pytest.approx(1.83, abs=0.005)
    for stimp_ft in (8.0, 10.0, 12.0, 14.0):
        speed = STIMPMETER_EXIT_SPEED_MPS
        rolling_spin = np.array([[-speed / BALL_RADIUS_M, 0.0, 0.0]])
        rest = ground_phase(ORIGIN, np.array([[0.0, speed, 0.0]]), rolling_spin, surface("green", stimp_ft))
        assert rest.bounces[0] == 0
        assert rest.rest_position[0, 1] == pytest.approx(stimp_ft * FOOT_M, rel=1e-12)
    assert float(green_rolling_resistance(10.0)) == pytest.approx(0.056, abs=0.001)


@pytest.mark.parametrize("angle_deg", [3.0, 6.0, 10.0, 14.0, 20.0])
def test_a_shallow_fast_driver_landing_keeps_running_forward(angle_deg):
    """Taking the landing angle for Penner's theta_1 would make sin(theta_1 - theta_c) negative below theta_c and
    stop these balls dead; they must leave the first impact going forward and run on."""
    velocity, spin = landing(30.0, angle_deg, 2500)
    for where in SURFACES.values():
        out, _ = impact(velocity, spin, np.array([[0.0, 0.0, 1.0]]), where)
        assert out[0, 1] > 0.25 * velocity[0, 1]
    assert rest_y(30.0, angle_deg, 2500, SURFACES["fairway"]) > 10.0


def energy(velocity: np.ndarray, spin: np.ndarray) -> np.ndarray:
    return 0.5 * BALL_MASS_KG * np.sum(velocity**2, -1) + 0.5 * BALL_INERTIA_KG_M2 * np.sum(spin**2, -1)


finite = dict(allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(
    speed=st.floats(0.1, 80.0, **finite),
    angle=st.floats(0.5, 90.0, **finite),
    heading=st.floats(0.0, 360.0, **finite),
    spin=st.lists(st.floats(-1500.0, 1500.0, **finite), min_size=3, max_size=3),
    slope=st.floats(0.0, 20.0, **finite),
    slope_dir=st.floats(0.0, 360.0, **finite),
    params=st.tuples(st.floats(0.0, 3.0), st.floats(0.0, 45.0), st.floats(0.0, 2.0)),
)
def test_energy_never_grows_at_an_impact(speed, angle, heading, spin, slope, slope_dir, params):
    normal = plane_normals(slope, slope_dir, 1)
    a, h = math.radians(angle), math.radians(heading)
    velocity = speed * np.array([[math.cos(a) * math.sin(h), math.cos(a) * math.cos(h), -math.sin(a)]])
    if (velocity @ normal[0])[0] >= 0.0:
        return
    spin = np.array([spin])
    out, spin_out = impact(velocity, spin, normal, Surface(params[0], params[1], params[2], 0.1, 0.0))
    assert np.all(np.isfinite(out)) and np.all(np.isfinite(spin_out))
    assert energy(out, spin_out)[0] <= energy(velocity, spin)[0] * (1 + 1e-12) + 1e-15


def test_a_batch_is_the_balls_one_by_one():
    rng = np.random.default_rng(3)
    n = 12
    speeds, angles, rpms = rng.uniform(5, 35, n), rng.uniform(5, 60, n), rng.uniform(0, 9000, n)
    velocity = np.concatenate([landing(s, a, 0)[0] for s, a in zip(speeds, angles)])
    spin = np.concatenate([landing(1, 1, r)[1] for r in rpms])
    position = rng.uniform(-5, 5, (n, 3))
    names = rng.choice(list(SURFACES), n)
    slopes, dirs = np.where(rng.random(n) < 0.5, 0.0, 1.5), rng.uniform(0, 360, n)
    batch = ground_phase(position, velocity, spin, Surface.stack([SURFACES[k] for k in names]), slopes, dirs)
    for i in range(n):
        one = ground_phase(position[i : i + 1], velocity[i : i + 1], spin[i : i + 1], SURFACES[names[i]], slopes[i],
                           dirs[i])
        np.testing.assert_allclose(batch.rest_position[i], one.rest_position[0], atol=1e-9)
        assert batch.bounces[i] == one.bounces[0]


def test_the_stepped_slope_roll_meets_the_level_closed_form_as_the_slope_vanishes():
    for name in ("fairway", "rough", "green"):
        level = rest_y(20.0, 35.0, 2500, SURFACES[name])
        nearly = rest_y(20.0, 35.0, 2500, SURFACES[name], slope_deg=1e-9)
        assert nearly == pytest.approx(level, abs=1e-6)


def test_the_path_runs_from_the_landing_through_every_hop_to_the_rest():
    velocity, spin = landing(25.0, 40.0, 2500)
    for slope in (0.0, 1.0):
        phase = ground_phase(ORIGIN, velocity, spin, SURFACES["fairway"], slope, 30.0, keep_path=True)
        path = phase.paths[0]
        assert np.all(np.diff(path.times_s) >= 0) and path.times_s[0] == 0.0
        np.testing.assert_allclose(path.positions[-1], phase.rest_position[0])
        np.testing.assert_allclose(path.velocities[0], velocity[0])
        heights = path.positions @ plane_normals(slope, 30.0, 1)[0]
        assert np.all(heights > -1e-9) and np.all(heights < 1e-6)


def test_slopes_steeper_than_a_surface_holds_are_refused():
    limit = float(holding_slope_deg(surface("green").rolling_resistance))
    velocity, spin = landing(20.0, 45.0, 3000)
    with pytest.raises(ValueError, match=f"{limit:.2f} deg"):
        ground_phase(ORIGIN, velocity, spin, surface("green"), slope_deg=limit + 0.1)


def test_surface_presets_are_overridable_and_stimp_is_for_greens_only():
    assert surface("fairway", critical_angle_deg=3.0).critical_angle_deg == 3.0
    assert surface("green", 12.0).rolling_resistance < surface("green", 9.0).rolling_resistance
    with pytest.raises(ValueError, match="stimp_ft"):
        surface("rough", 10.0)
    with pytest.raises(ValueError, match="not one of"):
        surface("carpet")


def test_one_ball_on_plain_floats_is_the_batch():
    """`ground_phase_one` (the engine's one-shot path) runs the batch's formulas on floats: same rest, hops and
    recorded path."""
    rng = np.random.default_rng(5)
    for _ in range(200):
        speed, angle, heading = rng.uniform(3, 35), rng.uniform(2, 80), rng.uniform(0, 360)
        a, h = math.radians(angle), math.radians(heading)
        across, down = speed * math.cos(a), -speed * math.sin(a)
        velocity = np.array([across * math.sin(h), across * math.cos(h), down])
        spin, position = rng.normal(0, 400, 3), rng.uniform(-3, 3, 3)
        where = SURFACES[rng.choice(list(SURFACES))]
        slope = 0.0 if rng.random() < 0.5 else rng.uniform(0, 0.9) * float(holding_slope_deg(where.rolling_resistance))
        slope_dir = rng.uniform(0, 360)
        batch = ground_phase(position[None], velocity[None], spin[None], where, slope, slope_dir, keep_path=True)
        one = ground_phase_one(tuple(position), tuple(velocity), tuple(spin), where, slope, slope_dir, keep_path=True)
        np.testing.assert_allclose(one.position, batch.rest_position[0], atol=1e-6)
        assert one.bounces == batch.bounces[0] and one.time_s == pytest.approx(batch.time_s[0], abs=1e-6)
        path, kept = one.path, batch.paths[0]  # the path a served shot's screen draws: the batch's, state by state
        for mine, theirs in ((path.times_s, kept.times_s), (path.positions, kept.positions),
                             (path.velocities, kept.velocities)):
            np.testing.assert_allclose(mine, theirs, atol=1e-6)
