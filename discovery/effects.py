"""The effect library: physics a simulation can leave out, each a small object that modifies a simulation.

An effect has named internal parameters (with a null value that means "no effect", bounds, a typical size and a
finite-difference step) and `apply(theta, conditions)`, which turns the recorded launches and assumed conditions
into those of the world with the effect (theta is [N, k]: one parameter set per shot, so several sets can fly in
one batch). `describe` turns fitted internal parameters into the reported ones, in the conventions fixed by the
issue (wind: speed_mps and from_deg; air_density: ratio = true/assumed and the equivalent altitude; launch biases:
offset = true - recorded or scale = true/recorded; landing_elevation: height_m, negative = below the tee).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from golfflight.discovery.simulator import Correction, Setup
from golfflight.flight.air import DRY_AIR_GAS_CONSTANT, ZERO_CELSIUS_K, altitude_for_pressure


@dataclass(frozen=True)
class Parameter:
    """One internal parameter of an effect."""

    name: str
    unit: str
    null: float
    low: float
    high: float
    typical: float
    """Typical size of a real effect: the scale the optimiser works in."""
    step: float
    """Finite-difference step: large enough to step over the integrator's landing kinks."""


Reported = tuple[dict[str, float], dict[str, float]]

Kind = Literal["venue", "monitor", "form"]
"""What an effect says about the recordings: a condition of the venue (air, wind, ground), a bias of the launch
monitor's launch values, or the model's form (its coefficients or a learned correction: the recordings' physics
differs from the model's in form). Venue and monitor findings are what a user acts on; a form finding says the model
itself differs, whatever the venue."""

KINDS: dict[Kind, str] = {
    "venue": "a condition of the venue",
    "monitor": "a bias of the launch monitor",
    "form": "the model's form",
}

DENSITY_ONLY = "air_density_only"
"""The density-only variant of air density (no Reynolds change)."""


@dataclass(frozen=True)
class Effect:
    """A named effect with its parameters, how it changes a simulation and how its parameters are reported."""

    name: str
    parameters: tuple[Parameter, ...]
    apply: Callable[[np.ndarray, Setup], Setup]
    describe: Callable[[np.ndarray, np.ndarray, Context], Reported]
    summary: str
    correction: Correction | None = None
    """Extra acceleration the simulator adds (the learned correction); library effects have none."""
    kind: Kind = "form"

    @property
    def null(self) -> np.ndarray:
        return np.array([p.null for p in self.parameters])

    @property
    def size(self) -> int:
        return len(self.parameters)


@dataclass(frozen=True)
class Context:
    """What reporting needs beyond the parameters: the air the model assumed."""

    density_kg_m3: float
    temperature_c: float


def _launch(name: str, offset: bool) -> Callable[[np.ndarray, Setup], Setup]:
    def apply(theta: np.ndarray, conditions: Setup) -> Setup:
        out = conditions.copy()
        out.launch[name] = out.launch[name] + theta[:, 0] if offset else out.launch[name] * theta[:, 0]
        return out

    return apply


def _coefficient(column: int) -> Callable[[np.ndarray, Setup], Setup]:
    def apply(theta: np.ndarray, conditions: Setup) -> Setup:
        out = conditions.copy()
        out.coefficient_scale = out.coefficient_scale.copy()
        out.coefficient_scale[:, column] *= theta[:, 0]
        return out

    return apply


def _wind(theta: np.ndarray, conditions: Setup) -> Setup:
    out = conditions.copy()
    out.wind_xy_mps = out.wind_xy_mps + theta[:, :2]
    return out


def _density(theta: np.ndarray, conditions: Setup) -> Setup:
    """Real air `ratio` x as dense: the dynamic pressure scales with it and, at the same temperature, the kinematic
    viscosity with its inverse, so the Reynolds number scales with it too (density alone, then the Reynolds scale)."""
    return _reynolds(theta, _density_only(theta, conditions))


def _reynolds(theta: np.ndarray, conditions: Setup) -> Setup:
    """The coefficients read at `scale` x the Reynolds number the assumed air gives (its viscosity / scale)."""
    out = conditions.copy()
    out.viscosity_ratio = out.viscosity_ratio / theta[:, 0]
    return out


