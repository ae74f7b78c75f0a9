"""Bounce and roll to rest: the ground phase of a batch of landed balls, on a plane through each landing point.

Bounces: an impact (`flight.ground.impact`: Penner's tilted contact plane, the turf's torque on the spin, friction that
grips or lets the ball slip), then a hop under gravity alone, solved exactly (a parabola back to the
plane): hops are short and slow (a driver's first is about 0.5 s at 15 m/s), drag would take a few per cent of a
hop's length, and a closed form needs no steps and no coefficient model. A ball whose rebound leaves the plane at
less than MIN_HOP_SPEED_MPS stays down and rolls.

Roll: the ball first rolls without slipping (the slip left by the last impact taken out with the angular momentum
about the contact point kept: v = 5/7 v_t - 2/7 R n x omega), then decelerates by the surface's rolling resistance
c_r g cos(phi) and grass drag k v against its motion, plus 5/7 of gravity along a slope. Level ground is solved in
closed form; a slope is stepped (ROLL_STEP_S, midpoint steps) until the ball stops, which it does on any slope the
surface holds (`holding_slope_deg`; steeper slopes are refused).

No wind acts on the ground phase. A ball on the ground sits in the grass's boundary layer: the log profile
(`flight.wind`) gives 1 % of the reference wind at the ball's centre (21 mm over z0 = 20 mm), 0.08 m/s in an 8 m/s
wind, whose drag is about 1e-5 g, under a thousandth of the fastest green's rolling resistance (0.04 g at stimp 14).
On a hop the wind changes the air's push on the ball by as much as the ball's own drag, which the hops leave out
(above): a few per cent of a hop's length.

The formulas are written once on (x, y, z) tuples of floats, arrays or tensors (`flight.ground.vectors`, `flight.xp`),
and so is the driver (`_to_rest`): the balls of a batch go through the bounces and the slope's steps in step, a ball
done keeping its values (`choose`), so the same lines run one ball on plain floats (`ground_phase_one`, the engine's
one-shot latency path, where NumPy's per-call cost on arrays of one row would cost more than the physics), a batch
on NumPy (`ground_phase`) and the torch engine's on its device (`roll_to_rest`).

Every state of the phase can be kept (`keep_path`): after each impact, each touchdown, each roll step and the rest,
with velocities, and a level roll's states every ROLL_STEP_S, so a renderer's cubic Hermite resampling follows the
hops exactly (parabolas) and the roll closely.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from golfflight.flight.constants import BALL_RADIUS_M, GRAVITY_MPS2
from golfflight.flight.ground.impact import impact_components
from golfflight.flight.ground.surfaces import ROLLING_GRAVITY_FRACTION, Surface, check_slope_held
from golfflight.flight.ground.vectors import TINY, add, choose, cross, dot, norm, times
from golfflight.flight import xp
from golfflight.flight.xp import expm1, log1p, maximum, where

MIN_HOP_SPEED_MPS = 0.5
"""Rebounds slower than this off the plane (a hop under 13 mm high: a skip the turf soaks up) end the bounces: the
ball rolls."""

MAX_BOUNCES = 40
"""A ball still bouncing after this many hops rolls (a safety net: real bounces die out in a handful)."""

ROLL_STEP_S = 0.25
"""Step of a roll on a slope (on level ground the roll is solved exactly): rests within 2 cm of those of 100 times
finer steps on 3-6 degree slopes."""

MAX_ROLL_TIME_S = 120.0
"""Longest roll stepped on a slope (a safety net: on a slope the surface holds, every ball stops well before)."""


@dataclass(frozen=True)
class GroundPath:
    """One ball's states on the ground: times from touchdown [K], positions and velocities [K,3]. An impact appears
    twice, the incoming and the outgoing velocity at one time; the last row is the rest (velocity zero)."""

    times_s: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray


@dataclass(frozen=True)
class GroundPhase:
    """Where a batch of balls came to rest after landing: rest points [N,3], hops [N], time on the ground [N] and,
    when kept, each ball's path."""

    rest_position: np.ndarray
    bounces: np.ndarray
    time_s: np.ndarray
    paths: list[GroundPath] | None = None


