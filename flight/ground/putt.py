"""Putts: a ball that starts on the ground at the origin, skids, then rolls to rest (a bay's putter shots).

Start: a putter launches the ball at a few degrees with little spin, a hop at most a few millimetres high and a few
centimetres long (0.2 mm and 2 cm at 1.83 m/s and 2 degrees), too small to matter, so the launch velocity is
projected onto the ground's plane through the origin (its vertical part dropped on level ground). The launch velocity
and the spin are a flight's (`flight.launch_state`), omega = |omega| (cos psi, 0, -sin psi): back spin (+x for a putt
towards +y) makes the ball skid longer and roll off slower.

Skid: the contact point slips at s = v + R n x omega. Kinetic friction mu g cos(phi) against the slip slows the
centre by mu g cos(phi) and spins the ball up by (5/2) mu g cos(phi) / R, so the slip falls at (7/2) mu g cos(phi)
along its own direction: the skid lasts |s0| / ((7/2) mu g cos(phi)) and ends rolling at the velocity of
`phase.rolling_velocity` (friction at the contact point keeps the angular momentum about it), the centre moving at
the mean of its start and end velocities. On a slope gravity changes that angular momentum at a steady rate, adding
5/7 of its along-plane part times the skid's duration (`phase.downhill_acceleration`); the duration is taken as on
the level: within 1 cm and 1 mm/s of a fine integration of the skid on 2-4 degree slopes.

Roll: as after a landing (`flight.ground.phase`): rolling resistance, grass drag and 5/7 of gravity along a slope,
level ground in closed form, slopes in ROLL_STEP_S steps, so a putt on a slope breaks downhill.
"""

from __future__ import annotations

from typing import NamedTuple

from golfflight.flight.constants import BALL_RADIUS_M, GRAVITY_MPS2
from golfflight.flight.ground.phase import (
    GroundPath,
    _Record,
    _roll,
    downhill_acceleration,
    plane_normal_one,
    rolling_velocity,
)
from golfflight.flight.ground.surfaces import Surface
from golfflight.flight.ground.vectors import add, cross, dot, norm, times
from golfflight.flight.launch_state import launch_state

SKID_FRICTION = 0.3
"""Kinetic friction coefficient of a golf ball sliding on a green. It sets only where the skid ends, not the speed
the ball rolls off at; no measured value for greens was found in the sources at hand, so it is set by where putts
are seen to start rolling, 15-20 % along their length (Cochran and Stobbs, "The Search for the Perfect Swing",
1968, as quoted by G. Mangum, puttingzone.com): a spinless putt skids 24 c_r / (24 c_r + 25 mu) of its level run,
14-18 % with 0.3 on stimp 11-8 greens."""

_ORIGIN = (0.0, 0.0, 0.0)


class PuttPhase(NamedTuple):
    """Where a putt came to rest (x, y, z) on its plane through the origin, its time on the ground, the skid's duration
    and length, and, when kept, its path from the start (the start, the skid's end, every ROLL_STEP_S of the roll,
    the rest)."""

    position: tuple[float, float, float]
    time_s: float
    skid_time_s: float
    skid_m: float
    path: GroundPath | None


def putt_phase(
    ball_speed_mps: float,
    launch_angle_deg: float,
    launch_direction_deg: float,
    spin_rpm: float,
    spin_axis_deg: float,
    surface: Surface,
    slope_deg: float = 0.0,
    slope_dir_deg: float = 0.0,
    keep_path: bool = False,
) -> PuttPhase:
    """Skid and roll a putt launched from the origin to rest on a plane sloped by `slope_deg` towards `slope_dir_deg`
    (`phase.plane_normals`), on plain floats. InputError if the slope is steeper than the surface holds a ball on."""
    normal = plane_normal_one(surface, slope_deg, slope_dir_deg)
    launch, spin = launch_state(ball_speed_mps, launch_angle_deg, launch_direction_deg, spin_rpm, spin_axis_deg)
    velocity = add(launch, normal, -dot(launch, normal))
    slip = add(velocity, cross(normal, spin), BALL_RADIUS_M)
    skid_time = norm(slip) / (3.5 * SKID_FRICTION * GRAVITY_MPS2 * normal[2])
    downhill = downhill_acceleration(normal)
    rolling = add(rolling_velocity(velocity, spin, normal), downhill, skid_time)
    start = add(times(0.5 * skid_time, velocity), rolling, 0.5 * skid_time)
    record = _Record(None, keep_path)
    record.add(True, 0.0, _ORIGIN, velocity)
    record.add(skid_time > 0.0, skid_time, start, rolling)
    rest, roll_time = _roll(start, rolling, normal, surface, record, skid_time)
    rest, time = tuple(float(c) for c in rest), skid_time + roll_time
    record.add(True, time, rest, (0.0, 0.0, 0.0))
    return PuttPhase(rest, time, skid_time, norm(start), None if record.rows is None else record.paths()[0])
