"""Plain functions between the contract and the engine: requests in, results out (shared by HTTP and the CLI)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from golfflight.flight.conditions import STANDARD, AirConditions, Conditions
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.flight.ground import LEVEL_FAIRWAY, GroundSpec, surface
from golfflight.flight.wind import CALM, Wind
from golfflight.contract.requests import (
    AirRequest,
    FlatFlight,
    GroundRequest,
    Landing,
    NormalizedFlight,
    ReferenceAir,
    RestPoint,
    ShotFailure,
    ShotRequest,
    ShotResult,
    TrajectoryPoint,
    TrajectoryRequest,
    WindRequest,
)
from golfflight.service.engine import FlightEngine, FlightError, Launch, ShotFlight
from golfflight.contract.trajectory import resample


def spin_from_components(back_spin_rpm: float, side_spin_rpm: float) -> tuple[float, float]:
    """(total spin rpm, spin axis deg) from back and side spin; + side spin tilts the axis right (a fade)."""
    return math.hypot(back_spin_rpm, side_spin_rpm), math.degrees(math.atan2(side_spin_rpm, back_spin_rpm))


def launch_of(shot: ShotRequest) -> Launch:
    """The SI launch of a request, whichever unit form it used."""
    speed = shot.ball_speed_mps if shot.ball_speed_mps is not None else shot.ball_speed_mph * MPH_TO_MPS
    if shot.spin_rpm is not None:
        spin, axis = shot.spin_rpm, shot.spin_axis_deg or 0.0
    else:
        spin, axis = spin_from_components(shot.back_spin_rpm, shot.side_spin_rpm or 0.0)
    return Launch(speed, shot.launch_angle_deg, shot.launch_direction_deg, spin, axis)


def air_of(air: AirRequest | ReferenceAir | None) -> AirConditions:
    """Engine air from a request's air; omitted values take ICAO standard air."""
    if air is None:
        return AirConditions()
    given = {name: value for name, value in air.model_dump().items() if value is not None}
    if "density_kg_m3" in given:
        return AirConditions(density=given["density_kg_m3"])
    return AirConditions(**given)


def wind_speed_mps(wind: WindRequest) -> float:
    """The SI wind speed of a request's (or a bay's) wind, whichever unit form it used."""
    return wind.speed_mps if wind.speed_mps is not None else wind.speed_mph * MPH_TO_MPS


def wind_of(wind: WindRequest | None) -> Wind:
    speed = 0.0 if wind is None else wind_speed_mps(wind)
    if speed == 0.0:
        return CALM
    return Wind(speed, wind.from_deg, wind.profile, wind.reference_height_m)


def conditions_from(air: AirRequest | None, wind: WindRequest | None) -> Conditions:
    """Engine conditions from a request's (or a bay's) air and wind; neither = standard air, calm."""
    if air is None and wind is None:
        return STANDARD
    return Conditions(air_of(air), wind_of(wind))


def conditions_of(shot: ShotRequest) -> Conditions:
    return conditions_from(shot.air, shot.wind)


def elevation_m(ground: GroundRequest | None) -> float:
    """The SI elevation of a request's (or a bay's) ground, whichever unit form it used; 0 (the tee's) if none."""
    if ground is None or (ground.elevation_m is None and ground.elevation_ft is None):
        return 0.0
    return ground.elevation_m if ground.elevation_m is not None else ground.elevation_ft * FOOT_M


def ground_of(ground: GroundRequest | None) -> GroundSpec:
    """The engine's ground from a request's; omitted = level fairway at the tee's elevation."""
    if ground is None:
        return LEVEL_FAIRWAY
    return GroundSpec(
        surface(ground.surface, ground.stimp_ft), elevation_m(ground), ground.slope_deg, ground.slope_dir_deg
    )


def reference_of(shot: ShotRequest) -> ReferenceAir | None:
    """The reference air of the normalized flight, or None when none was asked for."""
    if shot.normalized is False:
        return None
    return ReferenceAir() if shot.normalized is True else shot.normalized


def _trajectory(flight: ShotFlight, request: TrajectoryRequest) -> list[TrajectoryPoint]:
    if request.rate_hz is None:
        times, positions = flight.states.times_s, flight.states.positions
    else:
        times, positions = resample(flight.states, request.rate_hz)
    return [
        TrajectoryPoint.model_construct(t_s=t, x_m=x, y_m=y, z_m=z)
        for t, (x, y, z) in zip(times.tolist(), positions.tolist(), strict=True)
    ]


IMPERIAL_TWINS = (("_m", "_yd", YARD_M), ("_mps", "_mph", MPH_TO_MPS))
"""(SI suffix, imperial suffix, SI units per imperial unit): every result number named NAME_m (a length) gets
NAME_yd beside it, every NAME_mps (a speed) NAME_mph: the one place the results' imperial fields are defined."""


