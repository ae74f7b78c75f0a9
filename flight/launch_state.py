"""The ball's velocity and spin at impact from launch-monitor values (paper eq. 12), written once over floats, NumPy and
torch (`flight.xp`): a flight's start (`flight.physics.initial_state`) and a putt's (`flight.ground.putt`) both come
from it, so a change to the launch convention is one edit. It imports no other physics, so the ground phase can
use it without an import circle."""

from __future__ import annotations

import math

from golfflight.flight import xp
from golfflight.flight.constants import RPM_TO_RADPS

RADIANS_PER_DEGREE = math.pi / 180.0
"""What `math.radians` and `numpy.radians` multiply by: the same angle to the last bit on floats and arrays."""


def launch_state(ball_speed_mps, launch_angle_deg, launch_direction_deg, spin_rpm, spin_axis_deg) -> tuple:
    """((vx, vy, vz), (wx, wy, wz)) at impact: the speed at the launch angle above the horizontal, the launch
    direction right (+) of the target line (+y); the spin about a horizontal axis tilted right (+) by the spin axis,
    rifle spin zero. Floats, NumPy arrays or torch tensors, component by component."""
    gamma, phi, psi = (angle * RADIANS_PER_DEGREE for angle in (launch_angle_deg, launch_direction_deg, spin_axis_deg))
    along = ball_speed_mps * xp.cos(gamma)
    omega = spin_rpm * RPM_TO_RADPS
    velocity = (along * xp.sin(phi), along * xp.cos(phi), ball_speed_mps * xp.sin(gamma))
    return velocity, (omega * xp.cos(psi), xp.zeros_like(omega), -omega * xp.sin(psi))
