"""Recordings with a known effect hidden in them: synthetic sessions flown through the reference world, or through
the model being diagnosed (its own flights, as the service flies them, so clean sets are its own output plus noise).

The base sessions are the synthetic generator's (players and robots, several clubs, realistic launch scatter and
launch-monitor noise) but in calm air at ICAO standard conditions, the air the shipped model assumes, so the hidden
effect is the only thing that differs from what the model is told. Launch biases are hidden by recording
recorded = true - offset (or true / scale) before the noise is added.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from golfflight.discovery.effects import AIR_VARIANTS, DENSITY_ONLY, Context, equivalent_altitude_m
from golfflight.discovery.model import FlightModel
from golfflight.discovery.noise import RADAR_NOISE
from golfflight.discovery.outside import OUTSIDE, air_motion, term_and_weights
from golfflight.discovery.simulator import Setup
from golfflight.errors import InputError
from golfflight.flight.air import Air
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import initial_state
from golfflight.flight.reference_aero import CALIBRATED
from golfflight.flight.wind import Wind, uniform_equivalent_factor, wind_vector
from golfflight.shots.records import ShotRecord, ShotSet
from golfflight.shots.reference_world import fly_reference
from golfflight.shots.synth import (
    MIN_APEX_M,
    LaunchTable,
    MeasurementNoise,
    SynthConfig,
    draw_launches,
    draw_sessions,
    measure,
)
from pydantic import ValidationError

NOMINAL_AIR = Air.standard()
"""The air of the base sessions and the air the model is told: 15 degC, sea level, dry (1.225 kg/m^3)."""

NOMINAL_CONTEXT = Context(float(NOMINAL_AIR.density_kg_m3), 15.0)

OUTSIDE_EFFECT = "critical_reynolds"
"""The effect outside the library that `prove` hides: the ball's drag crisis sits at another Reynolds number
(a different ball or dimple pattern), which changes drag and lift mostly at low speed, unlike any library effect."""

LAUNCH_BIASES = {
    "launch_angle_bias": ("launch_angle_deg", "offset_deg", True),
    "launch_direction_bias": ("launch_direction_deg", "offset_deg", True),
    "spin_axis_bias": ("spin_axis_deg", "offset_deg", True),
    "ball_speed_bias": ("ball_speed_mps", "scale", False),
    "spin_bias": ("spin_rpm", "scale", False),
}
KNOBS = {"drag_scale": "drag_scale", "lift_scale": "lift_scale", "spin_decay": "spin_decay_scale"}


@dataclass
class Concealed:
    """Recordings with hidden effects, and the truth: {effect: {parameter: value}}."""

    shots: ShotSet
    hidden: dict[str, dict[str, float]]
    dropped: int
    trajectories: dict[str, np.ndarray]
    wind_factor: float = 1.0
    """Mean over the recorded flights of the hidden wind's speed along each flight over its stated speed: 1 for a
    uniform wind; for a log profile (stated at 10 m) the factor that turns it into its uniform equivalent."""


def conceal(
    hidden: dict[str, dict[str, float]],
    n_shots: int,
    seed: int,
    noise: MeasurementNoise = RADAR_NOISE,
    trajectories: bool = False,
    wind_profile: Literal["uniform", "log"] = "uniform",
    model: FlightModel | None = None,
) -> Concealed:
    """Draw sessions, fly them with the hidden effects through the reference world (or `model`) and record them
    with noise.

    hidden uses the report's parameter conventions, e.g. {"wind": {"speed_mps": 4, "from_deg": 0}}, plus
    {"critical_reynolds": {"value": 9e4}} for the reference world's effect outside the library, or one of
    `discovery.outside.OUTSIDE` for a model's (the gust, `height_gust`, is air motion: either world takes it).
    """
    rng = np.random.default_rng(seed)
    config = SynthConfig(n_shots=n_shots, seed=seed, calm=True)
    sessions = draw_sessions(rng, n_shots, config)
    true = draw_launches(rng, sessions)
    recorded = LaunchTable(**{k: getattr(true, k).copy() for k in true.__dataclass_fields__})
    for name, (column, key, offset) in LAUNCH_BIASES.items():
        if name in hidden:
            value = hidden[name][key]
            setattr(recorded, column, getattr(true, column) - value if offset else getattr(true, column) / value)
    air, wind, ground = NOMINAL_AIR, Wind(), 0.0
    if "air_density" in hidden:
        altitude = equivalent_altitude_m(hidden["air_density"]["ratio"], NOMINAL_CONTEXT)
        air = Air.from_conditions(15.0, altitude, 0.0)
    if DENSITY_ONLY in hidden:
        ratio = hidden[DENSITY_ONLY]["ratio"]
        air = Air(NOMINAL_AIR.density_kg_m3 * ratio, NOMINAL_AIR.kinematic_viscosity_m2_s)
    if "wind" in hidden:
        wind = Wind(hidden["wind"]["speed_mps"], hidden["wind"]["from_deg"], profile=wind_profile)
    if "landing_elevation" in hidden:
        ground = hidden["landing_elevation"]["height_m"]
    params = CALIBRATED
    for name, knob in KNOBS.items():
        if name in hidden:
            params = replace(params, **{knob: hidden[name]["scale"]})
    if OUTSIDE_EFFECT in hidden:
        params = replace(params, critical_reynolds=hidden[OUTSIDE_EFFECT]["value"])
    keep = trajectories or wind_profile == "log"
    if model is None:
        wind = air_motion(hidden, wind)
        flight = fly_reference(initial_state(**true.launch()), air, wind, ground, keep_states=keep, params=params)
    else:
        flight = _fly_model(model, hidden, true, wind_profile, trajectories)
    values = measure(rng, recorded, flight, noise)
    records, dropped, paths, kept = [], 0, {}, []
    order = np.zeros(len(sessions), dtype=int)
    for i in range(len(true.club)):
        session = true.session_index[i]
        if not flight.landed[i] or flight.apex_m[i] < MIN_APEX_M:
            dropped += 1
            continue
        try:
            records.append(
                ShotRecord(
                    shot_id=f"{sessions[session].session}-{order[session]:04d}",
                    session=sessions[session].session,
                    club=true.club[i],
                    **{k: float(v[i]) for k, v in values.items()},
                )
            )
        except ValidationError:
            dropped += 1
            continue
        if trajectories:
            paths[records[-1].shot_id] = _path(flight, i, rng)
        kept.append(i)
        order[session] += 1
    factor = _mean_wind_factor(flight, wind, np.array(kept, dtype=int)) if wind.profile == "log" else 1.0
    return Concealed(ShotSet(records), hidden, dropped, paths, factor)


def _fly_model(
    model: FlightModel,
    hidden: dict[str, dict[str, float]],
    true: LaunchTable,
    wind_profile: str,
    trajectories: bool,
) -> Flight:
    """The true launches flown through the model with the hidden effects, in its flight core."""
    unknown = (
        set(hidden) - set(KNOBS) - set(LAUNCH_BIASES) - set(OUTSIDE) - {*AIR_VARIANTS, "wind", "landing_elevation"}
    )
    if unknown or wind_profile != "uniform":
        raise InputError(f"a model's own flights take library effects, uniform wind and discovery.outside: {unknown}")
    n = len(true.club)
    scale = np.ones((n, 3))
    for column, name in enumerate(("lift_scale", "drag_scale", "spin_decay")):
        if name in hidden:
            scale[:, column] = hidden[name]["scale"]
    wind = np.zeros((n, 2))
    if "wind" in hidden:
        wind[:] = wind_vector(hidden["wind"]["speed_mps"], hidden["wind"]["from_deg"])[:2]
    real, only = (hidden.get(name, {"ratio": 1.0})["ratio"] for name in AIR_VARIANTS)
    ratio = np.full(n, real * only)
    density = np.full(n, model.density_kg_m3)
    term, weights = term_and_weights(hidden, density * ratio)
    ground = np.full(n, hidden.get("landing_elevation", {"height_m": 0.0})["height_m"])
    setup = Setup(true.launch(), ratio, density, wind, ground, scale, weights, viscosity_ratio=np.full(n, 1.0 / real))
    air = air_motion(hidden, Wind.from_components(wind[:, 0], wind[:, 1]))
    return model.fly(setup, term, keep_states=trajectories, air=air)


def _mean_wind_factor(flight: Flight, wind: Wind, shots: np.ndarray) -> float:
    """The hidden log profile's uniform-equivalent factor along the recorded shots' flights."""
    heights = np.stack([state.position[shots, 2] for state in flight.states])
    heights[flight.times_s[:, None] > flight.flight_time_s[shots][None, :]] = np.nan
    return uniform_equivalent_factor(heights, wind.reference_height_m, wind.roughness_m)


def _path(flight: Flight, shot: int, rng: np.random.Generator, every: int = 10, noise_m: float = 0.1) -> np.ndarray:
    """Samples (t, x, y, z) of one reference flight every `every` steps up to its landing, with radar noise."""
    times = flight.times_s[::every]
    xyz = np.stack([s.position[shot] for s in flight.states[::every]])
    inside = times <= flight.flight_time_s[shot]
    samples = np.column_stack([times[inside], xyz[inside] + rng.normal(0, noise_m, xyz[inside].shape)])
    return samples