class OneRest(NamedTuple):
    """Where one ball came to rest: the point (x, y, z), hops, time on the ground and, when kept, its path."""

    position: tuple[float, float, float]
    bounces: int
    time_s: float
    path: GroundPath | None = None


RADIANS_PER_DEG = math.pi / 180.0
"""math.radians' and np.radians' own factor: one formula on floats and arrays gives both their bits."""


def plane_normal(slope_deg, slope_dir_deg) -> tuple:
    """Unit normal (x, y, z) of a plane falling at `slope_deg` towards `slope_dir_deg` (clockwise from the target line
    seen from behind the golfer: 0 = falls away towards the target, 90 = falls to the right, 180 = rises towards
    the target), on floats or [N] arrays."""
    phi, beta = slope_deg * RADIANS_PER_DEG, slope_dir_deg * RADIANS_PER_DEG
    return xp.sin(phi) * xp.sin(beta), xp.sin(phi) * xp.cos(beta), xp.cos(phi)


def plane_normals(slope_deg: np.ndarray | float, slope_dir_deg: np.ndarray | float, n: int) -> np.ndarray:
    """Unit normals [n,3] of `plane_normal`'s planes, one a ball (each angle shared or one a ball)."""
    angles = (np.broadcast_to(np.asarray(a, dtype=float), (n,)) for a in (slope_deg, slope_dir_deg))
    return np.stack(plane_normal(*angles), -1)


def hop(position: tuple, velocity: tuple, duration) -> tuple[tuple, tuple]:
    """Position and velocity after a hop of `duration` under gravity alone."""
    fall = 0.5 * GRAVITY_MPS2 * duration * duration
    moved = add(position, velocity, duration)
    return (moved[0], moved[1], moved[2] - fall), (velocity[0], velocity[1], velocity[2] - GRAVITY_MPS2 * duration)


def rolling_velocity(velocity: tuple, spin: tuple, normal: tuple) -> tuple:
    """The velocity a ball rolls off with, its slip taken out with the angular momentum about the contact point kept:
    5/7 v_t - 2/7 R n x omega, in the plane."""
    on_plane = add(velocity, normal, -dot(velocity, normal))
    rolling = add(times(5.0 / 7.0, on_plane), cross(normal, spin), -2.0 / 7.0 * BALL_RADIUS_M)
    return add(rolling, normal, -dot(rolling, normal))


def _ratios(x):
    """log(1 + x) / x and (x - log(1 + x)) / x^2 for x >= 0, without cancellation near 0 (limits 1 and 1/2)."""
    small = x < 1e-4
    safe = where(small, 1.0, x)
    log = log1p(safe)
    return where(small, 1.0 - x / 2.0, log / safe), where(small, 0.5 - x / 3.0, (safe - log) / (safe * safe))


def stopping(speed, braking, drag):
    """(distance, time) to stop from `speed` under a constant deceleration `braking` plus drag k v: the ball stops
    after T = ln(1 + k v0 / a) / k, having run v0 / k - a T / k (v0^2 / 2a without drag)."""
    time_ratio, distance_ratio = _ratios(drag * speed / braking)
    return speed * speed / braking * distance_ratio, speed / braking * time_ratio


def decay(drag, t):
    """E1 = (1 - exp(-k t)) / k and E2 = (t - E1) / k, without cancellation for small k t (limits t and t^2 / 2):
    under a constant acceleration A and drag k v, v(t) = v0 (1 - k E1) + A E1 and x(t) = x0 + v0 E1 + A E2."""
    kt = drag * t
    small = kt < 1e-6
    safe_k = where(small, 1.0, drag)
    e1 = where(small, t - 0.5 * kt * t, -expm1(-kt) / safe_k)
    e2 = where(small, 0.5 * t * t - kt * t / 6.0 * t, (t - e1) / safe_k)
    return e1, e2


