"""The impact of a spinning ball on turf, one ball or many: Penner's tilted contact plane (Can. J. Phys. 80, 931
(2002)), a turf that damps spin, and Coulomb friction that grips or lets the ball slip.

1. Tilt. The turf gives under the ball, so it bounces off a contact plane tilted back towards it by Penner's critical
   angle theta_c: the normal n' = cos(tilt) n - sin(tilt) t, t the direction of the incoming tangential velocity.
   Penner's fit grows the tilt linearly with the impact speed and with theta_1, the incoming angle from the normal:
   tilt = theta_c (v / 18.6 m/s)(theta_1 / 44 deg), theta_c being the surface's value at his typical approach
   landing (18.6 m/s at 44 degrees from the normal). A ball dropping straight down is not kicked sideways (theta_1 =
   0), a steep wedge meets a gentler wall than a fast, shallow drive, and the later touches of a ball running on
   (theta_1 near 90 degrees) tilt most: the fit, applied as published, takes speed out of a ball skipping across the
   turf, which is what holds a drive that lands on a green to a few tens of yards. (It starts from a landing: a ball
   already rolling, v_n = 0, would still see a tilt.) The tilt is the pitch mark's front wall, and its push runs
   through the ball's centre: it is the one force of the impact that takes forward speed without taking spin. It is
   capped at the surface's `max_tilt_deg`, the rim of the deepest pitch mark the turf takes (a mark d deep has its rim
   at arccos(1 - d / R) from the ball's lowest point), because the linear fit stretched to twice Penner's landing
   speed (a downwind drive) asks for walls that would stop a skimming ball dead; and at theta_1, so the tangential
   speed against the tilted plane, v sin(theta_1 - tilt), never turns negative: taking theta_1 as the landing angle
   from the horizontal instead makes that sine negative on shallow landings and "kills all rollout" of drivers (an
   open simulator's bug).
2. Restitution. Against the tilted plane the normal speed comes back times Penner's e(v_n), scaled per surface.
3. Spin damping. A ball pressed into turf touches it over a patch, not a point, and the grass the ball's surface rubs
   through resists the spin beyond what the friction force at the contact point does: it takes the share
   spin_damping x the normal impulse (per unit mass, m/s) of the spin's component along the plane, all of it at most,
   never reversing it. A damper's torque grows with the rate it resists, like the grass drag on a rolling ball (and
   the dampers of Haake's two-layer turf model), so a fast-spinning wedge loses the most and a slow spin still counts.
   Angular momentum about the contact point is what a ball rolls off with (5/7 v_t - 2/7 R omega); friction at the
   contact point cannot change it, so without this torque a steep wedge would keep every bit of its back spin's pull
   and roll back tens of metres.
4. Grip or slip (Cross, "Grip-slip behavior of a bouncing ball", Am. J. Phys. 70, 1093 (2002); Biber et al.,
   "Measurements and linearized models for golf ball bounce on a green", Sports Engineering (2023)). Coulomb
   friction drives the contact point's slip towards zero: the ball leaves rolling (it grips: Penner's v_t' =
   5/7 v_t - 2/7 R omega) only if friction mu (1 + e) v_n suffices, and otherwise still slipping, as most of Biber et
   al.'s 1,000 measured bounces do. Slipping, a ball keeps its back spin only above a threshold set by the friction
   and the spin damping: Haake's 721 filmed impacts on 18 greens (Aston PhD 1989; Science and Golf II, 1994) found
   firm, freely drained greens let it keep back spin above about 350 rad/s, and softer greens turn it into top spin.
   Friction takes 5/2 of a metre per second's worth of R omega with every metre per second of speed it takes, so with
   that threshold it cannot stop an approach iron on its own: the wall of step 1 does.

Energy never grows: |normal| shrinks by e <= 1, the spin damping shrinks |omega| and the friction impulse opposes the
slip and never overshoots it.
"""

from __future__ import annotations

import math

import numpy as np
from golfflight.flight.constants import BALL_INERTIA_KG_M2, BALL_MASS_KG, BALL_RADIUS_M
from golfflight.flight.ground.surfaces import Surface
from golfflight.flight.ground.vectors import TINY, add, cross, dot, norm, times
from golfflight.flight.xp import atan2, cos, maximum, minimum, sin

PENNER_MAX_NORMAL_SPEED_MPS = 20.0
"""Penner's restitution fit holds up to 20 m/s normal speed; faster impacts keep its value there (about 0.12)."""

