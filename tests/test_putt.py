"""Putts (flight.ground.putt_phase, FlightEngine.putt) against hand-worked cases: the stimpmeter's own definition, a
spinless skid, back spin, a launch monitor's putts on a stimp-11 green, slopes, and slopes too steep to hold a ball."""

from __future__ import annotations

import math

import numpy as np
import pytest
from golfflight.flight.constants import BALL_RADIUS_M, FOOT_M, GRAVITY_MPS2, RPM_TO_RADPS
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.ground import SKID_FRICTION, GroundSpec, holding_slope_deg, putt_phase, surface
from golfflight.flight.ground.phase import MAX_ROLL_TIME_S
from golfflight.flight.ground.surfaces import STIMPMETER_EXIT_SPEED_MPS, green_rolling_resistance
from golfflight.flight.physics import initial_state

TOP_SPIN_AXIS_DEG = 180.0
"""omega = |omega| (cos psi, 0, -sin psi) is -x at psi = 180: top spin for a ball moving to +y."""


def rolling_rpm(speed_mps: float) -> float:
    """The top spin of a ball rolling at `speed_mps` (v = R omega)."""
    return speed_mps / BALL_RADIUS_M / RPM_TO_RADPS


@pytest.mark.parametrize("stimp_ft", [8.0, 11.0, 13.0])
def test_a_ball_rolling_off_the_stimpmeter_stops_at_the_reading(stimp_ft):
    """The stimpmeter's definition: a ball rolling at 1.83 m/s stops after S feet. By hand: no slip, so no skid, then
    c_r = v0^2 / (2 g S) brings it to rest after v0^2 / (2 c_r g) = S."""
    v = STIMPMETER_EXIT_SPEED_MPS
    rolled = putt_phase(v, 0.0, 0.0, rolling_rpm(v), TOP_SPIN_AXIS_DEG, surface("green", stimp_ft=stimp_ft))
    assert rolled.skid_m == pytest.approx(0.0, abs=1e-9)
    assert rolled.position[1] == pytest.approx(stimp_ft * FOOT_M, rel=0.01)
    assert rolled.position[0] == pytest.approx(0.0, abs=1e-9) and rolled.position[2] == 0.0


def test_a_spinless_putt_skids_then_rolls_off_at_five_sevenths():
    """By hand: friction mu m g slows the centre, dv/dt = -mu g, and spins the ball up, d omega/dt = mu m g R / I =
    (5/2) mu g / R, so the slip v - R omega falls at (7/2) mu g from v0 and the skid lasts t = 2 v0 / (7 mu g). Then
    v = v0 - mu g t = 5/7 v0, and the skid's length is v0 t - mu g t^2 / 2 = (2/7 - 2/49) v0^2 / (mu g)
    = 12/49 v0^2 / (mu g). The roll then runs (5/7 v0)^2 / (2 c_r g) more."""
    v0, mu, green = 2.0, SKID_FRICTION, surface("green", stimp_ft=11.0)
    rolled = putt_phase(v0, 0.0, 0.0, 0.0, 0.0, green, keep_path=True)
    assert rolled.skid_time_s == pytest.approx(2 * v0 / (7 * mu * GRAVITY_MPS2), rel=1e-12)
    assert rolled.skid_m == pytest.approx(12 / 49 * v0**2 / (mu * GRAVITY_MPS2), rel=1e-12)
    np.testing.assert_allclose(rolled.path.velocities[1], [0.0, 5 / 7 * v0, 0.0], atol=1e-12)
    roll = (5 / 7 * v0) ** 2 / (2 * float(green.rolling_resistance) * GRAVITY_MPS2)
    assert rolled.position[1] == pytest.approx(12 / 49 * v0**2 / (mu * GRAVITY_MPS2) + roll, rel=1e-9)


