"""Shared tiny data: shots flown through Ferguson et al.'s quadratics (RK4, fine step) and written as canonical CSV;
and the shared data folder less its held-out rows."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.coefficients import QuadraticSpinRatio
from golfflight.flight.engine import FlightEngine
from golfflight.flight.physics import initial_state
from golfflight.shots.heldout import ROUND_COLUMN, HeldOutSet, held_out_set
from golfflight.shots.records import ShotRecord, write_shots

from flights import simulate


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


def _write_trainable_rows(source: Path, target: Path, held: HeldOutSet) -> None:
    """`source` less its held-out rows: the lines before `first_line`, or the rows of the rounds not held out."""
    with source.open(newline="", encoding="utf-8-sig") as handle:
        rows = list(csv.reader(handle))
    if held.rounds:
        column = rows[0].index(ROUND_COLUMN)
        rows = rows[:1] + [row for row in rows[1:] if not held.holds_round(int(row[column]))]
    else:
        rows = rows[: held.first_line - 1]
    with target.open("w", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerows(rows)


def trainable_copy(root: Path, out: Path) -> Path:
    """The shared data folder `root` rebuilt under `out` without a held-out row (`shots.heldout`): every other file a
    link to the original, a file split by lines or rounds rewritten with its trainable rows, a file held out whole
    left out. What is built from it and from `root` must be the same."""
    for path in root.rglob("*"):
        held = held_out_set(path) if path.is_file() else None
        if not path.is_file() or (held is not None and held.whole):
            continue
        target = out / path.relative_to(root)
        target.parent.mkdir(parents=True, exist_ok=True)
        if held is None:
            target.symlink_to(path)
        else:
            _write_trainable_rows(path, target, held)
    return out


@pytest.fixture(scope="module")
def engine() -> FlightEngine:
    """The shipped model's engine, loaded once a test module."""
    return FlightEngine(model_dir())


@pytest.fixture(scope="module")
def one_torch_thread():
    """One torch thread for a module: the 2-core test machines run other work, where a second thread waits more than
    it helps."""
    import torch  # here, not at the top: most tests must run without torch imported

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)
