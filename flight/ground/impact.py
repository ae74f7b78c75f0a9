"""Penner's impact of a spinning ball on turf (Can. J. Phys. 80, 931 (2002); NOTES.md section 7), batch-wise.

The turf gives under the ball, so it bounces off a contact plane tilted back towards it by the critical angle
theta_c: the normal n' = cos(tilt) n - sin(tilt) t, t the direction of the incoming tangential velocity. Against
that plane it is a rigid-body impact: the normal speed comes back times e(v_n) (Penner's restitution, scaled per
surface) and friction drives the contact point's slip towards zero, rolling at exit (Penner's
v_t' = 5/7 v_t - 2/7 R omega) unless the Coulomb limit mu (1 + e) v_n stops it first (Biber et al. 2023: many
balls leave the turf still slipping). Back spin is reduced, or reversed into a ball that runs back.

The tilt grows with the depth the ball presses into the turf: Penner's fit grows theta_c with impact speed and
angle; here it grows in proportion to the normal speed up to theta_c at REFERENCE_NORMAL_SPEED_MPS and no further
(faster, a steep wedge would meet a wall and shoot back metres), so a ball skimming the ground at a shallow angle is
not thrown up by a crater it never made. It is capped at theta_1, the
incoming angle from the normal, so the tangential speed against the tilted plane, v sin(theta_1 - tilt), never
turns negative: taking theta_1 as the landing angle from the horizontal instead makes that sine negative on every
landing shallower than theta_c and "kills all rollout" of drivers (an open simulator's bug); and a vertical drop is
not kicked sideways. Energy never grows: |normal| shrinks by e <= 1 and the
friction impulse opposes the slip and never overshoots it.
"""

from __future__ import annotations

import numpy as np

from flight.constants import BALL_MASS_KG, BALL_RADIUS_M, BALL_INERTIA_KG_M2
from flight.ground.surfaces import Surface

PENNER_MAX_NORMAL_SPEED_MPS = 20.0
"""Penner's restitution fit holds up to 20 m/s normal speed; faster impacts keep its value there (about 0.12)."""

REFERENCE_NORMAL_SPEED_MPS = 13.0
"""Normal speed from which the contact plane tilts by the surface's full critical angle: that of a typical
approach-shot landing in Penner's data (about 18.6 m/s at 44 degrees)."""

SPIN_PER_IMPULSE = BALL_MASS_KG * BALL_RADIUS_M / BALL_INERTIA_KG_M2
"""Change of spin (rad/s) per unit tangential speed change (m/s) from an impulse at the contact point: m R / I."""


def penner_restitution(normal_speed_mps: np.ndarray) -> np.ndarray:
    """Penner's coefficient of restitution of a golf ball on a fairway: 0.510 - 0.0375 v_n + 0.000903 v_n^2."""
    v = np.minimum(normal_speed_mps, PENNER_MAX_NORMAL_SPEED_MPS)
    return 0.510 - 0.0375 * v + 0.000903 * v * v


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


NEXT, AFTER = [1, 2, 0], [2, 0, 1]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a x b of [N,3] arrays (np.cross costs several times more on the few rows of one shot)."""
    return a[:, NEXT] * b[:, AFTER] - a[:, AFTER] * b[:, NEXT]


def impact(velocity: np.ndarray, spin: np.ndarray, normal: np.ndarray, surface: Surface) -> tuple[np.ndarray, ...]:
    """Velocity and spin [N,3] just after balls hit the ground with `velocity`, `spin` [N,3] against planes of unit
    `normal` [N,3] (pointing up out of the ground); `surface` holds floats or [N] arrays."""
    normal_speed = -_dot(velocity, normal)
    tangential = velocity + normal_speed[:, None] * normal
    tangential_speed = np.linalg.norm(tangential, axis=-1)
    along = tangential / np.maximum(tangential_speed, 1e-12)[:, None]
    depth = np.minimum(normal_speed / REFERENCE_NORMAL_SPEED_MPS, 1.0)
    tilt = np.minimum(np.radians(surface.critical_angle_deg) * depth, np.arctan2(tangential_speed, normal_speed))
    contact_normal = np.cos(tilt)[:, None] * normal - np.sin(tilt)[:, None] * along
    incoming = -_dot(velocity, contact_normal)
    restitution = np.clip(surface.restitution_scale * penner_restitution(incoming), 0.0, 1.0)
    sliding = velocity + incoming[:, None] * contact_normal
    slip = sliding + BALL_RADIUS_M * _cross(contact_normal, spin)
    slip_speed = np.linalg.norm(slip, axis=-1)
    impulse = np.minimum(2.0 / 7.0 * slip_speed, surface.friction * (1.0 + restitution) * incoming)
    friction = -(impulse / np.maximum(slip_speed, 1e-12))[:, None] * slip
    velocity_out = sliding + friction + (restitution * incoming)[:, None] * contact_normal
    spin_out = spin - SPIN_PER_IMPULSE * _cross(contact_normal, friction)
    return velocity_out, spin_out
