"""Equations of motion of a spinning golf ball (the paper's section 2, README.md; its errata marked below).

Axes: x to the right of the target line seen from behind the golfer, y towards the target, z up.
State of a batch of N balls: position r [N,3] (m), velocity v [N,3] (m/s), spin omega [N,3] (rad/s).

Aerodynamic coefficients come from a pluggable model (v_rel, omega) -> [N,4] = C_L, C_D, C_M, C_Q with
  q     = C_Q rho |v_rel|^2          (C_Q = 0.5 gives the usual dynamic pressure)
  F_D   = -C_D q A v_rel/|v_rel|
  F_L   =  C_L q A (omega x v_rel)/|omega x v_rel|   (erratum: the paper's v x omega points down)
  dw/dt = -C_M q d A omega/|omega| / I               (erratum: spin only ever decays)

The equations are written once, component by component (`accelerations`, `euler_step`), with nothing but
+ - * / and ** 0.5 and `flight.xp`, so the same code runs on plain Python floats (one shot, where NumPy's per-call
cost would dominate), on NumPy [N] arrays (a batch) and on torch [N] tensors (training's differentiable flight and
the torch engine, `flight.rollout`). `aerodynamics` wraps them for [N,3] arrays or tensors.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from golfflight.flight import xp
from golfflight.flight.constants import (
    BALL_AREA_M2,
    BALL_INERTIA_KG_M2,
    BALL_MASS_KG,
    BALL_RADIUS_M,
    GRAVITY_MPS2,
    TEE_HEIGHT_M,
)
from golfflight.flight.ground.vectors import norm
from golfflight.flight.launch_state import launch_state
from golfflight.flight.wind import CALM, Wind

TINY = 1e-12
"""Guards the unit vectors of a ball at rest or with no spin."""


class CoefficientModel(Protocol):
    """Aerodynamic coefficients [N,4] = (C_L, C_D, C_M, C_Q) of balls with air-relative velocity and spin [N,3].

    A model holding per-ball values (air, scales) also has `take(index)`, the same model for those balls only, so
    the integrator can drop landed balls from the batch; one without per-ball values needs none."""

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray: ...


class ExtraAcceleration(Protocol):
    """An acceleration [N,3] added to the equations from (air-relative velocity, spin, position) [N,3] (the position
    for an effect that changes with height); `take` as above."""

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray, position: np.ndarray) -> np.ndarray: ...


@dataclass
class State:
    """Position, velocity and spin of a batch of balls, each [N,3]."""

    position: np.ndarray
    velocity: np.ndarray
    spin: np.ndarray

    def take(self, index: np.ndarray) -> State:
        """The state of some of the balls."""
        return State(self.position[index], self.velocity[index], self.spin[index])


def initial_state(
    ball_speed_mps: np.ndarray,
    launch_angle_deg: np.ndarray,
    launch_direction_deg: np.ndarray,
    spin_rpm: np.ndarray,
    spin_axis_deg: np.ndarray,
) -> State:
    """State at impact from launch-monitor values (paper eq. 12, `flight.launch_state`), [N] arrays each."""
    velocity, spin = launch_state(*(np.asarray(value, dtype=float) for value in (
        ball_speed_mps, launch_angle_deg, launch_direction_deg, spin_rpm, spin_axis_deg)))
    velocity = np.stack(velocity, -1)
    position = np.zeros_like(velocity)
    position[:, 2] = TEE_HEIGHT_M
    return State(position, velocity, np.stack(spin, -1))


def spin_ratio(v_rel, omega):
    """S = R |omega| / |v_rel| [N]: surface speed over air speed, the variable lift and drag depend on (NumPy or
    torch [N,3])."""
    return spin_ratio_of(norm(xp.columns(v_rel)), norm(xp.columns(omega)))


def spin_ratio_of(speed, spin_rate):
    """S = R |omega| / |v_rel| from the two magnitudes, for callers that have them already."""
    return BALL_RADIUS_M * spin_rate / at_least_tiny(speed)


def reynolds_scale(kinematic_viscosity, nominal_kinematic_viscosity):
    """k = nu_0 / nu (float or array). A coefficient model trained in air of viscosity nu_0 and fed (k v_rel, k omega)
    sees the Reynolds number of the actual air, |v| d / nu, at the same spin ratio: hot or thin air lowers Re,
    which a model of |v| and |omega| alone would otherwise not know."""
    return nominal_kinematic_viscosity / kinematic_viscosity


def at_least_tiny(x):
    """max(x, TINY) of a float, an array or a tensor: the guard of every magnitude in a denominator."""
    return xp.maximum(x, TINY)


def accelerations(vx, vy, vz, wx, wy, wz, c_lift, c_drag, c_moment, c_q, density):
    """Aerodynamic acceleration (ax, ay, az) and spin acceleration (bx, by, bz) of balls with air-relative velocity
    v and spin w, component by component. Every argument is a float, or all are broadcastable NumPy arrays."""
    speed_sq = vx * vx + vy * vy + vz * vz
    q_area = c_q * density * speed_sq * BALL_AREA_M2
    mx, my, mz = wy * vz - wz * vy, wz * vx - wx * vz, wx * vy - wy * vx
    lift = c_lift * q_area / (BALL_MASS_KG * at_least_tiny((mx * mx + my * my + mz * mz) ** 0.5))
    drag = c_drag * q_area / (BALL_MASS_KG * at_least_tiny(speed_sq**0.5))
    spin = at_least_tiny((wx * wx + wy * wy + wz * wz) ** 0.5)
    decay = c_moment * q_area * 2.0 * BALL_RADIUS_M / (BALL_INERTIA_KG_M2 * spin)
    return lift * mx - drag * vx, lift * my - drag * vy, lift * mz - drag * vz, -decay * wx, -decay * wy, -decay * wz


def euler_step(x, y, z, vx, vy, vz, wx, wy, wz, coefficients, density, air_vx, air_vy, dt):
    """One forward-Euler step (paper eq. 13) of position, velocity and spin, component by component.

    `coefficients` = (C_L, C_D, C_M, C_Q) at the current state; (air_vx, air_vy) is the horizontal wind at the
    ball. Floats for one ball or NumPy [N] arrays for a batch; returns the nine new components in the same order.
    """
    ax, ay, az, bx, by, bz = accelerations(vx - air_vx, vy - air_vy, vz, wx, wy, wz, *coefficients, density)
    return (
        x + dt * vx,
        y + dt * vy,
        z + dt * vz,
        vx + dt * ax,
        vy + dt * ay,
        vz + dt * (az - GRAVITY_MPS2),
        wx + dt * bx,
        wy + dt * by,
        wz + dt * bz,
    )


def aerodynamics(v_rel, omega, coefficients, density, gravity_mps2: float = 0.0):
    """Aerodynamic acceleration [N,3] (drag + Magnus lift), less `gravity_mps2` on z where given (the equations'
    whole acceleration: subtracted from the column before it is stacked, so a gradient needs no in-place write), and
    spin acceleration [N,3] from the coefficients [N,4] (C_L, C_D, C_M, C_Q); NumPy arrays or torch tensors alike,
    density a float or [N]."""
    v, w = xp.columns(v_rel), xp.columns(omega)
    ax, ay, az, *spin = accelerations(*v, *w, *(coefficients[..., i] for i in range(4)), density)
    return xp.stack((ax, ay, az - gravity_mps2)), xp.stack(spin)


def derivatives(
    state: State,
    coefficient_model: CoefficientModel,
    density: np.ndarray | float,
    wind: Wind = CALM,
    extra: ExtraAcceleration | None = None,
) -> State:
    """d/dt of (position, velocity, spin): the right-hand side of the equations of motion (paper eq. 14), plus an
    optional extra acceleration of the air-relative velocity, spin and position (discovery's learned correction)."""
    v_rel = state.velocity if wind.is_calm else state.velocity - wind.velocity(state.position[:, 2])
    coefficients = coefficient_model(v_rel, state.spin)
    acceleration, spin_acceleration = aerodynamics(v_rel, state.spin, coefficients, density, GRAVITY_MPS2)
    if extra is not None:
        acceleration += extra(v_rel, state.spin, state.position)
    return State(state.velocity, acceleration, spin_acceleration)


def mechanical_energy(state: State) -> np.ndarray:
    """Kinetic (translational + rotational) plus potential energy per ball [N] (J)."""
    kinetic = 0.5 * BALL_MASS_KG * np.sum(state.velocity**2, axis=-1)
    rotational = 0.5 * BALL_INERTIA_KG_M2 * np.sum(state.spin**2, axis=-1)
    return kinetic + rotational + BALL_MASS_KG * GRAVITY_MPS2 * state.position[:, 2]
