"""Air: thinner or denser than assumed, as real air (the Reynolds number with it) or as density alone, and for
recordings that carry their air the Reynolds number the recordings' physics reads it at."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
from golfflight.discovery.effects.base import Context, Effect, Hiding, Parameter, Reported, World, unchanged
from golfflight.discovery.effects.parts import plus_minus, single
from golfflight.discovery.schema import AirAltitude, AirDensity, CorrectionSettings
from golfflight.discovery.simulator import Setup
from golfflight.flight.air import DRY_AIR_GAS_CONSTANT, ZERO_CELSIUS_K, Air, altitude_for_pressure

DENSITY_ONLY = "air_density_only"
"""The density-only variant of air density (no Reynolds change)."""

AIR_VARIANTS: tuple[str, ...] = ("air_density", DENSITY_ONLY)
"""Air density as real air changes it (the Reynolds number with it) and density alone."""

NOMINAL_AIR = Air.standard()
"""The air of concealed sets' base sessions and the air the model is told: 15 degC, sea level, dry (1.225 kg/m^3)."""

NOMINAL_CONTEXT = Context(float(NOMINAL_AIR.density_kg_m3), 15.0)


def equivalent_altitude_m(ratio: float, context: Context) -> float:
    """Standard-atmosphere height whose (dry) air at the assumed temperature has `ratio` x the assumed density."""
    pressure = ratio * context.density_kg_m3 * DRY_AIR_GAS_CONSTANT * (context.temperature_c + ZERO_CELSIUS_K)
    return float(altitude_for_pressure(pressure))


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


def _describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
    ratio, sd = float(theta[0]), float(np.sqrt(max(covariance[0, 0], 0.0)))
    altitude = equivalent_altitude_m(ratio, context)
    slope = abs(equivalent_altitude_m(ratio + 1e-4, context) - equivalent_altitude_m(ratio - 1e-4, context)) / 2e-4
    return (
        {"ratio": ratio, "equivalent_altitude_m": altitude, "density_kg_m3": ratio * context.density_kg_m3},
        {"ratio": sd, "equivalent_altitude_m": slope * sd, "density_kg_m3": sd * context.density_kg_m3},
    )


def _phrase(tail: str) -> Callable[[dict[str, float], dict[str, float]], str]:
    def phrase(p: dict[str, float], u: dict[str, float]) -> str:
        return (
            f"air {plus_minus(p['ratio'], u['ratio'])} times as dense as assumed "
            f"(as at about {p['equivalent_altitude_m']:.0f} ± {u['equivalent_altitude_m']:.0f} m{tail})"
        )

    return phrase


def _setting(settings: CorrectionSettings, p: dict[str, float], context: Context, wind_factor: float | None) -> None:
    """The air as the service's density option and, the same air, as altitude at the assumed temperature."""
    settings.air = AirDensity(density_kg_m3=p["density_kg_m3"])
    settings.air_as_altitude = AirAltitude(altitude_m=p["equivalent_altitude_m"], temperature_c=context.temperature_c)


def _thinner_or_denser(rng: np.random.Generator) -> dict[str, float]:
    """Thinner three times in four (5-22 %: altitude, heat), else 3-8 % denser (cold)."""
    thinner = rng.random() < 0.75
    return {"ratio": float(1 - rng.uniform(0.05, 0.22) if thinner else 1 + rng.uniform(0.03, 0.08))}


def _real_air(p: dict[str, float], world: World) -> World:
    """Dry air at 15 degC at the height that has this density."""
    return replace(world, air=Air.from_conditions(15.0, equivalent_altitude_m(p["ratio"], NOMINAL_CONTEXT), 0.0))


def _density_alone(p: dict[str, float], world: World) -> World:
    """The nominal air's density times the ratio, its viscosity unchanged."""
    return replace(world, air=Air(NOMINAL_AIR.density_kg_m3 * p["ratio"], NOMINAL_AIR.kinematic_viscosity_m2_s))


_RATIO = Parameter("ratio", "1", 1.0, 0.6, 1.3, 0.05, 0.01)

AIR_DENSITY = Effect(
    "air_density",
    (_RATIO,),
    _density,
    _describe,
    "the air is thinner or denser than assumed (altitude, temperature, pressure), with the Reynolds number "
    "changed as real air changes it",
    kind="venue",
    words="air density",
    phrase=_phrase(""),
    setting=_setting,
    hiding=Hiding(_thinner_or_denser, unchanged, _real_air, _density),
    stand_ins=(DENSITY_ONLY,),
)

AIR_DENSITY_ONLY = Effect(
    DENSITY_ONLY,
    (_RATIO,),
    _density_only,
    _describe,
    "the air density differs with the Reynolds number unchanged: drag, lift and spin torque scaled together, "
    "as flight models that take density alone fly thin air",
    kind="venue",
    words="air density alone",
    phrase=_phrase("; density alone, the Reynolds number unchanged"),
    setting=_setting,
    hiding=Hiding(_thinner_or_denser, unchanged, _density_alone, _density_only),
    stand_ins=("air_density",),
)

REYNOLDS_SCALE = Effect(
    "reynolds_scale",
    (Parameter("scale", "1", 1.0, 0.5, 2.0, 0.1, 0.02),),
    _reynolds,
    single("scale"),
    "the recordings' physics reads the coefficients at this many times the Reynolds number the recorded air gives "
    "(a flight model that takes the recorded density alone: scale = ICAO density / recorded density)",
    kind="form",
    words="Reynolds number",
    phrase=lambda p, u: (
        f"the coefficients read at {plus_minus(p['scale'], u['scale'])} times the Reynolds number of the recorded "
        "air (1 / the density ratio for a flight model that takes density alone)"
    ),
)
"""For recordings that carry their air, in place of the air variants: what can still differ about the air is how the
recordings' physics reads it. Real air and density alone differ by exactly this (`discovery.physical`)."""