def drift_velocity(velocity: tuple, acceleration: tuple, drag, e1) -> tuple:
    """v(t) = v0 (1 - k E1) + A E1: the velocity after a time whose `decay` factor is E1, under a constant
    acceleration A plus drag k v."""
    return add(times(1.0 - drag * e1, velocity), acceleration, e1)


def drift(position: tuple, velocity: tuple, acceleration: tuple, drag, t) -> tuple[tuple, tuple]:
    """Position and velocity after time `t` under a constant acceleration A plus drag k v, exactly (`decay`):
    x(t) = x0 + v0 E1 + A E2 and `drift_velocity`; the one motion of every roll, stepped or closed form."""
    e1, e2 = decay(drag, t)
    return add(add(position, velocity, e1), acceleration, e2), drift_velocity(velocity, acceleration, drag, e1)


def slope_step(position: tuple, velocity: tuple, downhill: tuple, brake, drag):
    """One ROLL_STEP_S of a roll on a slope: (stops, time taken, rest point, position, velocity after the step).
    Gravity and the rolling resistance act along the direction of motion at the step's middle (a midpoint step:
    errors fall as the step squared), grass drag exactly (`decay`); a ball that would stop within the step stops
    as on level ground, so the stepped roll meets the closed form as the slope vanishes."""
    speed = norm(velocity)
    direction = times(1.0 / maximum(speed, TINY), velocity)
    acceleration = add(downhill, direction, -brake)
    braking = maximum(-dot(acceleration, direction), TINY)
    run, stop_time = stopping(speed, braking, drag)
    stops = stop_time <= ROLL_STEP_S
    half = drift_velocity(velocity, acceleration, drag, decay(drag, 0.5 * ROLL_STEP_S)[0])
    midpoint = add(downhill, times(1.0 / maximum(norm(half), TINY), half), -brake)
    moved, after = drift(position, velocity, midpoint, drag, ROLL_STEP_S)
    return stops, where(stops, stop_time, ROLL_STEP_S), add(position, direction, run), moved, after


def downhill_acceleration(normal: tuple) -> tuple:
    """5/7 of gravity's component along the plane: what accelerates a rolling ball down a slope."""
    along = add((0.0, 0.0, -GRAVITY_MPS2), normal, GRAVITY_MPS2 * normal[2])
    return times(ROLLING_GRAVITY_FRACTION, along)


class _Record:
    """The states of a ground phase's balls when they are kept: a list for one ball on floats (`n` None), or one a
    ball of a batch; nothing otherwise."""

    def __init__(self, n: int | None, keep: bool) -> None:
        self.one = n is None
        self.rows: list[list[tuple]] | None = ([[]] if self.one else [[] for _ in range(n)]) if keep else None

    def _balls(self, flags) -> list[int]:
        return ([0] if flags else []) if self.one else np.flatnonzero(flags).tolist()

    def _floats(self, values: tuple, i: int) -> tuple:
        return tuple(float(v if self.one else v[i]) for v in values)

    def add(self, flags, t, position: tuple, velocity: tuple) -> None:
        """The state of the balls where `flags` hold, at time `t` of each."""
        if self.rows is None:
            return
        for i in self._balls(flags):
            self.rows[i].append((float(t if self.one else t[i]), self._floats(position, i), self._floats(velocity, i)))

    def level(self, flags, start, position: tuple, rolling: tuple, resistance, drag, roll_time) -> None:
        """The states of the level rolls where `flags` hold every ROLL_STEP_S from their start (closed form: `drift`
        under the rolling resistance; the rest is added by the caller)."""
        if self.rows is None:
            return
        for i in self._balls(flags):
            at, speed_vector = self._floats(position, i), self._floats(rolling, i)
            resistance_i, drag_i, start_i, time_i = (float(v if self.one or np.ndim(v) == 0 else v[i])
                                                     for v in (resistance, drag, start, roll_time))
            braking = times(-resistance_i * GRAVITY_MPS2 / max(norm(speed_vector), TINY), speed_vector)
            times_s = np.arange(ROLL_STEP_S, time_i - 1e-9, ROLL_STEP_S)
            moved, now = drift(at, speed_vector, braking, drag_i, times_s)
            states = zip(times_s.tolist(), np.stack(moved, -1).tolist(), np.stack(now, -1).tolist(), strict=True)
            self.rows[i] += [(start_i + t, tuple(p), tuple(v)) for t, p, v in states]

    def paths(self) -> list[GroundPath] | None:
        if self.rows is None:
            return None
        return [GroundPath(np.array([r[0] for r in rows]), np.array([r[1] for r in rows]).reshape(-1, 3),
                           np.array([r[2] for r in rows]).reshape(-1, 3)) for rows in self.rows]