def with_imperial(numbers: dict) -> dict:
    """`numbers` with each SI length and speed followed by its imperial twin (`IMPERIAL_TWINS`): value / unit."""
    out = {}
    for name, value in numbers.items():
        out[name] = value
        for si, imperial, unit in IMPERIAL_TWINS:
            if name.endswith(si):
                out[name.removesuffix(si) + imperial] = value / unit
    return out


def flight_numbers(flight) -> dict:
    """The flat numbers of a flight rolled to rest under their column names (yards alongside metres, mph alongside
    m/s: `with_imperial`), from one ShotFlight (floats) or a batch's `BatchFlights` (arrays): the one definition of
    both forms."""
    rest = flight.rest
    return with_imperial({
        "landing_x_m": flight.landing_x_m,
        "landing_y_m": flight.landing_y_m,
        "carry_m": flight.carry_m,
        "lateral_m": flight.lateral_m,
        "apex_m": flight.apex_m,
        "apex_time_s": flight.apex_time_s,
        "flight_time_s": flight.flight_time_s,
        "landing_angle_deg": flight.landing_angle_deg,
        "landing_speed_mps": flight.landing_speed_mps,
        "landing_spin_rpm": flight.landing_spin_rpm,
        "total_m": rest.total_m,
        "roll_m": rest.roll_m,
        "rest_x_m": rest.x_m,
        "rest_y_m": rest.y_m,
        "bounces": rest.bounces,
    })


def flat_numbers(flight) -> dict:
    """The flat numbers of a flight flown down to z = 0, from a ShotFlight or a `BatchFlights` (`flight_numbers`)."""
    return with_imperial({
        "landing_x_m": flight.landing_x_m,
        "landing_y_m": flight.landing_y_m,
        "carry_m": flight.carry_m,
        "lateral_m": flight.lateral_m,
        "flight_time_s": flight.flight_time_s,
        "landing_angle_deg": flight.landing_angle_deg,
    })


POINTS = (("landing", Landing), ("rest", RestPoint))
"""Result fields that are points; their numbers are NAME_FIELD (landing_x_m, landing_x_yd, ...)."""


def _points(numbers: dict) -> dict:
    """A flight's numbers with NAME_x_m, NAME_y_m, NAME_x_yd and NAME_y_yd as the result's points."""
    fields = dict(numbers)
    for name, point in POINTS:
        if f"{name}_x_m" in fields:
            fields[name] = point.model_construct(**{key: fields.pop(f"{name}_{key}") for key in point.model_fields})
    return fields


def flight_fields(flight: ShotFlight, trajectory: TrajectoryRequest | None) -> dict:
    """The FlightResult fields of an engine flight rolled to rest (yards alongside metres)."""
    return {**_points(flight_numbers(flight)), "trajectory": None if trajectory is None else _trajectory(flight, trajectory)}


def lands_off_the_flat(shot: ShotRequest) -> bool:
    """Whether the shot's ground lies above or below the tee's, so that its flat flight is returned beside it."""
    return elevation_m(shot.ground) != 0.0


def flat_fields(flight: ShotFlight) -> FlatFlight:
    """The flat figures of a flight flown down to z = 0."""
    return FlatFlight.model_construct(**_points(flat_numbers(flight)))


def result_of(
    shot: ShotRequest, flight: ShotFlight, normalized: ShotFlight | None = None, flat: ShotFlight | None = None
) -> ShotResult:
    """The response for one shot from its flight and, if asked for, its normalized flight, and its flat flight when
    its ground is off the tee's elevation (built without re-validation: every value comes from the engine)."""
    extra = None
    if normalized is not None:
        fields = flight_fields(normalized, shot.trajectory)
        extra = NormalizedFlight.model_construct(**fields, conditions=reference_of(shot))
    flat_result = None if flat is None else flat_fields(flat)
    return ShotResult.model_construct(**flight_fields(flight, shot.trajectory), normalized=extra, flat=flat_result)


def fly_shot(engine: FlightEngine, shot: ShotRequest) -> ShotResult:
    """One shot (and its normalized replay) on the engine's single-shot path; FlightError if it cannot land."""
    launch, keep, ground = launch_of(shot), shot.trajectory is not None, ground_of(shot.ground)
    flight = engine.fly(launch, conditions_of(shot), keep, ground)
    reference = reference_of(shot)
    normalized = None
    if reference is not None:
        normalized = engine.fly(launch, Conditions(air_of(reference), CALM), keep, ground)
    flat = engine.fly(launch, conditions_of(shot)) if lands_off_the_flat(shot) else None
    return result_of(shot, flight, normalized, flat)


