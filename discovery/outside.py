"""Effects outside the library, hidden in the diagnosed model's own flights.

None of them is a condition, a launch bias or a uniform coefficient scale, so no library effect can explain their
structure: a drag rise at low speed only and a lift loss at high spin ratio only (each an extra acceleration of the
air-relative velocity and the spin, with its size and threshold per shot in the weights, `flight.field`), and a gust
that blows only above a height and grows with it (a wind the ball meets above the trees: it needs the ball's height,
so it is the air's motion the model flies through, `HeightGust`, and acts through the model's own coefficients).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property

import numpy as np
from golfflight.discovery.simulator import Correction
from golfflight.errors import InputError
from golfflight.flight.physics import aerodynamics, spin_ratio
from golfflight.flight.wind import Wind, wind_vector

LOW_SPEED_DRAG = "low_speed_drag"
"""{"rise": extra C_D at zero air speed, "speed_mps": the air speed where it has faded to nothing}."""

HIGH_SPIN_LIFT_LOSS = "high_spin_lift_loss"
"""{"loss": C_L lost per unit of spin ratio above the threshold, "spin_ratio": the threshold}."""

HEIGHT_GUST = "height_gust"
"""{"rate_mps_per_m": extra wind speed per metre above the threshold, "height_m": the threshold, "from_deg": where it
blows from (the report's wind convention)}."""

OUTSIDE = (LOW_SPEED_DRAG, HIGH_SPIN_LIFT_LOSS, HEIGHT_GUST)


def _coefficient_acceleration(v: np.ndarray, w: np.ndarray, c_lift: np.ndarray, c_drag: np.ndarray,
                               density: np.ndarray) -> np.ndarray:
    """The acceleration [N,3] of extra lift and drag coefficients [N] at air-relative velocity and spin [N,3] in air
    of this density [N]: `flight.physics.aerodynamics`' drag and Magnus lift at C_Q 0.5, the flight's own q A / m."""
    no_moment, half = np.zeros(len(v)), np.full(len(v), 0.5)
    return aerodynamics(v, w, np.stack([c_lift, c_drag, no_moment, half], axis=1), density)[0]


def low_speed_drag(v: np.ndarray, w: np.ndarray, r: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Extra drag [N,3] of C_D += rise x max(0, 1 - |v| / speed); weights [N,3] = (rise, speed, density)."""
    rise, fade, density = weights.T
    extra_cd = rise * np.clip(1.0 - np.linalg.norm(v, axis=1) / fade, 0.0, None)
    return _coefficient_acceleration(v, w, np.zeros(len(v)), extra_cd, density)


def high_spin_lift_loss(v: np.ndarray, w: np.ndarray, r: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Lift lost [N,3] of C_L -= loss x max(0, S - threshold), along the Magnus direction (S `flight.physics.
    spin_ratio`); weights [N,3] = (loss, threshold, density)."""
    loss, threshold, density = weights.T
    lost_cl = loss * np.clip(spin_ratio(v, w) - threshold, 0.0, None)
    return _coefficient_acceleration(v, w, -lost_cl, np.zeros(len(v)), density)


TERMS = {
    LOW_SPEED_DRAG: (low_speed_drag, ("rise", "speed_mps")),
    HIGH_SPIN_LIFT_LOSS: (high_spin_lift_loss, ("loss", "spin_ratio")),
}


@dataclass(frozen=True)
class HeightGust(Wind):
    """A wind plus a gust that is still below `threshold_m` and grows by `rate_mps_per_m` per metre above it, from
    `gust_from_deg`: the air a ball meets once it rises above sheltering trees (or into a stronger layer). It is a
    `flight.wind.Wind` (the base wind in its fields, per shot or shared), so every flight core takes it; the gust is
    the same for every shot."""

    rate_mps_per_m: float = 0.0
    threshold_m: float = 0.0
    gust_from_deg: float = 0.0

    @cached_property
    def is_calm(self) -> bool:
        return self.rate_mps_per_m == 0.0 and super().is_calm

    def velocity(self, height_m: np.ndarray) -> np.ndarray:
        above = np.clip(np.asarray(height_m, dtype=float) - self.threshold_m, 0.0, None)
        gust = wind_vector(self.rate_mps_per_m, self.gust_from_deg) * above[..., None]
        return super().velocity(height_m) + gust

    def take(self, index: np.ndarray) -> HeightGust:
        return _with_gust(super().take(index), self.rate_mps_per_m, self.threshold_m, self.gust_from_deg)


def _with_gust(base: Wind, rate_mps_per_m: float, threshold_m: float, from_deg: float) -> HeightGust:
    return HeightGust(
        **{f.name: getattr(base, f.name) for f in fields(Wind)},
        rate_mps_per_m=rate_mps_per_m,
        threshold_m=threshold_m,
        gust_from_deg=from_deg,
    )


def air_motion(hidden: dict[str, dict[str, float]], base: Wind) -> Wind:
    """The air the model's flights meet: `base`, plus the gust of `HEIGHT_GUST` when it is hidden."""
    if HEIGHT_GUST not in hidden:
        return base
    gust = hidden[HEIGHT_GUST]
    return _with_gust(base, gust["rate_mps_per_m"], gust["height_m"], gust["from_deg"])


def term_and_weights(
    hidden: dict[str, dict[str, float]], density: np.ndarray
) -> tuple[Correction | None, np.ndarray | None]:
    """The extra acceleration of the one outside effect in `hidden` with its weights [N,3], or (None, None) when it
    has none (none hidden, or the gust, which is air motion: `air_motion`)."""
    present = [name for name in OUTSIDE if name in hidden]
    if len(present) > 1:
        raise InputError(f"one outside effect at a time, not {present}")
    if not present or present[0] not in TERMS:
        return None, None
    term, keys = TERMS[present[0]]
    values = [np.full(density.shape, hidden[present[0]][k]) for k in keys]
    return term, np.stack(values + [density], axis=1)
