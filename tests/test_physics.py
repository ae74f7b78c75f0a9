"""The NumPy equations of motion against cases worked by hand (the paper's equations, their errata in
flight/physics.py)."""

import numpy as np
import pytest
from golfflight.flight.air import Air
from golfflight.flight.coefficients import ConstantCoefficients, QuadraticSpinRatio
from golfflight.flight.constants import BALL_INERTIA_KG_M2, BALL_MASS_KG, BALL_RADIUS_M, GRAVITY_MPS2, TEE_HEIGHT_M
from golfflight.flight.physics import State, derivatives, initial_state, mechanical_energy
from golfflight.flight.wind import Wind

from flights import simulate

RHO = Air.standard().density_kg_m3


def launch(speed=70.0, angle=12.0, direction=0.0, spin=2800.0, axis=0.0) -> State:
    one = lambda x: np.atleast_1d(np.asarray(x, dtype=float))  # noqa: E731
    return initial_state(one(speed), one(angle), one(direction), one(spin), one(axis))


def test_initial_state_follows_paper_eq_12_and_spin_convention():
    state = launch(speed=50.0, angle=30.0, direction=10.0, spin=3000.0, axis=20.0)
    v = state.velocity[0]
    assert v == pytest.approx([50 * np.cos(np.radians(30)) * np.sin(np.radians(10)),
                               50 * np.cos(np.radians(30)) * np.cos(np.radians(10)),
                               25.0])
    w = 3000 * 2 * np.pi / 60
    assert state.spin[0] == pytest.approx([w * np.cos(np.radians(20)), 0.0, -w * np.sin(np.radians(20))])
    assert state.position[0] == pytest.approx([0.0, 0.0, TEE_HEIGHT_M])


def test_vacuum_flight_matches_closed_form():
    speed, angle = 40.0, 35.0
    vy, vz = speed * np.cos(np.radians(angle)), speed * np.sin(np.radians(angle))
    t_land = (vz + np.sqrt(vz**2 + 2 * GRAVITY_MPS2 * TEE_HEIGHT_M)) / GRAVITY_MPS2
    flight = simulate(launch(speed, angle, spin=0.0), ConstantCoefficients(), RHO, dt=0.01, method="rk4")
    assert flight.flight_time_s[0] == pytest.approx(t_land, abs=1e-5)
    assert flight.landing_position[0, 1] == pytest.approx(vy * t_land, abs=1e-3)
    assert flight.apex_m[0] == pytest.approx(TEE_HEIGHT_M + vz**2 / (2 * GRAVITY_MPS2), abs=1e-3)
    assert flight.landing_angle_deg[0] == pytest.approx(np.degrees(np.arctan2(np.sqrt(vz**2 + 2 * GRAVITY_MPS2 * TEE_HEIGHT_M), vy)), abs=1e-4)


def test_euler_vacuum_flight_converges_to_closed_form_at_first_order():
    exact = simulate(launch(40.0, 35.0, spin=0.0), ConstantCoefficients(), RHO, dt=0.001, method="rk4").carry_m[0]
    errors = [abs(simulate(launch(40.0, 35.0, spin=0.0), ConstantCoefficients(), RHO, dt=dt).carry_m[0] - exact)
              for dt in (0.1, 0.05)]
    assert errors[1] == pytest.approx(errors[0] / 2, rel=0.2)


def test_back_spin_lifts_the_ball():
    horizontal = launch(speed=60.0, angle=0.0, spin=3000.0)
    rate = derivatives(horizontal, ConstantCoefficients(c_lift=0.2, c_drag=0.25), RHO)
    assert rate.velocity[0, 2] > -GRAVITY_MPS2 + 1.0
    assert rate.velocity[0, 0] == pytest.approx(0.0, abs=1e-12)
    with_spin = simulate(launch(spin=3000.0), QuadraticSpinRatio(), RHO)
    no_spin = simulate(launch(spin=0.0), QuadraticSpinRatio(), RHO)
    assert with_spin.apex_m[0] > no_spin.apex_m[0] + 10


@pytest.mark.parametrize("axis, side", [(15.0, 1.0), (-15.0, -1.0)])
def test_spin_axis_curves_the_ball_to_its_side(axis, side):
    flight = simulate(launch(axis=axis), QuadraticSpinRatio(), RHO)
    assert side * flight.lateral_m[0] > 10.0


def test_spin_magnitude_falls_monotonically():
    flight = simulate(launch(spin=6000.0), QuadraticSpinRatio(), RHO, dt=0.01, method="rk4", keep_states=True)
    spin = np.array([np.linalg.norm(s.spin[0]) for s in flight.states])
    assert np.all(np.diff(spin) < 0)
    assert flight.landing_spin_rpm[0] < 6000.0


