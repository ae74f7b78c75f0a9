"""Air density, viscosity and wind against published values (US Standard Atmosphere, Tetens, Sutherland)."""

import numpy as np
import pytest
from golfflight.contract.inputs import air_of
from golfflight.contract.requests import ReferenceAir
from golfflight.flight.air import Air, air_density, altitude_for_pressure, dynamic_viscosity, pressure_at_altitude
from golfflight.flight.conditions import NORMALIZED_REFERENCE
from golfflight.flight.wind import Wind, log_profile_factor, uniform_equivalent_factor, wind_vector


def test_standard_sea_level_density():
    assert air_density(15.0, 101325.0, 0.0) == pytest.approx(1.225, abs=0.001)
    assert Air.standard().density_kg_m3 == pytest.approx(1.225, abs=0.001)


def test_warm_dry_air_is_thinner():
    assert air_density(25.0, 101325.0, 0.0) == pytest.approx(1.184, abs=0.001)


@pytest.mark.parametrize("temperature_c, humidity_pct, change", [(15.0, 50.0, -0.003), (40.0, 100.0, -0.027)])
def test_humid_air_is_lighter_by_the_published_amount(temperature_c, humidity_pct, change):
    dry = air_density(temperature_c, 101325.0, 0.0)
    moist = air_density(temperature_c, 101325.0, humidity_pct)
    assert moist / dry - 1 == pytest.approx(change, abs=0.001)


def test_standard_atmosphere_pressure_and_its_inverse():
    assert pressure_at_altitude(0.0) == pytest.approx(101325.0)
    assert pressure_at_altitude(1000.0) == pytest.approx(89874.6, rel=1e-4)
    assert pressure_at_altitude(7800 * 0.3048) / 101325.0 == pytest.approx(75840.0 / 101325.0, abs=0.002)
    assert altitude_for_pressure(pressure_at_altitude(np.array([-300.0, 2377.0]))) == pytest.approx([-300.0, 2377.0])


def test_station_pressure_overrides_altitude():
    by_pressure = Air.from_conditions(20.0, altitude_m=0.0, pressure_pa=pressure_at_altitude(1500.0))
    by_altitude = Air.from_conditions(20.0, altitude_m=1500.0)
    assert by_pressure.density_kg_m3 == pytest.approx(by_altitude.density_kg_m3)


def test_sutherland_viscosity_of_air():
    assert dynamic_viscosity(15.0) == pytest.approx(1.789e-5, rel=2e-3)
    assert Air.standard().kinematic_viscosity_m2_s == pytest.approx(1.461e-5, rel=3e-3)


def test_one_air_is_floats_and_the_same_numbers_as_a_batch_of_airs():
    """The engine's per-step loop takes floats; a data set's air is arrays; both from the same formulas."""
    one = Air.from_conditions(31.0, 1234.0, 65.0)
    batch = Air.from_conditions(np.array([31.0, 15.0]), np.array([1234.0, 0.0]), np.array([65.0, 0.0]))
    assert type(one.density_kg_m3) is float and type(one.kinematic_viscosity_m2_s) is float
    first = (batch.density_kg_m3[0], batch.kinematic_viscosity_m2_s[0])
    assert first == pytest.approx((one.density_kg_m3, one.kinematic_viscosity_m2_s), rel=1e-14)
    assert batch.density_kg_m3[1] == pytest.approx(Air.standard().density_kg_m3, rel=1e-14)


def test_an_explicit_density_keeps_the_standard_viscosity():
    """A density alone is air of that density at 15 degC: its kinematic viscosity is mu(15 degC) / density."""
    thin = Air.from_density(1.0)
    assert thin.density_kg_m3 == 1.0 and thin.kinematic_viscosity_m2_s == float(dynamic_viscosity(15.0)) / 1.0
    assert Air.from_density(Air.standard().density_kg_m3) == Air.standard()


def test_a_normalized_flight_by_default_flies_in_the_normalized_reference_air():
    assert air_of(ReferenceAir()) == NORMALIZED_REFERENCE.air


@pytest.mark.parametrize("from_deg, direction", [(0.0, (0, -1)), (90.0, (-1, 0)), (180.0, (0, 1)), (270.0, (1, 0))])
def test_wind_blows_away_from_where_it_comes_from(from_deg, direction):
    assert wind_vector(4.0, from_deg) == pytest.approx([4.0 * direction[0], 4.0 * direction[1], 0.0], abs=1e-12)


def test_log_profile_is_reference_speed_at_reference_height_and_still_at_the_ground():
    assert log_profile_factor(10.0, 10.0, 0.02) == pytest.approx(1.0)
    assert log_profile_factor(0.01, 10.0, 0.02) == 0.0
    heights = np.array([1.0, 5.0, 20.0, 40.0])
    assert np.all(np.diff(log_profile_factor(heights, 10.0, 0.02)) > 0)
    wind = Wind(5.0, 0.0, profile="log", reference_height_m=10.0, roughness_m=0.02)
    assert wind.velocity(np.array([10.0, 0.0]))[:, 1] == pytest.approx([-5.0, 0.0])


def test_uniform_equivalent_of_a_log_profile_averages_over_time_aloft():
    """Two flights sampled at equal steps: one at 10 m for four steps (factor 1), one at 40 m for two steps then
    landed (factor ln(2000)/ln(500) = 1.2231): the mean of the two time averages."""
    nan = np.nan
    heights = np.array([[10.0, 40.0], [10.0, 40.0], [10.0, nan], [10.0, nan]])
    expected = (1.0 + np.log(40.0 / 0.02) / np.log(10.0 / 0.02)) / 2
    assert uniform_equivalent_factor(heights, 10.0, 0.02) == pytest.approx(expected, rel=1e-12)
    assert uniform_equivalent_factor(heights, 10.0, 0.02) == pytest.approx(1.1115, abs=1e-4)


def test_uniform_wind_is_the_same_at_every_height_and_per_shot_arrays_work():
    wind = Wind(np.array([3.0, 6.0]), np.array([0.0, 180.0]))
    assert wind.velocity(np.array([1.0, 30.0]))[:, 1] == pytest.approx([-3.0, 6.0])
    assert not wind.is_calm and Wind().is_calm
