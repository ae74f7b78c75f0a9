"""The one table of ground surfaces and their parameters (the impact of `flight.ground.impact` plus rolling resistance).

Parameters per surface: `restitution_scale` multiplies Penner's normal restitution e(v_n) (1 = his fairway);
`critical_angle_deg` is Penner's theta_c, the angle the turf tilts the contact plane towards the incoming ball at his
typical approach landing, 18.6 m/s at 44 degrees from the normal (in proportion to the speed and to that angle
otherwise), and `max_tilt_deg` the most it tilts at any landing: the rim of the deepest pitch mark the turf takes (a
mark d deep has its rim at arccos(1 - d / R) from the ball's lowest point); `friction` is the kinetic (Coulomb)
friction coefficient that caps the tangential impulse of an impact, and `spin_damping_s_per_m` the share of the spin
(along the contact plane) the turf's torque takes per metre per second of normal impulse; `rolling_resistance` is the
rolling deceleration on level ground in units of g, and `grass_drag_per_s` a further deceleration in proportion to
the rolling speed (grass the ball brushes through: a fast roll slows sooner).

Where the rows come from (docs/ground.md says more):
- fairway: fitted on THE PLAYERS 2020 rest positions (`golfflight ground-fit`), friction held at 0.5 (openfairway's
  fairway) and spin damping at 0; its tilt is a hair and never nears a cap;
- firm_fairway: the fitted fairway with Penner's restitution, the fit's least rolling resistance and grass drag
  0.8 /s, set by that rule and not tuned;
- rough: the fitted fairway times the anchors' rough-to-fairway ratios (ROUGH_OVER_FAIRWAY): every parameter soaks up
  at least as much as the fairway's, so a landing runs less far in the rough;
- green: a firm, freely drained tour green that takes a pitch mark from every approach. Friction 0.115 and spin
  damping 0.015 s/m put Haake's threshold at Penner's typical landing: the ball keeps its back spin through the bounce
  only above 350 rad/s. Friction at the contact point takes spin with every bit of speed it takes, so with that
  threshold it cannot stop an approach iron; the pitch mark's front wall, pushing through the ball's centre, takes
  the forward speed and leaves the spin. Its theta_c is 20 degrees (Penner's fit to Haake's greens: 15.4), so that
  calm tour 7-irons and wedges check on a green at least as well as TrackMan's table has them run on a fairway; capped
  at 38 degrees, the rim of a pitch mark 4.5 mm deep, so that a drive skimming in downwind (Penner's fit would give it
  52) is not stopped by a wall; friction against spin damping split so that the steepest headwind wedges spin back a
  few yards. These four are set to the anchors, not measured (docs/ground.md). The restitution is libgolf's
  green-to-fairway ratio (0.3-0.4 against 0.4-0.5: about three quarters); the rolling resistance comes from the
  stimpmeter reading, with no grass drag, so the reading maps exactly;
- bunker: anchors (Penner's soft-turf tilt and more, libgolf's and openfairway's figures), not measurements.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
from golfflight.errors import InputError
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
    spin_damping_s_per_m: float | np.ndarray
    rolling_resistance: float | np.ndarray
    grass_drag_per_s: float | np.ndarray
    max_tilt_deg: float | np.ndarray = 90.0
    """The steepest the contact plane tilts (90: no cap but the ball's own incoming angle, `impact.penner_tilt`)."""

    def take(self, index: np.ndarray) -> Surface:
        """The parameters of some balls of a batch."""
        return Surface(*(v[index] if np.ndim(v) else v for v in (getattr(self, f.name) for f in fields(self))))

    @staticmethod
    def stack(surfaces: list[Surface]) -> Surface:
        """One batch Surface from one Surface per ball."""
        return Surface(*(np.array([getattr(s, f.name) for s in surfaces], dtype=float) for f in fields(Surface)))


FAIRWAY = Surface(0.6631, 0.000549, 0.5, 0.0, 0.1296, 1.322)
"""The fitted fairway (`golfflight ground-fit`, docs/ground.md)."""

ROUGH_OVER_FAIRWAY = {
    "restitution_scale": 0.25 / 0.45,
    "critical_angle_deg": 0.35 / 0.29,
    "friction": 0.62 / 0.50,
    "rolling_resistance": 0.095 / 0.050,
    "grass_drag_per_s": 0.0032 / 0.0017,
}
"""The rough's parameters over the fairway's in the anchors: libgolf's restitution (rough 0.2-0.3, fairway 0.4-0.5,
mid-ranges) and openfairway's critical angle, kinetic friction, rolling friction and grass drag."""


def scaled(base: Surface, ratios: dict[str, float]) -> Surface:
    """`base` with some parameters multiplied by `ratios` (by name)."""
    return replace(base, **{name: getattr(base, name) * ratio for name, ratio in ratios.items()})


SURFACES: dict[str, Surface] = {
    "fairway": FAIRWAY,
    "firm_fairway": Surface(1.0, 0.0, 0.4, 0.0, 0.08, 0.8),
    "rough": scaled(FAIRWAY, ROUGH_OVER_FAIRWAY),
    "green": Surface(0.75, 20.0, 0.115, 0.015, float(green_rolling_resistance(DEFAULT_STIMP_FT)), 0.0, 38.0),
    "bunker": Surface(0.2, 30.0, 0.8, 0.0, 1.0, 3.0),
}
"""Surface presets by name; `surface(name, ...)` overrides any parameter."""


def surface(name: str, stimp_ft: float | None = None, **overrides: float) -> Surface:
    """A preset with parameters overridden; `stimp_ft` (greens only) sets the green's rolling resistance."""
    if name not in SURFACES:
        raise InputError(f"surface {name!r} is not one of {', '.join(SURFACES)}")
    preset = SURFACES[name]
    if stimp_ft is not None:
        if name != "green":
            raise InputError(f"stimp_ft is a green's reading; surface {name!r} takes none")
        preset = replace(preset, rolling_resistance=float(green_rolling_resistance(stimp_ft)))
    return replace(preset, **overrides)


def holding_slope_deg(rolling_resistance: float | np.ndarray) -> float | np.ndarray:
    """The steepest slope a surface holds a ball still on: (5/7) g sin(phi) < c_r g cos(phi). Steeper, a ball never
    comes to rest on an endless plane."""
    return np.degrees(np.arctan(np.asarray(rolling_resistance, dtype=float) / ROLLING_GRAVITY_FRACTION))


def check_slope_held(
    slope_deg: float | np.ndarray, rolling_resistance: float | np.ndarray, surface_name: str = "the surface"
) -> None:
    """InputError naming slope_deg, the steepest slope the surface holds and the range allowed, where a slope (one or
    [N], each with its surface's rolling resistance) is not below `holding_slope_deg`: the one check of every place
    that takes a slope (a shot's ground, the ground phase, a request)."""
    limit = holding_slope_deg(rolling_resistance)
    steep = slope_deg >= limit  # NumPy's (limit is), so `any` is there for one slope too: the single shot's few us
    if not steep.any():
        return
    first = int(np.argmax(steep))
    slope, held = (float(np.ravel(np.broadcast_to(v, np.shape(steep)))[first]) for v in (slope_deg, limit))
    raise InputError(
        f"slope_deg: {slope:g} is steeper than {surface_name} holds a ball still on ({held:.2f} deg: it would never "
        f"come to rest); allowed 0 to {held - 0.005:.2f} deg on this surface"
    )
