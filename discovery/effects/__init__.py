"""The effect library: physics a simulation can leave out, each a small object that modifies a simulation.

An effect has named internal parameters (with a null value that means "no effect", bounds, a typical size and a
finite-difference step) and `apply(theta, conditions)`, which turns the recorded launches and assumed conditions
into those of the world with the effect (theta is [N, k]: one parameter set per shot, so several sets can fly in
one batch). `describe` turns fitted internal parameters into the reported ones, in the conventions fixed by the
issue (wind: speed_mps and from_deg; air_density: ratio = true/assumed and the equivalent altitude; launch biases:
offset = true - recorded or scale = true/recorded; landing_elevation: height_m, negative = below the tee).

Each effect is one module of this package (`base.Effect` says what it holds); this module only registers them.
"""

from __future__ import annotations

from golfflight.discovery.effects.air import (
    AIR_DENSITY,
    AIR_DENSITY_ONLY,
    AIR_VARIANTS,
    DENSITY_ONLY,
    NOMINAL_AIR,
    NOMINAL_CONTEXT,
    REYNOLDS_SCALE,
    equivalent_altitude_m,
)
from golfflight.discovery.effects.ball import BALL
from golfflight.discovery.effects.base import (
    KINDS,
    Context,
    Draw,
    Effect,
    Hiding,
    Kind,
    Parameter,
    Reported,
    World,
    apply_all,
)
from golfflight.discovery.effects.coefficients import ALIASES, DRAG_SCALE, LIFT_SCALE, SPIN_DECAY
from golfflight.discovery.effects.ground import LANDING_ELEVATION
from golfflight.discovery.effects.monitor import (
    BALL_SPEED_BIAS,
    LAUNCH_ANGLE_BIAS,
    LAUNCH_DIRECTION_BIAS,
    SPIN_AXIS_BIAS,
    SPIN_BIAS,
)
from golfflight.discovery.effects.wind import WIND, wind_from_components

LIBRARY: tuple[Effect, ...] = (
    WIND,
    AIR_DENSITY,
    AIR_DENSITY_ONLY,
    LAUNCH_ANGLE_BIAS,
    LAUNCH_DIRECTION_BIAS,
    BALL_SPEED_BIAS,
    SPIN_BIAS,
    SPIN_AXIS_BIAS,
    LANDING_ELEVATION,
    SPIN_DECAY,
    DRAG_SCALE,
    LIFT_SCALE,
)
"""Every library effect, in report order."""

EFFECTS: dict[str, Effect] = {effect.name: effect for effect in (*LIBRARY, REYNOLDS_SCALE, BALL)}
"""Every effect by name, in the order `discovery.conceal` hides them (real air before density alone): the library,
and those offered only where they apply (the Reynolds scale where the air is recorded, another ball against a
baseline session)."""

__all__ = [
    "AIR_VARIANTS",
    "ALIASES",
    "BALL",
    "DENSITY_ONLY",
    "EFFECTS",
    "KINDS",
    "LIBRARY",
    "NOMINAL_AIR",
    "NOMINAL_CONTEXT",
    "REYNOLDS_SCALE",
    "Context",
    "Draw",
    "Effect",
    "Hiding",
    "Kind",
    "Parameter",
    "Reported",
    "World",
    "apply_all",
    "equivalent_altitude_m",
    "wind_from_components",
]
