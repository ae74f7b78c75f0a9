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
and so is the batch's driver (`roll_to_rest`, NumPy or torch: `ground_phase` runs it on a batch, the torch engine on a
device's tensors); `ground_phase_one` runs the formulas on one ball's plain floats (the engine's one-shot latency
path, where NumPy's per-call cost on arrays of one row would cost more than the physics).

Every state of the phase can be kept (`keep_path`): after each impact, each touchdown, each roll step and the rest,
with velocities, and a level roll's states every ROLL_STEP_S, so a renderer's cubic Hermite resampling follows the
hops exactly (parabolas) and the roll closely.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.constants import BALL_RADIUS_M, GRAVITY_MPS2
from golfflight.flight.ground.impact import impact_components
from golfflight.flight.ground.surfaces import ROLLING_GRAVITY_FRACTION, Surface, holding_slope_deg
from golfflight.flight.ground.vectors import TINY, add, cross, dot, norm, times
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


def plane_normals(slope_deg: np.ndarray | float, slope_dir_deg: np.ndarray | float, n: int) -> np.ndarray:
    """Unit normals [n,3] of planes falling at `slope_deg` towards `slope_dir_deg` (clockwise from the target line
    seen from behind the golfer: 0 = falls away towards the target, 90 = falls to the right, 180 = rises towards
    the target)."""
    phi = np.broadcast_to(np.radians(slope_deg), (n,))
    beta = np.broadcast_to(np.radians(slope_dir_deg), (n,))
    return np.stack([np.sin(phi) * np.sin(beta), np.sin(phi) * np.cos(beta), np.cos(phi)], -1)


def _check_slopes(slope: np.ndarray, resistance: np.ndarray) -> None:
    steep = slope >= holding_slope_deg(resistance)
    if np.any(steep):
        i = int(np.flatnonzero(np.atleast_1d(steep))[0])
        raise InputError(
            f"slope_deg {np.atleast_1d(slope)[i]:g} is steeper than the surface holds a ball on "
            f"({float(np.atleast_1d(holding_slope_deg(resistance))[i]):.2f} deg): it would never come to rest"
        )


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
    half_e1, _ = decay(drag, 0.5 * ROLL_STEP_S)
    half = add(times(1.0 - drag * half_e1, velocity), acceleration, half_e1)
    midpoint = add(downhill, times(1.0 / maximum(norm(half), TINY), half), -brake)
    e1, e2 = decay(drag, ROLL_STEP_S)
    moved = add(add(position, velocity, e1), midpoint, e2)
    after = add(times(1.0 - drag * e1, velocity), midpoint, e1)
    return stops, where(stops, stop_time, ROLL_STEP_S), add(position, direction, run), moved, after


def downhill_acceleration(normal: tuple) -> tuple:
    """5/7 of gravity's component along the plane: what accelerates a rolling ball down a slope."""
    along = add((0.0, 0.0, -GRAVITY_MPS2), normal, GRAVITY_MPS2 * normal[2])
    return times(ROLLING_GRAVITY_FRACTION, along)


class _Recorder:
    """Per-ball lists of (t, position, velocity), or nothing when paths are not kept."""

    def __init__(self, n: int, keep: bool) -> None:
        self.rows: list[list[tuple]] | None = [[] for _ in range(n)] if keep else None

    def add(self, ids: np.ndarray, t: np.ndarray, position: np.ndarray, velocity: np.ndarray) -> None:
        if self.rows is None:
            return
        for k, i in enumerate(ids.tolist()):
            self.rows[i].append((float(t[k]), position[k].copy(), velocity[k].copy()))

    def paths(self) -> list[GroundPath] | None:
        if self.rows is None:
            return None
        return [
            GroundPath(np.array([r[0] for r in rows]), np.array([r[1] for r in rows]), np.array([r[2] for r in rows]))
            for rows in self.rows
        ]


def _bounce(position, velocity, spin, normal, surface: Surface, record: _Recorder):
    """Impacts and hops until every ball rolls: (roll-start position, rolling velocity, time, hops)."""
    n = len(position)
    time, hops = xp.zeros(n, position), xp.zeros(n, position, integer=True)
    position, velocity, spin = xp.copy(position), xp.copy(velocity), xp.copy(spin)
    bouncing = xp.arange(n, position)
    record.add(bouncing, time, position, velocity)
    while xp.size(bouncing):
        ids = bouncing
        v_out, w_out = impact_components(xp.columns(velocity[ids]), xp.columns(spin[ids]), xp.columns(normal[ids]),
                                         surface.take(ids))
        rebound = dot(v_out, xp.columns(normal[ids]))
        hopping = (rebound > MIN_HOP_SPEED_MPS) & (hops[ids] < MAX_BOUNCES)
        velocity[ids], spin[ids] = xp.stack(v_out), xp.stack(w_out)
        flying = ids[hopping]
        if xp.size(flying):
            record.add(flying, time[flying], position[flying], velocity[flying])
            duration = 2.0 * rebound[hopping] / (GRAVITY_MPS2 * normal[flying, 2])
            landed, incoming = hop(xp.columns(position[flying]), xp.columns(velocity[flying]), duration)
            position[flying], velocity[flying] = xp.stack(landed), xp.stack(incoming)
            time[flying] += duration
            hops[flying] += 1
            record.add(flying, time[flying], position[flying], velocity[flying])
        bouncing = flying
    rolling = xp.stack(rolling_velocity(xp.columns(velocity), xp.columns(spin), xp.columns(normal)))
    return position, rolling, time, hops


def _level_states(speed, deceleration, drag, t):
    """Distance run and speed [K] of a level roll at times t [K] from its start (closed form)."""
    e1, e2 = decay(drag, t)
    return speed * e1 - deceleration * e2, speed * (1.0 - drag * e1) - deceleration * e1


def _record_level(record: _Recorder, ids, start_time, position, velocity, resistance, drag, roll_time) -> None:
    """The states of level rolls every ROLL_STEP_S (the rest is recorded by the caller)."""
    if record.rows is None:
        return
    deceleration = resistance * GRAVITY_MPS2
    for k, i in enumerate(ids.tolist()):
        speed = float(np.linalg.norm(velocity[k]))
        times_s = np.arange(ROLL_STEP_S, roll_time[k] - 1e-9, ROLL_STEP_S)
        run, now = _level_states(speed, deceleration[k], drag[k], times_s)
        direction = velocity[k] / max(speed, TINY)
        record.add(np.full(len(times_s), i), start_time[k] + times_s, position[k] + run[:, None] * direction,
                   now[:, None] * direction)


def _roll_level(position, velocity, resistance, drag):
    """Rest point and roll time on level ground (closed form, `stopping`)."""
    speed = norm(xp.columns(velocity))
    distance, time = stopping(speed, resistance * GRAVITY_MPS2, drag)
    direction = velocity / maximum(speed, TINY)[:, None]
    return position + direction * distance[:, None], time


def _roll_slope(position, velocity, normal, resistance, drag, record: _Recorder, ids, start):
    """Rest point and roll time on slopes, in `slope_step`s until every ball has stopped."""
    downhill = xp.stack(downhill_acceleration(xp.columns(normal)))
    brake = resistance * GRAVITY_MPS2 * normal[:, 2]
    position, velocity = xp.copy(position), xp.copy(velocity)
    rest, time = xp.copy(position), xp.zeros(len(position), position)
    moving = xp.arange(len(position), position)
    for _ in range(int(MAX_ROLL_TIME_S / ROLL_STEP_S)):
        if not xp.size(moving):
            break
        stops, taken, stop_at, moved, after = slope_step(
            xp.columns(position[moving]), xp.columns(velocity[moving]), xp.columns(downhill[moving]), brake[moving],
            drag[moving],
        )
        stopped, going = moving[stops], moving[~stops]
        rest[stopped] = xp.stack(stop_at)[stops]
        time[moving] += taken
        position[going], velocity[going] = xp.stack(moved)[~stops], xp.stack(after)[~stops]
        record.add(ids[going], start[going] + time[going], position[going], velocity[going])
        moving = going
    rest[moving] = position[moving]
    return rest, time


def roll_to_rest(position, velocity, spin, normal, surface: Surface, record: _Recorder | None = None):
    """The batch's ground phase, NumPy arrays or torch tensors alike (the torch engine's on its device): bounce every
    ball, then roll those on level ground (a normal straight up) in closed form and the rest in slope steps. Landing
    states and plane normals [N,3]; `surface` holds floats or [N] values of the same kind. (rest [N,3], hops [N],
    time on the ground [N]); `record` (NumPy only) keeps every state."""
    n = len(position)
    record = record or _Recorder(n, keep=False)
    resistance = xp.zeros(n, position) + surface.rolling_resistance
    drag = xp.zeros(n, position) + surface.grass_drag_per_s
    level = normal[:, 2] == 1.0
    everyone = xp.arange(n, position)
    start, rolling, time, hops = _bounce(position, velocity, spin, normal, surface, record)
    record.add(everyone[norm(xp.columns(rolling)) > 0.0], time, start, rolling)
    rest, roll_time = xp.copy(start), xp.zeros(n, position)
    rest[level], roll_time[level] = _roll_level(start[level], rolling[level], resistance[level], drag[level])
    _record_level(record, everyone[level], time[level], start[level], rolling[level], resistance[level], drag[level],
                  roll_time[level])
    sloped = ~level
    if bool(sloped.any()):
        ids = everyone[sloped]
        rest[sloped], roll_time[sloped] = _roll_slope(
            start[sloped], rolling[sloped], normal[sloped], resistance[sloped], drag[sloped], record, ids, time[sloped]
        )
    return rest, hops, time + roll_time


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
    slope = np.broadcast_to(np.asarray(slope_deg, dtype=float), (n,))
    _check_slopes(slope, np.broadcast_to(np.asarray(surface.rolling_resistance, dtype=float), (n,)))
    normal = plane_normals(slope, slope_dir_deg, n)
    record = _Recorder(n, keep_path)
    rest, hops, total = roll_to_rest(position, velocity, spin, normal, surface, record)
    record.add(np.arange(n), total, rest, np.zeros_like(rest))
    return GroundPhase(rest, hops, total, record.paths())


def plane_normal_one(surface: Surface, slope_deg: float, slope_dir_deg: float) -> tuple[float, float, float]:
    """One plane's unit normal on floats (`plane_normals`' formula), after refusing a slope steeper than `surface`
    holds a ball on (ValueError): where every one-ball phase on a plane starts."""
    _check_slopes(np.float64(slope_deg), np.float64(surface.rolling_resistance))
    phi, beta = math.radians(slope_deg), math.radians(slope_dir_deg)
    return math.sin(phi) * math.sin(beta), math.sin(phi) * math.cos(beta), math.cos(phi)


def ground_phase_one(
    position: tuple,
    velocity: tuple,
    spin: tuple,
    surface: Surface,
    slope_deg: float = 0.0,
    slope_dir_deg: float = 0.0,
    keep_path: bool = False,
) -> OneRest:
    """`ground_phase` of one ball on plain floats (the same formulas): from its landing (x, y, z) tuples to its
    rest, with the path `ground_phase` would record when `keep_path` (the served shot a screen draws). ValueError if
    the slope is steeper than the surface holds a ball on."""
    normal = plane_normal_one(surface, slope_deg, slope_dir_deg)
    path: list[tuple[float, tuple, tuple]] | None = [(0.0, position, velocity)] if keep_path else None
    time, hops = 0.0, 0
    while True:
        velocity, spin = impact_components(velocity, spin, normal, surface)
        rebound = dot(velocity, normal)
        if not (rebound > MIN_HOP_SPEED_MPS and hops < MAX_BOUNCES):
            break
        duration = 2.0 * rebound / (GRAVITY_MPS2 * normal[2])
        if path is not None:
            path.append((time, position, velocity))
        position, velocity = hop(position, velocity, duration)
        time, hops = time + duration, hops + 1
        if path is not None:
            path.append((time, position, velocity))
    rolling = rolling_velocity(velocity, spin, normal)
    if path is not None and norm(rolling) > 0.0:
        path.append((time, position, rolling))
    rest, roll_time = _roll_one(position, rolling, normal, surface, slope_deg, path, time)
    if path is not None:
        path.append((time + roll_time, rest, (0.0, 0.0, 0.0)))
    return OneRest(rest, hops, time + roll_time, None if path is None else _ground_path(path))


def _roll_one(position: tuple, rolling: tuple, normal: tuple, surface: Surface, slope_deg: float,
              path: list | None, start: float) -> tuple[tuple, float]:
    """One ball's roll from `position` at `rolling` velocity: (rest point, roll time), its states added to `path`
    as `ground_phase` records them (every ROLL_STEP_S)."""
    drag = float(surface.grass_drag_per_s)
    if slope_deg == 0.0:
        speed = norm(rolling)
        distance, roll_time = stopping(speed, surface.rolling_resistance * GRAVITY_MPS2, drag)
        direction = times(1.0 / max(speed, TINY), rolling)
        if path is not None:
            times_s = np.arange(ROLL_STEP_S, float(roll_time) - 1e-9, ROLL_STEP_S)
            run, now = _level_states(speed, surface.rolling_resistance * GRAVITY_MPS2, drag, times_s)
            path += [(start + t, add(position, direction, r), times(v, direction))
                     for t, r, v in zip(times_s.tolist(), run.tolist(), now.tolist(), strict=True)]
        return add(position, direction, float(distance)), float(roll_time)
    downhill, brake = downhill_acceleration(normal), surface.rolling_resistance * GRAVITY_MPS2 * normal[2]
    elapsed = 0.0
    for _ in range(int(MAX_ROLL_TIME_S / ROLL_STEP_S)):
        stops, taken, stop_at, position, rolling = slope_step(position, rolling, downhill, brake, drag)
        elapsed += float(taken)
        if stops:
            return stop_at, elapsed
        if path is not None:
            path.append((start + elapsed, position, rolling))
    return position, elapsed


def _ground_path(rows: list[tuple[float, tuple, tuple]]) -> GroundPath:
    return GroundPath(np.array([r[0] for r in rows]), np.array([[float(v) for v in r[1]] for r in rows]),
                      np.array([[float(v) for v in r[2]] for r in rows]))
