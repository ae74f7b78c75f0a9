"""The one table of ground surfaces and their parameters (Penner's impact model plus rolling resistance).

Parameters per surface: `restitution_scale` multiplies Penner's normal restitution e(v_n) (1 = his fairway);
`critical_angle_deg` is Penner's theta_c, the angle the turf tilts the contact plane towards the incoming ball at
a normal speed of 13 m/s (in proportion to it otherwise, `flight.ground.impact`); `friction` is the kinetic
(Coulomb) friction coefficient that caps the tangential impulse of an impact; `rolling_resistance` is the rolling
deceleration on level ground in units of g, and `grass_drag_per_s` a further deceleration in proportion to the
rolling speed (grass the ball brushes through: a fast roll slows sooner). The fairway row is fitted on THE PLAYERS
2020 rest positions (`golfflight ground-fit`, docs/ground.md); the other rows are anchors from the literature
(Penner 2002, libgolf, openfairway; docs/ground.md), not measurements, but for the firm fairway: the fitted
fairway with Penner's restitution, the fit's least rolling resistance and half its grass drag, set by that rule and
not tuned. A green's rolling resistance comes from its stimpmeter reading.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
from golfflight.flight.constants import FOOT_M, GRAVITY_MPS2

STIMPMETER_EXIT_SPEED_MPS = 6.00 * FOOT_M
"""Speed a ball leaves the stimpmeter's ramp at, rolling: 6.00 ft/s = 1.83 m/s (the USGA device: released from the
notch 30 in up a 36 in bar at about 20 degrees; the figure quoted by its description, e.g. Wikipedia "Stimpmeter")."""

DEFAULT_STIMP_FT = 10.0
"""A green's stimpmeter reading when none is given (a fast club green; tour greens run 12-14)."""

ROLLING_GRAVITY_FRACTION = 5.0 / 7.0
"""Share of the along-slope gravity that accelerates a rolling solid sphere (I = 2/5 m R^2)."""


def green_rolling_resistance(stimp_ft: float | np.ndarray) -> float | np.ndarray:
    """Rolling deceleration (in g) of a green that stops a ball rolling off the stimpmeter at 1.83 m/s after
    `stimp_ft` feet: v0^2 / (2 g S), the stimpmeter's own definition of green speed."""
    return STIMPMETER_EXIT_SPEED_MPS**2 / (2.0 * GRAVITY_MPS2 * np.asarray(stimp_ft, dtype=float) * FOOT_M)


@dataclass(frozen=True)
class Surface:
    """Parameters of one surface, or of a batch (each field a float or an [N] array)."""

    restitution_scale: float | np.ndarray
    critical_angle_deg: float | np.ndarray
    friction: float | np.ndarray
    rolling_resistance: float | np.ndarray
    grass_drag_per_s: float | np.ndarray

    def take(self, index: np.ndarray) -> Surface:
        """The parameters of some balls of a batch."""
        return Surface(*(v[index] if np.ndim(v) else v for v in (getattr(self, f.name) for f in fields(self))))

    @staticmethod
    def stack(surfaces: list[Surface]) -> Surface:
        """One batch Surface from one Surface per ball."""
        return Surface(*(np.array([getattr(s, f.name) for s in surfaces], dtype=float) for f in fields(Surface)))


SURFACES: dict[str, Surface] = {
    "fairway": Surface(0.6627, 0.00067, 0.5, 0.1301, 1.321),
    "firm_fairway": Surface(1.0, 0.0, 0.4, 0.08, 0.8),
    "rough": Surface(0.55, 20.0, 0.62, 0.35, 1.5),
    "green": Surface(0.75, 20.6, 0.58, float(green_rolling_resistance(DEFAULT_STIMP_FT)), 0.0),
    "bunker": Surface(0.2, 30.0, 0.8, 1.0, 3.0),
}
"""Surface presets by name; `surface(name, ...)` overrides any parameter."""


def surface(name: str, stimp_ft: float | None = None, **overrides: float) -> Surface:
    """A preset with parameters overridden; `stimp_ft` (greens only) sets the green's rolling resistance."""
    if name not in SURFACES:
        raise ValueError(f"surface {name!r} is not one of {', '.join(SURFACES)}")
    preset = SURFACES[name]
    if stimp_ft is not None:
        if name != "green":
            raise ValueError(f"stimp_ft is a green's reading; surface {name!r} takes none")
        preset = replace(preset, rolling_resistance=float(green_rolling_resistance(stimp_ft)))
    return replace(preset, **overrides)


def holding_slope_deg(rolling_resistance: float | np.ndarray) -> float | np.ndarray:
    """The steepest slope a surface holds a ball still on: (5/7) g sin(phi) < c_r g cos(phi). Steeper, a ball never
    comes to rest on an endless plane."""
    return np.degrees(np.arctan(np.asarray(rolling_resistance, dtype=float) / ROLLING_GRAVITY_FRACTION))
