"""Penner's impact of a spinning ball on turf (Can. J. Phys. 80, 931 (2002)), one ball or many.

The turf gives under the ball, so it bounces off a contact plane tilted back towards it by the critical angle
theta_c: the normal n' = cos(tilt) n - sin(tilt) t, t the direction of the incoming tangential velocity. Against
that plane it is a rigid-body impact: the normal speed comes back times e(v_n) (Penner's restitution, scaled per
surface) and friction drives the contact point's slip towards zero, rolling at exit (Penner's
v_t' = 5/7 v_t - 2/7 R omega) unless the Coulomb limit mu (1 + e) v_n stops it first (Biber et al. 2023: many
balls leave the turf still slipping). Back spin is reduced, or reversed into a ball that runs back.

The tilt grows with the depth the ball presses into the turf: Penner's fit grows theta_c with impact speed and
angle; here it grows in proportion to the normal speed up to theta_c at REFERENCE_NORMAL_SPEED_MPS and no further
(faster, a steep wedge would meet a wall and shoot back metres), so a ball skimming the ground at a shallow angle is
not thrown up by a crater it never made. It is capped at theta_1, the incoming angle from the normal, so the
tangential speed against the tilted plane, v sin(theta_1 - tilt), never turns negative: taking theta_1 as the
landing angle from the horizontal instead makes that sine negative on every landing shallower than theta_c and
"kills all rollout" of drivers (an open simulator's bug); and a vertical drop is not kicked sideways. Energy never
grows: |normal| shrinks by e <= 1 and the friction impulse opposes the slip and never overshoots it.
"""

from __future__ import annotations

import math

import numpy as np
from golfflight.flight.constants import BALL_INERTIA_KG_M2, BALL_MASS_KG, BALL_RADIUS_M
from golfflight.flight.ground.surfaces import Surface
from golfflight.flight.ground.vectors import TINY, add, atan2, cos, cross, dot, maximum, minimum, norm, sin, times

PENNER_MAX_NORMAL_SPEED_MPS = 20.0
"""Penner's restitution fit holds up to 20 m/s normal speed; faster impacts keep its value there (about 0.12)."""

REFERENCE_NORMAL_SPEED_MPS = 13.0
"""Normal speed from which the contact plane tilts by the surface's full critical angle: that of a typical
approach-shot landing in Penner's data (about 18.6 m/s at 44 degrees)."""

SPIN_PER_IMPULSE = BALL_MASS_KG * BALL_RADIUS_M / BALL_INERTIA_KG_M2
"""Change of spin (rad/s) per unit tangential speed change (m/s) from an impulse at the contact point: m R / I."""


def penner_restitution(normal_speed_mps):
    """Penner's coefficient of restitution of a golf ball on a fairway: 0.510 - 0.0375 v_n + 0.000903 v_n^2."""
    v = minimum(normal_speed_mps, PENNER_MAX_NORMAL_SPEED_MPS)
    return 0.510 - 0.0375 * v + 0.000903 * v * v


def impact_components(velocity: tuple, spin: tuple, normal: tuple, surface: Surface) -> tuple[tuple, tuple]:
    """Velocity and spin just after an impact, as (x, y, z) tuples of floats (one ball) or [N] arrays (a batch;
    `surface` then holds floats or [N] arrays): the ball hits the ground with `velocity` and `spin` against a plane
    of unit `normal` (pointing up out of the ground)."""
    normal_speed = -dot(velocity, normal)
    tangential = add(velocity, normal, normal_speed)
    tangential_speed = norm(tangential)
    along = times(1.0 / maximum(tangential_speed, TINY), tangential)
    depth = minimum(normal_speed / REFERENCE_NORMAL_SPEED_MPS, 1.0)
    critical = surface.critical_angle_deg * (math.pi / 180.0)
    tilt = minimum(critical * depth, atan2(tangential_speed, normal_speed))
    contact_normal = add(times(cos(tilt), normal), along, -sin(tilt))
    incoming = -dot(velocity, contact_normal)
    restitution = minimum(maximum(surface.restitution_scale * penner_restitution(incoming), 0.0), 1.0)
    sliding = add(velocity, contact_normal, incoming)
    slip = add(sliding, cross(contact_normal, spin), BALL_RADIUS_M)
    slip_speed = norm(slip)
    impulse = minimum(2.0 / 7.0 * slip_speed, surface.friction * (1.0 + restitution) * incoming)
    friction = times(-impulse / maximum(slip_speed, TINY), slip)
    velocity_out = add(add(sliding, friction), contact_normal, restitution * incoming)
    spin_out = add(spin, cross(contact_normal, friction), -SPIN_PER_IMPULSE)
    return velocity_out, spin_out


def impact(velocity: np.ndarray, spin: np.ndarray, normal: np.ndarray, surface: Surface) -> tuple[np.ndarray, ...]:
    """`impact_components` on [N,3] arrays: velocity and spin [N,3] just after the impact."""
    out, spin_out = impact_components(tuple(velocity.T), tuple(spin.T), tuple(normal.T), surface)
    return np.stack(out, -1), np.stack(spin_out, -1)
