"""The ground phase (flight.ground) against hand-worked cases and published numbers: a dead drop, back spin, slopes,
the stimpmeter, shallow driver landings, energy at every impact (hypothesis), batch against one by one, Penner's
tilt and its cap, the pitch mark's wall, the turf's damping of the spin, Haake's back-spin threshold, Biber et al.'s
slipping lift-off, the rough against the fairway and the wind a ball on the ground feels
(tests/test_ground_anchors.py: whole shots against the tour tables)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from golfflight.flight.constants import (
    BALL_AREA_M2,
    BALL_INERTIA_KG_M2,
    BALL_MASS_KG,
    BALL_RADIUS_M,
    FOOT_M,
    GRAVITY_MPS2,
    RPM_TO_RADPS,
)
from golfflight.flight.ground import SURFACES, Surface, ground_phase, ground_phase_one, holding_slope_deg, surface
from golfflight.flight.ground.impact import impact, penner_tilt
from golfflight.flight.ground.phase import plane_normals, stopping
from golfflight.flight.ground.surfaces import (
    ROUGH_OVER_FAIRWAY,
    STIMPMETER_EXIT_SPEED_MPS,
    green_rolling_resistance,
    scaled,
)
from golfflight.flight.wind import FAIRWAY_ROUGHNESS_M, STATION_HEIGHT_M, log_profile_factor
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


def test_back_spin_shortens_the_roll_and_pulls_a_steep_wedge_back():
    rests = [rest_y(20.0, 50.0, rpm, surface("green")) for rpm in (0, 2000, 4000, 6000, 8000)]
    assert np.all(np.diff(rests) < 0)
    assert rests[0] > 5.0
    assert rest_y(20.0, 80.0, 8000, surface("green")) < -0.5
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
    the green's speed is how many feet it then rolls: the roll after the bounces (a green has no grass drag), and a
    putt that starts rolling (tests/test_putt.py)."""
    assert STIMPMETER_EXIT_SPEED_MPS == pytest.approx(1.83, abs=0.005)
    for stimp_ft in (8.0, 10.0, 12.0, 14.0):
        green = surface("green", stimp_ft)
        run, _ = stopping(STIMPMETER_EXIT_SPEED_MPS, green.rolling_resistance * GRAVITY_MPS2, green.grass_drag_per_s)
        assert run == pytest.approx(stimp_ft * FOOT_M, rel=1e-12)
    assert float(green_rolling_resistance(10.0)) == pytest.approx(0.056, abs=0.001)


@pytest.mark.parametrize("angle_deg", [3.0, 6.0, 10.0, 14.0, 20.0])
def test_a_shallow_fast_driver_landing_keeps_running_forward(angle_deg):
    """Taking the landing angle for Penner's theta_1 would make sin(theta_1 - theta_c) negative below theta_c and
    stop these balls dead; on turf they must leave the first impact going forward and run on (sand may stop them)."""
    velocity, spin = landing(30.0, angle_deg, 2500)
    for where in (SURFACES[name] for name in SURFACES if name != "bunker"):
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
    params=st.tuples(st.floats(0.0, 3.0), st.floats(0.0, 45.0), st.floats(0.0, 2.0), st.floats(0.0, 2.0)),
)
def test_energy_never_grows_at_an_impact(speed, angle, heading, spin, slope, slope_dir, params):
    normal = plane_normals(slope, slope_dir, 1)
    a, h = math.radians(angle), math.radians(heading)
    velocity = speed * np.array([[math.cos(a) * math.sin(h), math.cos(a) * math.cos(h), -math.sin(a)]])
    if (velocity @ normal[0])[0] >= 0.0:
        return
    spin = np.array([spin])
    out, spin_out = impact(velocity, spin, normal, Surface(*params, 0.1, 0.0))
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


