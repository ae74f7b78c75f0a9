"""The per-source air of scripts/source_air.py: which cells it moves and what denser air means, worked by hand."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from flight.air import Air
from shots.calibrate_reference import CalibrationCell
from shots.reference_world import CALIBRATION_AIR

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "source_air.py"
spec = importlib.util.spec_from_file_location("source_air", SCRIPT)
source_air = importlib.util.module_from_spec(spec)
spec.loader.exec_module(source_air)

KNOWN_AIR = Air.from_conditions(temperature_c=25.0, altitude_m=346.0, humidity_pct=50.0)


def cell(name: str, air: Air) -> CalibrationCell:
    launch = {k: np.array([1.0]) for k in ("ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm",
                                           "spin_axis_deg")}
    return CalibrationCell(name, launch, air, np.array([[100.0, 20.0, 40.0]]))


def test_only_sources_without_recorded_air_get_a_factor():
    cells = [cell("players-2020 0-52 m/s", CALIBRATION_AIR), cell("players-2020 52-60 m/s", CALIBRATION_AIR),
             cell("trackman-normalized-7iron >= 0 m/s", KNOWN_AIR)]
    assert source_air.unrecorded_sources(cells) == ["players-2020"]
    moved = source_air.with_factors(cells, {"players-2020": 1.02})
    assert moved[2] is cells[2]
    assert moved[0].air.density_kg_m3 == pytest.approx(1.02 * CALIBRATION_AIR.density_kg_m3)


def test_denser_air_at_the_same_temperature_keeps_the_dynamic_viscosity():
    denser = source_air.in_denser_air(cell("sentry-2022 >= 72 m/s", CALIBRATION_AIR), 1.05).air
    mu = CALIBRATION_AIR.density_kg_m3 * CALIBRATION_AIR.kinematic_viscosity_m2_s
    assert denser.density_kg_m3 * denser.kinematic_viscosity_m2_s == pytest.approx(mu)
    assert denser.kinematic_viscosity_m2_s == pytest.approx(CALIBRATION_AIR.kinematic_viscosity_m2_s / 1.05)
