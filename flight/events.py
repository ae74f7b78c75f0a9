"""The one rule for where a flight lands and where it peaks, written once over floats, NumPy and torch (`flight.xp`):
the single shot's float loop (`flight.engine`), the integrator's marks (`flight.integrator`: the NumPy batch and the
torch engine) and training's rollout (`flight.rollout`: a whole trajectory at once, differentiably) all call it, so a
change to how a landing or an apex is found is one edit, here.

- Landing: the first step that comes down through the ground's plane (above it before the step, on or below it
  after: `came_down`); the state is interpolated linearly into that step (`crossing_fraction`: exact for Euler's
  straight segments).
- Apex: the first state higher than every state before it (`rose_above`: of equal heights the first stays), the
  figure the vertex of the parabola through it and its two neighbours (`parabola_apex`).
"""

from __future__ import annotations

from golfflight.flight import xp


def came_down(z_before, z_after, height):
    """Which balls came down through the plane z = `height` during a step: above it before, on or below it after
    (flags; one ball's a plain bool)."""
    return (z_before > height) & (z_after <= height)


def crossing_fraction(z_before, z_after, height, crossed=True):
    """How far into the step (0..1) each ball met the plane z = `height`, where it `crossed` it (elsewhere a finite
    value of no meaning: no division by a zero drop, so no NaN reaches a gradient)."""
    drop = xp.where(crossed, z_before - z_after, 1.0)
    return (z_before - height) / drop


def rose_above(z, peak):
    """Whether a state is higher than the flight's peak so far, and so the peak now (flags; one ball's a plain
    bool)."""
    return z > peak


def parabola_apex(before, peak, after, peak_time_s, dt: float, inside=True):
    """(apex height, apex time) of the parabola through three heights one step apart, the middle one the highest
    state: the apex between the steps rather than on them (about g dt^2 / 8 higher at most, up to dt / 2 earlier or
    later). Where a neighbour is missing (NaN: the launch state; or `inside` False: a differentiable caller's peak at
    the first or last state) or the three do not bend down, the peak state itself."""
    bend = before - 2.0 * peak + after
    rise = before - after
    down = (bend < 0.0) & inside
    shift = xp.where(down, rise / (2.0 * xp.where(down, bend, -1.0)), 0.0)
    return xp.where(down, peak - rise * shift / 4.0, peak), peak_time_s + shift * dt