def test_penners_tilt_grows_with_the_speed_and_the_angle_from_the_normal():
    """theta_c (v / 18.6 m/s)(theta_1 / 44 deg): the surface's angle at Penner's typical landing, twice it at twice
    the speed, half at half the angle, none for a ball dropping straight down, and never past theta_1 or the turf's
    cap: a downwind drive (34.9 m/s, 60.7 deg from the normal) on a green of theta_c 20 would meet
    20 x (34.9 / 18.6) x (60.7 / 44) = 51.8 deg, and meets the green's 38."""
    at = math.radians(44.0)
    assert penner_tilt(15.0, 18.6, at) == pytest.approx(math.radians(15.0))
    assert penner_tilt(15.0, 37.2, at) == pytest.approx(math.radians(30.0))
    assert penner_tilt(15.0, 18.6, at / 2) == pytest.approx(math.radians(7.5))
    assert penner_tilt(15.0, 30.0, 0.0) == 0.0
    assert penner_tilt(30.0, 40.0, math.radians(60.0)) == pytest.approx(math.radians(60.0))  # 88 deg, capped
    drive = math.radians(60.7)
    assert penner_tilt(20.0, 34.9, drive) == pytest.approx(math.radians(20.0 * 34.9 / 18.6 * 60.7 / 44.0))
    assert penner_tilt(20.0, 34.9, drive, 38.0) == pytest.approx(math.radians(38.0))
    assert penner_tilt(20.0, 18.6, at, 38.0) == pytest.approx(math.radians(20.0))  # under the cap: Penner's
    assert surface("green").max_tilt_deg == 38.0 and SURFACES["fairway"].max_tilt_deg == 90.0


def test_the_pitch_marks_wall_takes_forward_speed_and_leaves_the_spin():
    """A 7-iron's landing, 24.6 m/s at 50 deg below the horizontal (40 deg from the normal) with 619 rad/s of back
    spin, on turf of theta_c 20 with no restitution, friction or spin damping: the wall tilts by
    20 x (24.6 / 18.6) x (40 / 44) = 24.05 deg, the ball meets it 15.95 deg from its normal and leaves along it at
    24.6 sin 15.95 deg = 6.761 m/s, 6.175 m/s forward and 2.755 m/s up, its spin untouched: the wall's push runs
    through the ball's centre. Coulomb friction at the contact point cannot do that: it takes 5/2 of a metre per
    second's worth of R omega for every metre per second of forward speed."""
    turf = Surface(0.0, 20.0, 0.0, 0.0, 0.05, 0.0, 38.0)
    velocity, spin = landing(24.6, 50.0, 619.0 / RPM_TO_RADPS)
    out, spin_out = impact(velocity, spin, np.array([[0.0, 0.0, 1.0]]), turf)
    tilt = math.radians(20.0 * 24.6 / 18.6 * 40.0 / 44.0)
    along = 24.6 * math.sin(math.radians(40.0) - tilt)
    assert math.degrees(tilt) == pytest.approx(24.05, abs=0.005) and along == pytest.approx(6.761, abs=5e-4)
    np.testing.assert_allclose(out[0], [0.0, along * math.cos(tilt), along * math.sin(tilt)], atol=1e-12)
    np.testing.assert_allclose(out[0], [0.0, 6.175, 2.755], atol=5e-4)
    np.testing.assert_allclose(spin_out, spin, atol=1e-9)


def test_the_turfs_torque_damps_a_share_of_the_spin_and_never_reverses_it():
    """A ball dropped at 5 m/s on turf without tilt or friction: e = 0.510 - 0.0375 x 5 + 0.000903 x 25 = 0.345075,
    normal impulse (1 + e) 5 = 6.725375 m/s, so a spin damping of 0.1 s/m takes the share 0.6725375 of its spin,
    whatever the spin (300 rad/s keeps 98.24, 50 keeps 16.37), and 0.2 s/m (a share of 1.345) stops it without
    reversing it."""
    impulse = (1.0 + 0.345075) * 5.0
    for damping, share in ((0.1, 0.1 * impulse), (0.2, 1.0)):
        turf = Surface(1.0, 0.0, 0.0, damping, 0.1, 0.0)
        for spin_radps in (300.0, 50.0):
            out, spin_out = impact(np.array([[0.0, 0.0, -5.0]]), np.array([[spin_radps, 0.0, 0.0]]),
                                   np.array([[0.0, 0.0, 1.0]]), turf)
            assert spin_out[0, 0] == pytest.approx(spin_radps * (1.0 - share), abs=1e-9)
            np.testing.assert_allclose(out[0], [0.0, 0.0, 0.345075 * 5.0], atol=1e-12)
    assert 300.0 * (1.0 - 0.1 * impulse) == pytest.approx(98.24, abs=0.005)