def _bounce(position: tuple, velocity: tuple, spin: tuple, normal: tuple, surface: Surface, record: _Record):
    """Impacts and hops until every ball rolls, the balls in step (one that has stopped hopping keeps its values):
    (roll-start position, velocity, spin, time, hops)."""
    time = xp.zeros_like(position[0])
    hops, bouncing = xp.zeros_like(time, integer=True), time == 0.0  # every ball, to begin with
    record.add(bouncing, time, position, velocity)
    while xp.anything(bouncing):
        velocity_out, spin_out = impact_components(velocity, spin, normal, surface)
        velocity, spin = choose(bouncing, velocity_out, velocity), choose(bouncing, spin_out, spin)
        rebound = dot(velocity, normal)
        bouncing = bouncing & (rebound > MIN_HOP_SPEED_MPS) & (hops < MAX_BOUNCES)
        record.add(bouncing, time, position, velocity)
        duration = where(bouncing, 2.0 * rebound / (GRAVITY_MPS2 * normal[2]), 0.0)
        position, velocity = hop(position, velocity, duration)  # a hop of no time leaves a ball as it is
        time, hops = time + duration, hops + bouncing
        record.add(bouncing, time, position, velocity)
    return position, velocity, spin, time, hops


def _roll_slope(position: tuple, velocity: tuple, normal: tuple, resistance, drag, moving, record: _Record, start):
    """Rest point and roll time of the balls `moving` on slopes, in `slope_step`s, in step, until each has stopped."""
    downhill = downhill_acceleration(normal)
    brake = resistance * GRAVITY_MPS2 * normal[2]
    rest, elapsed = position, xp.zeros_like(start)
    for _ in range(int(MAX_ROLL_TIME_S / ROLL_STEP_S)):
        if not xp.anything(moving):
            break
        stops, taken, stop_at, moved, after = slope_step(position, velocity, downhill, brake, drag)
        rest, elapsed = choose(moving & stops, stop_at, rest), elapsed + where(moving, taken, 0.0)
        moving = moving & xp.negated(stops)
        position, velocity = choose(moving, moved, position), choose(moving, after, velocity)
        record.add(moving, start + elapsed, position, velocity)
    return choose(moving, position, rest), elapsed


def _roll(position: tuple, rolling: tuple, normal: tuple, surface: Surface, record: _Record, start):
    """Rest point and roll time of balls rolling off from `position` at `rolling` velocity, their time on the ground
    `start` so far: on level ground (a normal straight up) in closed form (`stopping`), on slopes in steps."""
    resistance, drag = surface.rolling_resistance, surface.grass_drag_per_s
    speed = norm(rolling)
    distance, roll_time = stopping(speed, resistance * GRAVITY_MPS2, drag)
    guarded = maximum(speed, TINY)
    rest = add(position, (rolling[0] / guarded, rolling[1] / guarded, rolling[2] / guarded), distance)
    level = normal[2] == 1.0
    record.level(level, start, position, rolling, resistance, drag, roll_time)
    sloped = xp.negated(level)
    if xp.anything(sloped):
        slope_rest, slope_time = _roll_slope(position, rolling, normal, resistance, drag, sloped, record, start)
        rest, roll_time = choose(level, rest, slope_rest), where(level, roll_time, slope_time)
    return rest, roll_time