def _density_only(theta: np.ndarray, conditions: Setup) -> Setup:
    """Density `ratio` x the assumed one with the viscosity unchanged: drag, lift and spin torque scaled together
    and nothing else, as flight models that take density alone (some launch monitors' and rigs') fly thin air."""
    out = conditions.copy()
    out.density_ratio = out.density_ratio * theta[:, 0]
    return out


def _ground(theta: np.ndarray, conditions: Setup) -> Setup:
    out = conditions.copy()
    out.ground_height_m = out.ground_height_m + theta[:, 0]
    return out


def _single(key: str) -> Callable[[np.ndarray, np.ndarray, Context], Reported]:
    def describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
        return {key: float(theta[0])}, {key: float(np.sqrt(max(covariance[0, 0], 0.0)))}

    return describe


def wind_from_components(x_mps: float, y_mps: float) -> tuple[float, float]:
    """(speed, direction it blows FROM, degrees clockwise from the target line) of an air velocity (x, y)."""
    return float(np.hypot(x_mps, y_mps)), float(np.degrees(np.arctan2(-x_mps, -y_mps)) % 360.0)


def _describe_wind(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
    speed, from_deg = wind_from_components(theta[0], theta[1])
    if speed > 0:
        along = theta[:2] / speed
        across = np.array([-along[1], along[0]])
        speed_sd = float(np.sqrt(max(along @ covariance[:2, :2] @ along, 0.0)))
        direction_sd = float(np.degrees(np.sqrt(max(across @ covariance[:2, :2] @ across, 0.0)) / speed))
    else:
        speed_sd, direction_sd = float(np.sqrt(np.trace(covariance[:2, :2]) / 2)), 180.0
    return {"speed_mps": speed, "from_deg": from_deg}, {"speed_mps": speed_sd, "from_deg": min(direction_sd, 180.0)}


def equivalent_altitude_m(ratio: float, context: Context) -> float:
    """Standard-atmosphere height whose (dry) air at the assumed temperature has `ratio` x the assumed density."""
    pressure = ratio * context.density_kg_m3 * DRY_AIR_GAS_CONSTANT * (context.temperature_c + ZERO_CELSIUS_K)
    return float(altitude_for_pressure(pressure))


def _describe_density(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
    ratio, sd = float(theta[0]), float(np.sqrt(max(covariance[0, 0], 0.0)))
    altitude = equivalent_altitude_m(ratio, context)
    slope = abs(equivalent_altitude_m(ratio + 1e-4, context) - equivalent_altitude_m(ratio - 1e-4, context)) / 2e-4
    return (
        {"ratio": ratio, "equivalent_altitude_m": altitude, "density_kg_m3": ratio * context.density_kg_m3},
        {"ratio": sd, "equivalent_altitude_m": slope * sd, "density_kg_m3": sd * context.density_kg_m3},
    )


LIBRARY: tuple[Effect, ...] = (
    Effect(
        "wind",
        (
            Parameter("wind_x_mps", "m/s", 0.0, -20.0, 20.0, 3.0, 0.3),
            Parameter("wind_y_mps", "m/s", 0.0, -20.0, 20.0, 3.0, 0.3),
        ),
        _wind,
        _describe_wind,
        "a steady uniform wind (the air moves at (x, y); reported as speed and the direction it blows from)",
        kind="venue",
    ),
    Effect(
        "air_density",
        (Parameter("ratio", "1", 1.0, 0.6, 1.3, 0.05, 0.01),),
        _density,
        _describe_density,
        "the air is thinner or denser than assumed (altitude, temperature, pressure), with the Reynolds number "
        "changed as real air changes it",
        kind="venue",
    ),
    Effect(
        DENSITY_ONLY,
        (Parameter("ratio", "1", 1.0, 0.6, 1.3, 0.05, 0.01),),
        _density_only,
        _describe_density,
        "the air density differs with the Reynolds number unchanged: drag, lift and spin torque scaled together, "
        "as flight models that take density alone fly thin air",
        kind="venue",
    ),
    Effect(
        "launch_angle_bias",
        (Parameter("offset_deg", "deg", 0.0, -6.0, 6.0, 1.0, 0.1),),
        _launch("launch_angle_deg", True),
        _single("offset_deg"),
        "the true launch angle = recorded + offset",
        kind="monitor",
    ),
    Effect(
        "launch_direction_bias",
        (Parameter("offset_deg", "deg", 0.0, -10.0, 10.0, 1.0, 0.1),),
        _launch("launch_direction_deg", True),
        _single("offset_deg"),
        "the true launch direction = recorded + offset",
        kind="monitor",
    ),
    Effect(
        "ball_speed_bias",
        (Parameter("scale", "1", 1.0, 0.85, 1.15, 0.02, 0.003),),
        _launch("ball_speed_mps", False),
        _single("scale"),
        "the true ball speed = recorded x scale",
        kind="monitor",
    ),
    Effect(
        "spin_bias",
        (Parameter("scale", "1", 1.0, 0.6, 1.5, 0.05, 0.01),),
        _launch("spin_rpm", False),
        _single("scale"),
        "the true spin = recorded x scale",
        kind="monitor",
    ),
    Effect(
        "spin_axis_bias",
        (Parameter("offset_deg", "deg", 0.0, -15.0, 15.0, 2.0, 0.2),),
        _launch("spin_axis_deg", True),
        _single("offset_deg"),
        "the true spin axis = recorded + offset",
        kind="monitor",
    ),
    Effect(
        "landing_elevation",
        (Parameter("height_m", "m", 0.0, -40.0, 40.0, 5.0, 0.3),),
        _ground,
        _single("height_m"),
        "the balls land on ground this high above the tee (negative = below)",
        kind="venue",
    ),
    Effect(
        "spin_decay",
        (Parameter("scale", "1", 1.0, 0.2, 4.0, 0.3, 0.05),),
        _coefficient(2),
        _single("scale"),
        "spin decays this many times as fast as the model's C_M says",
        kind="form",
    ),
    Effect(
        "drag_scale",
        (Parameter("scale", "1", 1.0, 0.7, 1.4, 0.05, 0.005),),
        _coefficient(1),
        _single("scale"),
        "the drag coefficient is this many times the model's",
        kind="form",
    ),
    Effect(
        "lift_scale",
        (Parameter("scale", "1", 1.0, 0.6, 1.5, 0.05, 0.005),),
        _coefficient(0),
        _single("scale"),
        "the lift coefficient is this many times the model's",
        kind="form",
    ),
)
"""Every library effect, in report order."""



REYNOLDS_SCALE = Effect(
    "reynolds_scale",
    (Parameter("scale", "1", 1.0, 0.5, 2.0, 0.1, 0.02),),
    _reynolds,
    _single("scale"),
    "the recordings' physics reads the coefficients at this many times the Reynolds number the recorded air gives "
    "(a flight model that takes the recorded density alone: scale = ICAO density / recorded density)",
    kind="form",
)
"""For recordings that carry their air, in place of the air variants: what can still differ about the air is how the
recordings' physics reads it. Real air and density alone differ by exactly this (`discovery.physical`)."""

EFFECTS: dict[str, Effect] = {effect.name: effect for effect in (*LIBRARY, REYNOLDS_SCALE)}

AIR_VARIANTS: tuple[str, ...] = ("air_density", DENSITY_ONLY)
"""Air density as real air changes it (the Reynolds number with it) and density alone."""

ALIASES: tuple[str, ...] = ("lift_scale", "drag_scale", "spin_decay")
"""The coefficient scales air density is made of: air `ratio` x as dense scales drag, lift and the spin torque by
`ratio` together (exactly so for density alone; real air also moves the Reynolds number). A combination of two or
more of them that agree is air, stated with one parameter (`discovery.physical`)."""


def apply_all(effects: tuple[Effect, ...], theta: np.ndarray, conditions: Setup) -> Setup:
    """Apply several effects; theta [N, sum of their sizes] holds their parameters side by side."""
    start = 0
    for effect in effects:
        conditions = effect.apply(theta[:, start : start + effect.size], conditions)
        start += effect.size
    return conditions