def test_back_spin_skids_longer_and_rolls_off_slower():
    """By hand: back spin omega about +x (the flight's convention at spin axis 0) starts the slip at v0 + R omega; the
    ball rolls off at 5/7 v0 - 2/7 R omega after a skid of 2 (v0 + R omega) / (7 mu g)."""
    v0, rpm = 2.0, 300.0
    w = rpm * RPM_TO_RADPS
    rolled = putt_phase(v0, 0.0, 0.0, rpm, 0.0, surface("green", stimp_ft=11.0), keep_path=True)
    assert rolled.skid_time_s == pytest.approx(2 * (v0 + BALL_RADIUS_M * w) / (7 * SKID_FRICTION * GRAVITY_MPS2))
    assert rolled.path.velocities[1][1] == pytest.approx(5 / 7 * v0 - 2 / 7 * BALL_RADIUS_M * w, rel=1e-12)
    spinless = putt_phase(v0, 0.0, 0.0, 0.0, 0.0, surface("green", stimp_ft=11.0))
    assert rolled.skid_m > spinless.skid_m and rolled.position[1] < spinless.position[1]


@pytest.mark.parametrize("back_spin_rpm", [0.0, 150.0, 300.0])
def test_a_launch_monitor_putt_on_a_stimp_11_green(engine: FlightEngine, back_spin_rpm):
    """A 4.09 mph (1.83 m/s) putt at 2 degrees rolls 1.5-4.0 m, and twice as fast 2.5-5.5 times as far, on the
    ground throughout. By hand, with no spin: 12/49 v^2 / (mu g) + 25/98 v^2 / (c_r g) with v = 1.83 cos 2 deg."""
    green = GroundSpec(surface=surface("green", stimp_ft=11.0))
    putt = engine.putt(Launch(1.83, 2.0, 0.0, back_spin_rpm, 0.0), green, keep_states=True)
    twice = engine.putt(Launch(3.66, 2.0, 0.0, back_spin_rpm, 0.0), green)
    assert 1.5 <= putt.rest.total_m <= 4.0
    assert 2.5 <= twice.rest.total_m / putt.rest.total_m <= 5.5
    assert putt.states.positions[:, 2].max() - putt.states.positions[0, 2] <= 0.05
    assert (putt.carry_m, putt.apex_m, putt.flight_time_s, putt.landing_angle_deg) == (0.0, 0.0, 0.0, 0.0)
    assert (putt.landing_x_m, putt.landing_y_m, putt.landing_speed_mps) == (0.0, 0.0, 1.83)
    assert putt.landing_spin_rpm == back_spin_rpm and putt.rest.roll_m == putt.rest.total_m
    assert putt.rest.bounces == 0 and putt.rest.ground_time_s == pytest.approx(putt.states.times_s[-1])
    assert putt.states.times_s[0] == 0.0 and np.all(np.diff(putt.states.times_s) > 0)
    np.testing.assert_allclose(putt.states.positions[-1, :2], [putt.rest.x_m, putt.rest.y_m])
    if back_spin_rpm == 0.0:
        v = 1.83 * math.cos(math.radians(2.0))
        c_r = float(green_rolling_resistance(11.0))
        by_hand = 12 / 49 * v**2 / (SKID_FRICTION * GRAVITY_MPS2) + 25 / 98 * v**2 / (c_r * GRAVITY_MPS2)
        assert putt.rest.total_m == pytest.approx(by_hand, rel=1e-9)


