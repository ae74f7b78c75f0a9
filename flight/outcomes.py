"""What a flight's states say about it: the landing angle and the apex between steps, and `Flight`, the outcome of a
batch. Every function works on plain floats (the engine's one-shot latency path) and on NumPy arrays alike, so
both paths derive their figures from the same formulas."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from golfflight.flight.constants import RPM_TO_RADPS
from golfflight.flight.physics import State


def landing_angle_deg(vx, vy, vz):
    """Descent angle below the horizontal (positive, degrees) of a velocity, component by component."""
    if isinstance(vz, np.ndarray):
        return np.degrees(np.arctan2(-vz, np.hypot(vx, vy)))
    return math.degrees(math.atan2(-vz, math.hypot(vx, vy)))


def parabola_apex(before, peak, after, peak_time_s, dt: float):
    """(apex height, apex time) of the parabola through three heights one step apart, the middle one the highest
    state: the integrator's apex between its steps rather than on them (about g dt^2 / 8 higher at most, up to dt / 2
    earlier or later). Where a neighbour is missing (NaN: the launch state) or the three do not bend down, the peak
    state itself."""
    bend = before - 2.0 * peak + after
    rise = before - after
    if isinstance(bend, np.ndarray):
        down = bend < 0.0
        shift = np.where(down, rise / (2.0 * np.where(down, bend, -1.0)), 0.0)
        return np.where(down, peak - rise * shift / 4.0, peak), peak_time_s + shift * dt
    if bend < 0.0:
        shift = rise / (2.0 * bend)
        return peak - rise * shift / 4.0, peak_time_s + shift * dt
    return peak, peak_time_s


@dataclass
class Flight:
    """Outcome of a batch of flights; landing values are NaN where `landed` is False.

    `states` (when recorded) holds the state of every ball at each time of `times_s` (t = 0, dt, 2 dt, ...), a landed
    ball's flying on below its ground; `last_step[i]` is the index of ball i's last state above its ground."""

    landed: np.ndarray
    landing_position: np.ndarray
    landing_velocity: np.ndarray
    landing_spin: np.ndarray
    flight_time_s: np.ndarray
    apex_m: np.ndarray
    apex_time_s: np.ndarray
    times_s: np.ndarray | None = None
    states: list[State] | None = None
    last_step: np.ndarray | None = None

    @property
    def carry_m(self) -> np.ndarray:
        """Straight-line horizontal distance from the tee to the landing point."""
        return np.hypot(self.landing_position[:, 0], self.landing_position[:, 1])

    @property
    def lateral_m(self) -> np.ndarray:
        """Landing point right (+) or left (-) of the target line."""
        return self.landing_position[:, 0]

    @property
    def landing_angle_deg(self) -> np.ndarray:
        """Descent angle below the horizontal at landing (positive)."""
        return landing_angle_deg(*self.landing_velocity.T)

    @property
    def landing_speed_mps(self) -> np.ndarray:
        return np.linalg.norm(self.landing_velocity, axis=-1)

    @property
    def landing_spin_rpm(self) -> np.ndarray:
        return np.linalg.norm(self.landing_spin, axis=-1) / RPM_TO_RADPS
