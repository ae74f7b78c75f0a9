"""The ground phase of a batch on a torch device: the torch engine's landings bounced and rolled to rest where they
were flown, so that a GPU's sweep does not wait on one CPU core for them.

The physics is the engine's own, not written again: the impact (`flight.ground.impact.impact_components`: Penner's
tilt and its cap, the turf's damping of the spin, grip or slip), the hop, the rolling velocity, the level roll's
closed form and the slope's step (`flight.ground.phase`) are formulas on (x, y, z) tuples whose components may be
torch tensors (`flight.ground.vectors` dispatches their few functions).
What is torch's here is only the batch's bookkeeping, as `flight.ground.phase.ground_phase` keeps it in NumPy: which
balls still bounce, which roll on a slope, their states gathered and scattered by index. No path is kept (a sweep
keeps none). The planes' normals and the surfaces' parameters come in as tensors: slopes are checked where a
`GroundSpec` is made.
"""

from __future__ import annotations

import torch
from golfflight.flight.constants import GRAVITY_MPS2
from golfflight.flight.ground import Surface
from golfflight.flight.ground.impact import impact_components
from golfflight.flight.ground.phase import (
    MAX_BOUNCES,
    MAX_ROLL_TIME_S,
    MIN_HOP_SPEED_MPS,
    ROLL_STEP_S,
    downhill_acceleration,
    hop,
    rolling_velocity,
    slope_step,
    stopping,
)
from golfflight.flight.ground.vectors import TINY


def _columns(a: torch.Tensor) -> tuple[torch.Tensor, ...]:
    return a[:, 0], a[:, 1], a[:, 2]


def _bounce(position: torch.Tensor, velocity: torch.Tensor, spin: torch.Tensor, normal: torch.Tensor,
            surface: Surface) -> tuple[torch.Tensor, ...]:
    """Impacts and hops until every ball rolls: (roll-start position, rolling velocity, time, hops)."""
    n = len(position)
    time = position.new_zeros(n)
    hops = torch.zeros(n, dtype=torch.int64, device=position.device)
    position, velocity, spin = position.clone(), velocity.clone(), spin.clone()
    bouncing = torch.arange(n, device=position.device)
    while bouncing.numel():
        ids = bouncing
        v_out, w_out = impact_components(_columns(velocity[ids]), _columns(spin[ids]), _columns(normal[ids]),
                                         surface.take(ids))
        v_out, w_out = torch.stack(v_out, -1), torch.stack(w_out, -1)
        rebound = torch.einsum("ij,ij->i", v_out, normal[ids])
        hopping = (rebound > MIN_HOP_SPEED_MPS) & (hops[ids] < MAX_BOUNCES)
        velocity[ids], spin[ids] = v_out, w_out
        flying = ids[hopping]
        if flying.numel():
            duration = 2.0 * rebound[hopping] / (GRAVITY_MPS2 * normal[flying, 2])
            landed, incoming = hop(_columns(position[flying]), _columns(velocity[flying]), duration)
            position[flying], velocity[flying] = torch.stack(landed, -1), torch.stack(incoming, -1)
            time[flying] += duration
            hops[flying] += 1
        bouncing = flying
    rolling = torch.stack(rolling_velocity(_columns(velocity), _columns(spin), _columns(normal)), -1)
    return position, rolling, time, hops


def _roll_level(position: torch.Tensor, velocity: torch.Tensor, resistance: torch.Tensor,
                drag: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Rest point and roll time on level ground (closed form, `stopping`)."""
    speed = torch.linalg.vector_norm(velocity, dim=-1)
    distance, time = stopping(speed, resistance * GRAVITY_MPS2, drag)
    direction = velocity / speed.clamp_min(TINY)[:, None]
    return position + direction * distance[:, None], time


def _roll_slope(position: torch.Tensor, velocity: torch.Tensor, normal: torch.Tensor, resistance: torch.Tensor,
                drag: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Rest point and roll time on slopes, in `slope_step`s until every ball has stopped."""
    downhill = torch.stack(downhill_acceleration(_columns(normal)), -1)
    brake = resistance * GRAVITY_MPS2 * normal[:, 2]
    position, velocity = position.clone(), velocity.clone()
    rest, time = position.clone(), position.new_zeros(len(position))
    moving = torch.arange(len(position), device=position.device)
    for _ in range(int(MAX_ROLL_TIME_S / ROLL_STEP_S)):
        if not moving.numel():
            break
        stops, taken, stop_at, moved, after = slope_step(
            _columns(position[moving]), _columns(velocity[moving]), _columns(downhill[moving]), brake[moving],
            drag[moving],
        )
        stopped, going = moving[stops], moving[~stops]
        rest[stopped] = torch.stack(stop_at, -1)[stops]
        time[moving] += taken
        position[going], velocity[going] = torch.stack(moved, -1)[~stops], torch.stack(after, -1)[~stops]
        moving = going
    rest[moving] = position[moving]
    return rest, time


def ground_phase(position: torch.Tensor, velocity: torch.Tensor, spin: torch.Tensor, normal: torch.Tensor,
                 surface: Surface) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Bounce and roll a batch of balls to rest from their landing states [N,3] (position on the ground, velocity,
    spin in rad/s) on planes of unit `normal` [N,3] through the landing points; `surface` holds floats or [N]
    tensors. (rest points [N,3], hops [N], time on the ground [N]), as `flight.ground.ground_phase` gives them."""
    n = len(position)
    resistance, drag = (torch.as_tensor(value, dtype=position.dtype, device=position.device).expand(n)
                        for value in (surface.rolling_resistance, surface.grass_drag_per_s))
    start, rolling, time, hops = _bounce(position, velocity, spin, normal, surface)
    level = normal[:, 2] == 1.0
    rest, roll_time = torch.empty_like(start), position.new_empty(n)
    rest[level], roll_time[level] = _roll_level(start[level], rolling[level], resistance[level], drag[level])
    sloped = ~level
    if bool(sloped.any()):
        rest[sloped], roll_time[sloped] = _roll_slope(start[sloped], rolling[sloped], normal[sloped],
                                                      resistance[sloped], drag[sloped])
    return rest, hops, time + roll_time
