"""Shared tiny data: shots flown through Ferguson et al.'s quadratics (RK4, fine step) and written as canonical CSV."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from flight.coefficients import QuadraticSpinRatio
from flight.integrator import simulate
from flight.physics import initial_state
from shots.records import ShotRecord, write_shots


def random_launches(n: int, seed: int = 0) -> dict[str, np.ndarray]:
    """Plausible launches from wedges to drivers (m/s, deg, rpm)."""
    rng = np.random.default_rng(seed)
    speed = rng.uniform(30.0, 75.0, n)
    return {
        "ball_speed_mps": speed,
        "launch_angle_deg": rng.uniform(9.0, 30.0, n),
        "launch_direction_deg": rng.uniform(-6.0, 6.0, n),
        "spin_rpm": rng.uniform(2000.0, 9000.0, n) * (1.0 - 0.5 * (speed - 30.0) / 45.0),
        "spin_axis_deg": rng.uniform(-20.0, 20.0, n),
    }


def write_synthetic_shots(path: Path, n: int, seed: int = 0, val_fraction: float = 0.2) -> Path:
    """Fly `n` launches with RK4 (dt 0.01 s) through Ferguson's coefficients; the last shots are the val split."""
    launch = random_launches(n, seed)
    flight = simulate(initial_state(**launch), QuadraticSpinRatio(), density=1.225, dt=0.01, t_max=15.0, method="rk4")
    n_val = int(round(n * val_fraction))
    records = [
        ShotRecord(
            shot_id=f"s{i}",
            split="val" if i >= n - n_val else "train",
            **{k: float(v[i]) for k, v in launch.items()},
            carry_x_m=float(flight.landing_position[i, 0]),
            carry_y_m=float(flight.landing_position[i, 1]),
            apex_m=float(flight.apex_m[i]),
        )
        for i in range(n)
        if flight.landed[i]
    ]
    write_shots(path, records)
    return path


@pytest.fixture(scope="session")
def tiny_shots(tmp_path_factory) -> Path:
    """About 200 shots (160 train, 40 val)."""
    return write_synthetic_shots(tmp_path_factory.mktemp("data") / "tiny.csv", 200, seed=1)