def _to_rest(position: tuple, velocity: tuple, spin: tuple, normal: tuple, surface: Surface, record: _Record):
    """THE ground phase, written once for one ball on floats and for a batch on NumPy or torch: (x, y, z) tuples of
    floats or of [N] arrays, `surface` holding floats or [N] values; bounce every ball, then roll it. (rest (x, y,
    z), hops, time on the ground), the rest added to `record` with a velocity of zero."""
    position, velocity, spin, time, hops = _bounce(position, velocity, spin, normal, surface, record)
    rolling = rolling_velocity(velocity, spin, normal)
    record.add(norm(rolling) > 0.0, time, position, rolling)
    rest, roll_time = _roll(position, rolling, normal, surface, record, time)
    total = time + roll_time
    record.add(total >= 0.0, total, rest, times(0.0, rest))  # every ball
    return rest, hops, total


def roll_to_rest(position, velocity, spin, normal, surface: Surface):
    """The batch's ground phase on [N,3] arrays or tensors (the torch engine's on its device: `surface` holds floats
    or [N] values of the same kind): (rest [N,3], hops [N], time on the ground [N])."""
    columns = (xp.columns(v) for v in (position, velocity, spin, normal))
    rest, hops, total = _to_rest(*columns, surface, _Record(len(position), keep=False))
    return xp.stack(rest), hops, total


def ground_phase(
    position: np.ndarray,
    velocity: np.ndarray,
    spin: np.ndarray,
    surface: Surface,
    slope_deg: np.ndarray | float = 0.0,
    slope_dir_deg: np.ndarray | float = 0.0,
    keep_path: bool = False,
) -> GroundPhase:
    """Bounce and roll a batch of balls to rest from their landing states [N,3] (position on the ground, velocity,
    spin in rad/s) on planes through the landing points, sloped by `slope_deg` towards `slope_dir_deg`
    (`plane_normals`); `surface` holds floats or [N] arrays. InputError if a slope is steeper than its surface
    holds a ball on."""
    n = len(position)
    check_slope_held(slope_deg, surface.rolling_resistance)
    record = _Record(n, keep_path)
    columns = (xp.columns(v) for v in (position, velocity, spin, plane_normals(slope_deg, slope_dir_deg, n)))
    rest, hops, total = _to_rest(*columns, surface, record)
    return GroundPhase(xp.stack(rest), hops, total, record.paths())


def plane_normal_one(surface: Surface, slope_deg: float, slope_dir_deg: float) -> tuple[float, float, float]:
    """One plane's unit normal on floats (`plane_normal`), after refusing a slope steeper than `surface` holds a ball
    on (InputError, `check_slope_held`): where every one-ball phase on a plane starts."""
    check_slope_held(slope_deg, surface.rolling_resistance)
    return plane_normal(slope_deg, slope_dir_deg)


def ground_phase_one(
    position: tuple,
    velocity: tuple,
    spin: tuple,
    surface: Surface,
    slope_deg: float = 0.0,
    slope_dir_deg: float = 0.0,
    keep_path: bool = False,
) -> OneRest:
    """`ground_phase` of one ball on plain floats (the same driver, `_to_rest`): from its landing (x, y, z) tuples
    to its rest, with the path `ground_phase` would record when `keep_path` (the served shot a screen draws).
    InputError if the slope is steeper than the surface holds a ball on (`check_slope_held`)."""
    normal = plane_normal_one(surface, slope_deg, slope_dir_deg)
    record = _Record(None, keep_path)
    rest, hops, time = _to_rest(position, velocity, spin, normal, surface, record)
    return OneRest(rest, hops, time, None if record.rows is None else record.paths()[0])