def test_aerodynamic_power_is_never_positive_without_wind():
    rng = np.random.default_rng(0)
    n = 500
    velocity = rng.normal(size=(n, 3)) * rng.uniform(15, 80, size=(n, 1)) / np.sqrt(3)
    spin_axis = rng.normal(size=(n, 3))
    spin_size = rng.uniform(0, 0.7, size=(n, 1)) * np.linalg.norm(velocity, axis=1, keepdims=True) / BALL_RADIUS_M
    spin = spin_axis / np.linalg.norm(spin_axis, axis=1, keepdims=True) * spin_size
    state = State(rng.normal(size=(n, 3)), velocity, spin)
    rate = derivatives(state, QuadraticSpinRatio(), RHO)
    power = BALL_MASS_KG * np.sum(state.velocity * rate.velocity, -1) + BALL_INERTIA_KG_M2 * np.sum(state.spin * rate.spin, -1)
    power += BALL_MASS_KG * GRAVITY_MPS2 * state.velocity[:, 2]
    assert np.all(power <= 1e-9)


def test_mechanical_energy_falls_along_a_flight_without_wind():
    flight = simulate(launch(), QuadraticSpinRatio(), RHO, dt=0.01, method="rk4", keep_states=True)
    energy = np.array([mechanical_energy(s)[0] for s in flight.states])
    assert np.all(np.diff(energy) < 0)


def test_headwind_shortens_and_tailwind_lengthens_carry():
    calm = simulate(launch(), QuadraticSpinRatio(), RHO).carry_m[0]
    head = simulate(launch(), QuadraticSpinRatio(), RHO, wind=Wind(5.0, 0.0)).carry_m[0]
    tail = simulate(launch(), QuadraticSpinRatio(), RHO, wind=Wind(5.0, 180.0)).carry_m[0]
    assert head < calm - 5 and tail > calm + 3


def test_wind_from_the_right_moves_the_ball_left():
    flight = simulate(launch(), QuadraticSpinRatio(), RHO, wind=Wind(5.0, 90.0))
    assert flight.lateral_m[0] < -3.0


def test_mirror_symmetry_of_spin_axis_and_direction():
    right = simulate(launch(direction=3.0, axis=12.0), QuadraticSpinRatio(), RHO)
    left = simulate(launch(direction=-3.0, axis=-12.0), QuadraticSpinRatio(), RHO)
    assert left.landing_position[0, 0] == pytest.approx(-right.landing_position[0, 0], abs=1e-9)
    assert left.landing_position[0, 1] == pytest.approx(right.landing_position[0, 1], abs=1e-9)
    assert left.apex_m[0] == pytest.approx(right.apex_m[0], abs=1e-12)


def test_batch_gives_the_same_flights_as_single_shots():
    speeds, angles, spins = np.array([75.0, 55.0, 40.0]), np.array([10.0, 16.0, 28.0]), np.array([2600.0, 7000.0, 9500.0])
    batch = simulate(initial_state(speeds, angles, np.zeros(3), spins, np.zeros(3)), QuadraticSpinRatio(), RHO)
    for i in range(3):
        single = simulate(launch(speeds[i], angles[i], spin=spins[i]), QuadraticSpinRatio(), RHO)
        assert batch.carry_m[i] == pytest.approx(single.carry_m[0], abs=1e-12)


def test_landing_on_raised_or_lowered_ground():
    flat = simulate(launch(), QuadraticSpinRatio(), RHO, dt=0.01, method="rk4")
    below = simulate(launch(), QuadraticSpinRatio(), RHO, dt=0.01, method="rk4", ground_height_m=-5.0)
    above = simulate(launch(), QuadraticSpinRatio(), RHO, dt=0.01, method="rk4", ground_height_m=5.0)
    assert below.carry_m[0] > flat.carry_m[0] > above.carry_m[0]
    assert below.landing_position[0, 2] == pytest.approx(-5.0)


def test_shot_that_never_comes_down_is_reported_not_landed():
    flight = simulate(launch(speed=80.0, angle=60.0, spin=0.0), ConstantCoefficients(), RHO, t_max=2.0)
    assert not flight.landed[0] and np.isnan(flight.carry_m[0])


def test_ferguson_driver_matches_published_open_model_figures():
    """Ferguson, McNally & McPhee 2022's coefficients fly the PGA driver to about 290.7 yd carry, 32.5 yd apex,
    36.0 deg."""
    air = Air.from_conditions(25.0, 0.0, 50.0)
    flight = simulate(launch(171 * 0.44704, 10.4, spin=2545.0), QuadraticSpinRatio(), air.density_kg_m3, dt=0.005, method="rk4")
    assert flight.carry_m[0] / 0.9144 == pytest.approx(290.7, abs=3.0)
    assert flight.apex_m[0] / 0.9144 == pytest.approx(32.5, abs=1.5)
    assert flight.landing_angle_deg[0] == pytest.approx(36.0, abs=1.5)