PENNER_REFERENCE_SPEED_MPS = 18.6
"""Impact speed at which the contact plane tilts by the surface's critical angle (with PENNER_REFERENCE_ANGLE_DEG):
Penner's typical approach-shot landing."""

PENNER_REFERENCE_ANGLE_DEG = 44.0
"""Incoming angle from the normal at which the contact plane tilts by the surface's critical angle (with
PENNER_REFERENCE_SPEED_MPS): Penner's typical approach-shot landing, 46 degrees below the horizontal."""

SPIN_PER_IMPULSE = BALL_MASS_KG * BALL_RADIUS_M / BALL_INERTIA_KG_M2
"""Change of spin (rad/s) per unit tangential speed change (m/s) from an impulse at the contact point: m R / I."""


def penner_restitution(normal_speed_mps):
    """Penner's coefficient of restitution of a golf ball on a fairway: 0.510 - 0.0375 v_n + 0.000903 v_n^2."""
    v = minimum(normal_speed_mps, PENNER_MAX_NORMAL_SPEED_MPS)
    return 0.510 - 0.0375 * v + 0.000903 * v * v


def penner_tilt(critical_angle_deg, speed_mps, incoming_rad, max_tilt_deg=90.0):
    """Penner's tilt of the contact plane (rad): theta_c (v / 18.6 m/s)(theta_1 / 44 deg), capped at `max_tilt_deg`
    (the rim of the deepest pitch mark the turf takes) and at theta_1 (the incoming angle from the normal,
    `incoming_rad`), so the ball never meets a wall steeper than the turf's or than its own path."""
    per_unit = math.radians(1.0) / (PENNER_REFERENCE_SPEED_MPS * math.radians(PENNER_REFERENCE_ANGLE_DEG))
    penner = minimum(critical_angle_deg * per_unit * speed_mps * incoming_rad, max_tilt_deg * math.radians(1.0))
    return minimum(penner, incoming_rad)


def _soak_spin(spin: tuple, contact_normal: tuple, normal_impulse, surface: Surface) -> tuple:
    """The spin after the turf's torque: its component along the contact plane shrunk by the share spin_damping x the
    normal impulse (per unit mass, m/s), all of it at most."""
    along_plane = add(spin, contact_normal, -dot(spin, contact_normal))
    share = minimum(surface.spin_damping_s_per_m * normal_impulse, 1.0)
    return add(spin, along_plane, -share)


def impact_components(velocity: tuple, spin: tuple, normal: tuple, surface: Surface) -> tuple[tuple, tuple]:
    """Velocity and spin just after an impact, as (x, y, z) tuples of floats (one ball) or [N] arrays (a batch;
    `surface` then holds floats or [N] arrays): the ball hits the ground with `velocity` and `spin` against a plane
    of unit `normal` (pointing up out of the ground)."""
    normal_speed = -dot(velocity, normal)
    tangential = add(velocity, normal, normal_speed)
    tangential_speed = norm(tangential)
    along = times(1.0 / maximum(tangential_speed, TINY), tangential)
    tilt = penner_tilt(surface.critical_angle_deg, norm(velocity), atan2(tangential_speed, normal_speed),
                       surface.max_tilt_deg)
    contact_normal = add(times(cos(tilt), normal), along, -sin(tilt))
    incoming = -dot(velocity, contact_normal)
    restitution = minimum(maximum(surface.restitution_scale * penner_restitution(incoming), 0.0), 1.0)
    normal_impulse = (1.0 + restitution) * incoming
    spin = _soak_spin(spin, contact_normal, normal_impulse, surface)
    sliding = add(velocity, contact_normal, incoming)
    slip = add(sliding, cross(contact_normal, spin), BALL_RADIUS_M)
    slip_speed = norm(slip)
    impulse = minimum(2.0 / 7.0 * slip_speed, surface.friction * normal_impulse)
    friction = times(-impulse / maximum(slip_speed, TINY), slip)
    velocity_out = add(add(sliding, friction), contact_normal, restitution * incoming)
    spin_out = add(spin, cross(contact_normal, friction), -SPIN_PER_IMPULSE)
    return velocity_out, spin_out


def impact(velocity: np.ndarray, spin: np.ndarray, normal: np.ndarray, surface: Surface) -> tuple[np.ndarray, ...]:
    """`impact_components` on [N,3] arrays: velocity and spin [N,3] just after the impact."""
    out, spin_out = impact_components(tuple(velocity.T), tuple(spin.T), tuple(normal.T), surface)
    return np.stack(out, -1), np.stack(spin_out, -1)