def _batch_of(shots: list[ShotRequest]) -> tuple[list[Launch], list[Conditions], list, list[int], list[int]]:
    """One engine batch for `shots`: their launches, conditions and grounds, then their normalized replays' and flat
    flights' appended, and which shots those are (in the order appended)."""
    launches = [launch_of(shot) for shot in shots]
    conditions = [conditions_of(shot) for shot in shots]
    grounds: list[GroundSpec | None] = [ground_of(shot.ground) for shot in shots]
    replays = [i for i, shot in enumerate(shots) if reference_of(shot) is not None]
    flats = [i for i, shot in enumerate(shots) if lands_off_the_flat(shot)]
    launches += [launches[i] for i in replays + flats]
    conditions += [Conditions(air_of(reference_of(shots[i])), CALM) for i in replays] + [conditions[i] for i in flats]
    grounds += [grounds[i] for i in replays] + [None] * len(flats)
    return launches, conditions, grounds, replays, flats


def _fly_group(engine: FlightEngine, shots: list[ShotRequest], keep: bool) -> list[ShotResult | ShotFailure]:
    """One engine batch for `shots`, their normalized replays and their flat flights; results in order."""
    launches, conditions, grounds, replays, flats = _batch_of(shots)
    flights = engine.fly_batch(launches, conditions, keep, grounds)
    replayed = dict(zip(replays, flights[len(shots) : len(shots) + len(replays)], strict=True))
    flat = dict(zip(flats, flights[len(shots) + len(replays) :], strict=True))
    results: list[ShotResult | ShotFailure] = []
    for i, shot in enumerate(shots):
        own = (flights[i], replayed.get(i), flat.get(i))
        failure = next((f for f in own if isinstance(f, FlightError)), None)
        results.append(ShotFailure(error=str(failure)) if failure else result_of(shot, *own))
    return results


@dataclass(frozen=True)
class ShotColumns:
    """`fly_shots`'s results as columns over the shots, named as `contract.columns.flat_row` names them: `values` holds
    an array for each flight, normalized_* and flat_* column, valid where `present` is True (the shot flew and, for
    normalized_* and flat_*, asked for that flight); `errors` the error column (None where the shot flew)."""

    values: dict[str, np.ndarray]
    present: dict[str, np.ndarray]
    errors: list[str | None]


def fly_columns(engine: FlightEngine, shots: list[ShotRequest]) -> ShotColumns:
    """`fly_shots` without a result object a shot (the same batch, numbers and errors, straight into columns):
    for many shots at once (`golfflight sweep`). No trajectories: a shot asking for one is refused."""
    if any(shot.trajectory is not None for shot in shots):
        raise ValueError("fly_columns flies no trajectories (fly_shots does)")
    n = len(shots)
    launches, conditions, grounds, replays, flats = _batch_of(shots)
    flights = engine.fly_columns(np.array(launches, dtype=float).reshape(-1, 5), conditions, grounds)
    replay_rows = np.arange(n, n + len(replays))
    flat_rows = np.arange(n + len(replays), n + len(replays) + len(flats))
    errors: list[str | None] = [None] * n
    for shot, rows in ((range(n), range(n)), (replays, replay_rows.tolist()), (flats, flat_rows.tolist())):
        for i, row in zip(shot, rows, strict=True):
            if errors[i] is None and row in flights.errors:
                errors[i] = flights.errors[row]
    flew = np.array([e is None for e in errors], dtype=bool)
    values, present = {}, {}
    for prefix, numbers, rows, own in (
        ("", flight_numbers, np.arange(n), np.arange(n)),
        ("normalized_", flight_numbers, replay_rows, np.array(replays, dtype=np.intp)),
        ("flat_", flat_numbers, flat_rows, np.array(flats, dtype=np.intp)),
    ):
        mask = np.zeros(n, dtype=bool)
        mask[own] = True
        mask &= flew
        for name, column in numbers(flights.take(rows)).items():
            full = np.zeros(n, dtype=column.dtype)
            full[own] = column
            values[prefix + name], present[prefix + name] = full, mask
    return ShotColumns(values, present, errors)


def fly_shots(engine: FlightEngine, shots: list[ShotRequest]) -> list[ShotResult | ShotFailure]:
    """Many shots in engine batches (normalized replays ride along); results in order. Shots asking for a
    trajectory fly in a batch of their own, so the rest do not keep every integrator state."""
    traced = [i for i, shot in enumerate(shots) if shot.trajectory is not None]
    if not traced or len(traced) == len(shots):
        return _fly_group(engine, shots, keep=bool(traced))
    plain = [i for i, shot in enumerate(shots) if shot.trajectory is None]
    results: list[ShotResult | ShotFailure | None] = [None] * len(shots)
    for indices, keep in ((plain, False), (traced, True)):
        for i, result in zip(indices, _fly_group(engine, [shots[i] for i in indices], keep), strict=True):
            results[i] = result
    return results
