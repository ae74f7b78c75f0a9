"""Effects outside the library, hidden in the diagnosed model's own flights as an extra acceleration.

None of them is a condition, a launch bias or a uniform coefficient scale, so no library effect can explain their
structure: a drag rise at low speed only, and a lift loss at high spin ratio only. Each is one function of the
air-relative velocity and the spin, with its size and threshold per shot in the weights (`flight.field`).
"""

from __future__ import annotations

import numpy as np

from discovery.simulator import Correction
from flight.constants import BALL_AREA_M2, BALL_MASS_KG, BALL_RADIUS_M

LOW_SPEED_DRAG = "low_speed_drag"
"""{"rise": extra C_D at zero air speed, "speed_mps": the air speed where it has faded to nothing}."""

HIGH_SPIN_LIFT_LOSS = "high_spin_lift_loss"
"""{"loss": C_L lost per unit of spin ratio above the threshold, "spin_ratio": the threshold}."""

OUTSIDE = (LOW_SPEED_DRAG, HIGH_SPIN_LIFT_LOSS)


def _pressure_over_mass(v: np.ndarray, density: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(|v| [N,1], q A / m [N,1]) of air-relative velocities v [N,3] in air of this density [N]."""
    speed = np.linalg.norm(v, axis=1, keepdims=True)
    return speed, 0.5 * density[:, None] * speed**2 * BALL_AREA_M2 / BALL_MASS_KG


def low_speed_drag(v: np.ndarray, w: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Extra drag [N,3] of C_D += rise x max(0, 1 - |v| / speed); weights [N,3] = (rise, speed, density)."""
    rise, fade, density = weights.T
    speed, pressure = _pressure_over_mass(v, density)
    extra_cd = rise[:, None] * np.clip(1.0 - speed / fade[:, None], 0.0, None)
    return -extra_cd * pressure * v / np.maximum(speed, 1e-9)


def high_spin_lift_loss(v: np.ndarray, w: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Lift lost [N,3] of C_L -= loss x max(0, S - threshold), along the Magnus direction; weights [N,3] = (loss,
    threshold, density)."""
    loss, threshold, density = weights.T
    speed, pressure = _pressure_over_mass(v, density)
    spin = np.linalg.norm(w, axis=1, keepdims=True)
    ratio = BALL_RADIUS_M * spin / np.maximum(speed, 1e-9)
    lost_cl = loss[:, None] * np.clip(ratio - threshold[:, None], 0.0, None)
    magnus = np.cross(w, v)
    magnus /= np.maximum(np.linalg.norm(magnus, axis=1, keepdims=True), 1e-12)
    return -lost_cl * pressure * magnus


TERMS = {
    LOW_SPEED_DRAG: (low_speed_drag, ("rise", "speed_mps")),
    HIGH_SPIN_LIFT_LOSS: (high_spin_lift_loss, ("loss", "spin_ratio")),
}


def term_and_weights(
    hidden: dict[str, dict[str, float]], density: np.ndarray
) -> tuple[Correction | None, np.ndarray | None]:
    """The extra acceleration of the one outside effect in `hidden` with its weights [N,3], or (None, None)."""
    present = [name for name in OUTSIDE if name in hidden]
    if not present:
        return None, None
    if len(present) > 1:
        raise ValueError(f"one outside effect at a time, not {present}")
    term, keys = TERMS[present[0]]
    values = [np.full(density.shape, hidden[present[0]][k]) for k in keys]
    return term, np.stack(values + [density], axis=1)