def test_a_putt_on_a_slope_breaks_downhill():
    """A putt across a 2 degree slope falling right ends right of the line (left for one falling left, mirrored); one
    rolling straight down the slope, by hand, decelerates at c_r g cos(phi) - 5/7 g sin(phi) and runs
    v^2 / (2 (c_r g cos(phi) - 5/7 g sin(phi))), v = 1.83 cos(phi) (the horizontal launch projected onto the
    plane), here with the top spin that makes it roll from the start."""
    green = surface("green", stimp_ft=11.0)
    right = putt_phase(1.83, 2.0, 0.0, 150.0, 0.0, green, slope_deg=2.0, slope_dir_deg=90.0, keep_path=True)
    left = putt_phase(1.83, 2.0, 0.0, 150.0, 0.0, green, slope_deg=2.0, slope_dir_deg=270.0)
    assert right.position[0] > 0.1 and left.position[0] == pytest.approx(-right.position[0])
    assert np.all(np.diff(right.path.positions[:, 0]) >= 0.0)
    phi = math.radians(3.0)
    v = 1.83 * math.cos(phi)
    down = putt_phase(1.83, 0.0, 0.0, rolling_rpm(v), TOP_SPIN_AXIS_DEG, green, slope_deg=3.0, slope_dir_deg=0.0)
    braking = float(green.rolling_resistance) * GRAVITY_MPS2 * math.cos(phi) - 5 / 7 * GRAVITY_MPS2 * math.sin(phi)
    assert down.skid_m == pytest.approx(0.0, abs=1e-9)
    assert math.hypot(*down.position) == pytest.approx(v**2 / (2 * braking), rel=0.01)


def test_a_slope_steeper_than_the_green_holds_is_refused():
    """By hand: a green of stimp 11 holds a ball on slopes below atan(7/5 c_r) = 4.07 degrees."""
    green = surface("green", stimp_ft=11.0)
    holding = float(holding_slope_deg(green.rolling_resistance))
    assert holding == pytest.approx(math.degrees(math.atan(1.4 * float(green_rolling_resistance(11.0)))))
    with pytest.raises(ValueError, match="slope_deg"):
        putt_phase(1.83, 2.0, 0.0, 0.0, 0.0, green, slope_deg=holding + 0.5)
    with pytest.raises(ValueError, match="slope_deg"):
        GroundSpec(surface=green, slope_deg=holding + 0.5)
    held = putt_phase(1.83, 2.0, 0.0, 0.0, 0.0, green, slope_deg=holding - 0.5, slope_dir_deg=90.0)
    assert held.time_s < MAX_ROLL_TIME_S and held.position[0] > 0.0


def test_a_putt_rolls_on_its_green_where_that_green_lies(engine: FlightEngine):
    """A bay's green 3 m below the tee: the putt's states lie on it (z = -3 m), the same roll as on a green at 0."""
    level = engine.putt(Launch(1.83, 2.0, 0.0, 100.0, 0.0), GroundSpec(surface=surface("green", 11.0)), True)
    below = engine.putt(Launch(1.83, 2.0, 0.0, 100.0, 0.0),
                        GroundSpec(surface=surface("green", 11.0), elevation_m=-3.0), True)
    np.testing.assert_allclose(below.states.positions[:, 2], -3.0)
    np.testing.assert_allclose(below.states.positions[:, :2], level.states.positions[:, :2])
    assert below.rest == level.rest


def test_a_putt_starts_from_the_flights_launch_state():
    """A putt's start is the launch state a flight starts from (`flight.launch_state`, as `initial_state` gives it),
    projected onto level ground: the same velocity to the last bit, its vertical part dropped; and with the spin of
    that state, a putt skids for |v + R e_z x omega| / (3.5 mu g)."""
    rng = np.random.default_rng(58)
    launches = np.stack([rng.uniform(0.5, 6.0, 40), rng.uniform(-3.0, 6.0, 40), rng.uniform(-15.0, 15.0, 40),
                         rng.uniform(0.0, 400.0, 40), rng.uniform(-180.0, 180.0, 40)], -1)
    start = initial_state(*launches.T)
    green = surface("green", 11.0)
    for launch, velocity, spin in zip(launches.tolist(), start.velocity, start.spin, strict=True):
        putt = putt_phase(*launch, green, keep_path=True)
        np.testing.assert_array_equal(putt.path.velocities[0], [velocity[0], velocity[1], 0.0])
        slip = velocity[:2] + BALL_RADIUS_M * np.array([-spin[1], spin[0]])
        skid_time = math.hypot(*slip.tolist()) / (3.5 * SKID_FRICTION * GRAVITY_MPS2)
        assert putt.skid_time_s == pytest.approx(skid_time, rel=1e-12)
