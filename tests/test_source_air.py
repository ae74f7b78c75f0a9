"""Each source's stated air (shots.source_air) and the calibration's fitted air factor for a source that recorded
none (shots.calibrate_reference), worked by hand."""

import math

import numpy as np
import pytest
from golfflight.flight.air import Air
from golfflight.shots.calibrate_reference import CalibrationCell, with_air_factors
from golfflight.shots.reference_world import CALIBRATION_AIR
from golfflight.shots.source_air import KNOWN_AIR, PGA_2023_TABLE, TOUR_CHAMPIONSHIP_2020, SourceAir

RHO_0 = 1.2250  # ICAO standard density, kg/m^3


def cell(name: str, air: Air) -> CalibrationCell:
    launch = {k: np.array([1.0]) for k in ("ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm",
                                           "spin_axis_deg")}
    return CalibrationCell(name, launch, air, np.array([[100.0, 20.0, 40.0]]))


def test_the_tour_table_flies_in_99_percent_of_standard_density():
    assert PGA_2023_TABLE.air().density_kg_m3 == pytest.approx(0.99 * RHO_0, rel=2e-4)
    assert PGA_2023_TABLE.density_ratio() == pytest.approx(0.99, abs=1e-9)


def test_east_lake_in_september_by_hand():
    """US Standard Atmosphere and Tetens: P = 101325 (1 - 2.25577e-5 H)^5.255876;
    e = RH 6.1078 exp(17.27 t/(t + 237.3)) hPa; rho = (P - e)/(287.05 T) + e/(461.5 T).
    988 ft = 301.14 m, 29 C, 60 %."""
    pressure = 101325 * (1 - 2.25577e-5 * 301.1424) ** 5.255876
    vapour = 0.60 * 6.1078 * math.exp(17.27 * 29 / (29 + 237.3)) * 100
    density = (pressure - vapour) / (287.05 * 302.15) + vapour / (461.5 * 302.15)
    assert TOUR_CHAMPIONSHIP_2020.air().density_kg_m3 == pytest.approx(density, rel=1e-9)
    assert 0.90 < density / RHO_0 < 0.92


@pytest.mark.parametrize("name", sorted(KNOWN_AIR))
def test_a_sources_record_conditions_give_back_its_air(name):
    air = KNOWN_AIR[name]
    conditions = air.record_conditions()
    again = Air.from_conditions(conditions["temperature_c"], conditions.get("altitude_m", 0.0),
                                conditions["humidity_pct"],
                                None if "pressure_hpa" not in conditions else conditions["pressure_hpa"] * 100)
    assert again.density_kg_m3 == pytest.approx(air.air().density_kg_m3, rel=1e-12)
    assert air.basis


def test_a_pressure_wins_over_an_altitude():
    air = SourceAir(temperature_c=15.0, humidity_pct=0.0, basis="test", altitude_m=3000.0, pressure_hpa=1013.25)
    assert air.air().density_kg_m3 == pytest.approx(RHO_0, rel=1e-4)


def test_only_the_named_sources_get_their_factor():
    cells = [cell("trackman-outdoor 0-52 m/s", CALIBRATION_AIR), cell("trackman-outdoor 52-60 m/s", CALIBRATION_AIR),
             cell("players-2020 >= 72 m/s", KNOWN_AIR["players-2020"].air())]
    moved = with_air_factors(cells, {"trackman-outdoor": 1.02})
    assert moved[2] is cells[2]
    assert moved[0].air.density_kg_m3 == pytest.approx(1.02 * CALIBRATION_AIR.density_kg_m3)


def test_denser_air_at_the_same_temperature_keeps_the_dynamic_viscosity():
    denser = cell("trackman-outdoor >= 72 m/s", CALIBRATION_AIR).in_denser_air(1.05).air
    mu = CALIBRATION_AIR.density_kg_m3 * CALIBRATION_AIR.kinematic_viscosity_m2_s
    assert denser.density_kg_m3 * denser.kinematic_viscosity_m2_s == pytest.approx(mu)
    assert denser.kinematic_viscosity_m2_s == pytest.approx(CALIBRATION_AIR.kinematic_viscosity_m2_s / 1.05)
