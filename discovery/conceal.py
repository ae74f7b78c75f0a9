"""Recordings with a known effect hidden in them: synthetic sessions flown through the reference world, or through
the model being diagnosed (its own flights, as the service flies them, so clean sets are its own output plus noise).

The base sessions are the synthetic generator's (players and robots, several clubs, realistic launch scatter and
launch-monitor noise) but in calm air at ICAO standard conditions, the air the shipped model assumes, so the hidden
effect is the only thing that differs from what the model is told. Each library effect says how it is hidden
(`effects.Effect.hiding`): what the launch monitor records (launch biases: recorded = true - offset, or true / scale,
before the noise is added), the reference world with it and the model's own flights with it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from golfflight.discovery.effects import EFFECTS, NOMINAL_AIR, Effect, World
from golfflight.discovery.effects import NOMINAL_CONTEXT as NOMINAL_CONTEXT
from golfflight.discovery.model import FlightModel
from golfflight.discovery.noise import RADAR_NOISE
from golfflight.discovery.outside import OUTSIDE, air_motion, term_and_weights
from golfflight.discovery.simulator import Setup, setup_flight
from golfflight.errors import InputError
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import initial_state
from golfflight.flight.reference_aero import CALIBRATED
from golfflight.flight.wind import Wind, uniform_equivalent_factor
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

OUTSIDE_EFFECT = "critical_reynolds"
"""The effect outside the library that `prove` hides: the ball's drag crisis sits at another Reynolds number
(a different ball or dimple pattern), which changes drag and lift mostly at low speed, unlike any library effect."""


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
    launch_seed: int | None = None,
) -> Concealed:
    """Draw sessions, fly them with the hidden effects through the reference world (or `model`) and record them
    with noise.

    hidden uses the report's parameter conventions, e.g. {"wind": {"speed_mps": 4, "from_deg": 0}}, plus
    {"critical_reynolds": {"value": 9e4}} for the reference world's effect outside the library, or one of
    `discovery.outside.OUTSIDE` for a model's (the gust, `height_gust`, is air motion: either world takes it).
    With `launch_seed`, the sessions are `seed`'s and their launches and noise are drawn afresh from it.
    """
    rng = np.random.default_rng(seed)
    config = SynthConfig(n_shots=n_shots, seed=seed, calm=True)
    sessions = draw_sessions(rng, n_shots, config)
    if launch_seed is not None:  # the same players and clubs, other launches and noise (a baseline session)
        rng = np.random.default_rng([seed, launch_seed])
    true = draw_launches(rng, sessions)
    recorded = LaunchTable(**{k: getattr(true, k).copy() for k in true.__dataclass_fields__})
    library = _hideable(hidden)
    for effect in library:
        recorded = effect.hiding.recorded(hidden[effect.name], recorded)
    keep = trajectories or wind_profile == "log"
    if model is None:
        world = World(NOMINAL_AIR, Wind(), 0.0, CALIBRATED, wind_profile)
        for effect in library:
            world = effect.hiding.reference(hidden[effect.name], world)
        params = world.params
        if OUTSIDE_EFFECT in hidden:
            params = replace(params, critical_reynolds=hidden[OUTSIDE_EFFECT]["value"])
        wind = air_motion(hidden, world.wind)
        flight = fly_reference(
            initial_state(**true.launch()), world.air, wind, world.ground_m, keep_states=keep, params=params
        )
    else:
        wind = Wind()
        flight = _fly_model(model, hidden, library, true, wind_profile, trajectories)
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


def _hideable(hidden: dict[str, dict[str, float]]) -> list[Effect]:
    """The hidden effects that say how they are hidden (`Effect.hiding`), in the registry's order: the order they
    change the recorded launches and the worlds in (real air before density alone)."""
    return [effect for name, effect in EFFECTS.items() if name in hidden and effect.hiding is not None]


def _fly_model(
    model: FlightModel,
    hidden: dict[str, dict[str, float]],
    library: list[Effect],
    true: LaunchTable,
    wind_profile: str,
    trajectories: bool,
) -> Flight:
    """The true launches flown through the model with the hidden effects (`library` those of the library), in its
    flight core."""
    unknown = set(hidden) - {effect.name for effect in library} - set(OUTSIDE)
    if unknown or wind_profile != "uniform":
        raise InputError(f"a model's own flights take library effects, uniform wind and discovery.outside: {unknown}")
    n = len(true.club)
    setup = Setup(
        true.launch(), np.ones(n), np.full(n, model.flyer.density_kg_m3), np.zeros((n, 2)), np.zeros(n), np.ones((n, 3))
    )
    for effect in library:
        setup = effect.hiding.model(np.repeat(effect.internal(hidden[effect.name])[None], n, axis=0), setup)
    term, setup.correction_weights = term_and_weights(hidden, setup.density_kg_m3 * setup.density_ratio)
    air = air_motion(hidden, Wind.from_components(setup.wind_xy_mps[:, 0], setup.wind_xy_mps[:, 1]))
    return setup_flight(setup, model.flyer, term, trajectories, air)


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