def spin_after(where: Surface, back_spin_radps: float, speed: float = 18.6, from_normal_deg: float = 44.0):
    """(forward velocity, back spin) just after one impact on level `where`."""
    velocity, _ = landing(speed, 90.0 - from_normal_deg, 0.0)
    out, spin = impact(velocity, np.array([[back_spin_radps, 0.0, 0.0]]), np.array([[0.0, 0.0, 1.0]]), where)
    return out[0, 1], spin[0, 0]


def test_a_firm_green_lets_a_ball_keep_back_spin_above_about_350_rad_s_and_softer_turf_never():
    """Haake (721 filmed impacts on 18 greens): on firm, freely drained greens the ball keeps back spin through the
    bounce if it came in with more than about 350 rad/s; on the others it leaves with top spin. At Penner's typical
    landing (18.6 m/s, 44 degrees from the normal) the green keeps 370 rad/s as back spin and turns 330 into top
    spin; the fairway and the rough turn even 800 rad/s into top spin. By hand: the green's wall tilts by its 20 deg,
    the ball meets it at 18.6 cos 24 deg = 16.992 m/s, e = 0.75 (0.510 - 0.0375 x 16.992 + 0.000903 x 16.992^2) =
    0.10015, the normal impulse is 1.10015 x 16.992 = 18.694 m/s; the turf damps the share 0.015 x 18.694 = 0.2804 of
    the spin and friction, sliding throughout, takes 0.115 x 18.694 = 2.150 m/s at the contact point, 2.5 / R x 2.150
    = 251.9 rad/s: the spin turns over at 251.9 / (1 - 0.2804) = 350.1 rad/s."""
    assert spin_after(surface("green"), 330.0)[1] < 0.0 < spin_after(surface("green"), 370.0)[1]
    threshold = 2.5 / BALL_RADIUS_M * 0.115 * 18.694 / (1.0 - 0.015 * 18.694)
    assert threshold == pytest.approx(350.1, abs=0.1)
    assert spin_after(surface("green"), threshold - 0.5)[1] < 0.0 < spin_after(surface("green"), threshold + 0.5)[1]
    for name in ("fairway", "rough"):
        assert spin_after(SURFACES[name], 800.0)[1] < 0.0


def test_a_wedge_leaves_a_firm_green_still_slipping_and_the_fairway_rolling():
    """Biber et al.: most bounces lift off still slipping. A pitching wedge's landing (24 m/s at 53 degrees, 830 rad/s)
    leaves the green going forward with back spin, its contact point sliding at metres per second; the fairway's
    friction makes it grip (slip taken out, but for the fitted fairway's hair of tilt)."""
    forward, back_spin = spin_after(surface("green"), 830.0, 24.0, 37.0)
    assert forward > 0.0 and back_spin > 0.0 and forward + BALL_RADIUS_M * back_spin > 5.0
    forward, back_spin = spin_after(SURFACES["fairway"], 830.0, 24.0, 37.0)
    assert forward + BALL_RADIUS_M * back_spin == pytest.approx(0.0, abs=1e-3)


def test_the_rough_soaks_up_at_least_what_the_fairway_does():
    """The rough is the fitted fairway times the anchors' rough-to-fairway ratios: less restitution, no less tilt,
    friction, spin damping, rolling resistance or grass drag."""
    rough, fairway = SURFACES["rough"], SURFACES["fairway"]
    assert rough == scaled(fairway, ROUGH_OVER_FAIRWAY)
    assert rough.restitution_scale < fairway.restitution_scale
    for name in ("critical_angle_deg", "max_tilt_deg", "friction", "spin_damping_s_per_m", "rolling_resistance",
                 "grass_drag_per_s"):
        assert getattr(rough, name) >= getattr(fairway, name), name


def test_wind_on_a_ball_on_the_ground_is_far_below_the_fastest_greens_resistance():
    """The ground phase leaves the wind out. At the ball's centre, 21 mm up, the log profile over grass (z0 = 2 cm)
    has 1 % of an 8 m/s wind at 10 m; even with a drag coefficient of 1 its push is under a thousandth of a stimp-14
    green's rolling resistance."""
    wind = 8.0 * log_profile_factor(BALL_RADIUS_M, STATION_HEIGHT_M, FAIRWAY_ROUGHNESS_M)
    assert wind == pytest.approx(0.083, abs=0.001)
    push = 0.5 * 1.225 * 1.0 * BALL_AREA_M2 * wind**2 / BALL_MASS_KG
    assert push < 1e-3 * float(green_rolling_resistance(14.0)) * GRAVITY_MPS2
