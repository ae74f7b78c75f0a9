"""The side-curvature analysis of docs/training_real.md: its regression and its scaled coefficients, on cases
worked by hand."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from golfflight.flight.field import ScaledCoefficients

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "side_curvature.py"
spec = importlib.util.spec_from_file_location("side_curvature", SCRIPT)
side_curvature = importlib.util.module_from_spec(spec)
spec.loader.exec_module(side_curvature)


def test_axis_slope_recovers_a_known_slope_beside_the_direction():
    rng = np.random.default_rng(0)
    axis, direction = rng.normal(0, 10, 400), rng.normal(0, 3, 400)
    errors = -0.2 * axis + 0.5 * direction + 1.0 + rng.normal(0, 0.1, 400)
    slope, se = side_curvature.axis_slope(errors, {"spin_axis_deg": axis, "launch_direction_deg": direction})
    assert abs(slope + 0.2) < 3 * se
    assert 0.0003 < se < 0.002  # 0.1 / (10 * sqrt(400)) = 0.0005


def test_scaled_coefficients_scale_lift_and_drag_only():
    class Constant:
        def __call__(self, v_rel, omega):
            return np.tile([0.2, 0.3, 0.01, 0.5], (len(v_rel), 1))

    scaled = ScaledCoefficients(Constant(), np.tile([1.1, 0.9, 1.0], (3, 1))).take(np.array([0, 1]))
    out = scaled(np.ones((2, 3)), np.ones((2, 3)))
    np.testing.assert_allclose(out, [[0.22, 0.27, 0.01, 0.5]] * 2)


def test_monitor_profile_scales_the_axis_shifts_the_launch_and_scales_the_spin():
    launch = {"ball_speed_mps": np.array([70.0]), "launch_angle_deg": np.array([12.0]),
              "launch_direction_deg": np.array([1.0]), "spin_rpm": np.array([2500.0]), "spin_axis_deg": np.array([-8.0])}
    read = side_curvature.monitor_profile(launch, np.array([1.25, -0.5, 1.1, 0.0]))
    assert read["spin_axis_deg"][0] == -10.0 and read["launch_angle_deg"][0] == 11.5
    assert read["spin_rpm"][0] == pytest.approx(2750.0)
    assert read["ball_speed_mps"][0] == 70.0 and read["launch_direction_deg"][0] == 1.0
    turned = side_curvature.monitor_profile(launch, np.array([1.0, 0.0, 1.0, -0.75]))
    assert turned["launch_direction_deg"][0] == 0.25 and turned["spin_axis_deg"][0] == -8.0
    assert launch["spin_axis_deg"][0] == -8.0  # the recorded launch is left as it was


def test_group_constants_take_out_a_crosswind_that_follows_the_groups_axes():
    rng = np.random.default_rng(1)
    groups = np.repeat(np.arange(10), 40)
    axis = rng.normal(0, 5, 400) + 2.0 * groups  # later blocks fade more ...
    wind_push = 0.5 * groups  # ... and had more crosswind
    errors = -0.2 * axis + wind_push + rng.normal(0, 0.1, 400)
    launch = {"spin_axis_deg": axis, "launch_direction_deg": rng.normal(0, 3, 400)}
    pooled, _ = side_curvature.axis_slope(errors, launch)
    within, se = side_curvature.axis_slope(errors, launch, groups)
    assert pooled > -0.15  # the wind's trend with the block hides part of the slope
    assert abs(within + 0.2) < 3 * se
