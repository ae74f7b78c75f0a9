"""Plain functions between the contract and the engine: requests in, results out (shared by HTTP, GSPro, the
viewer, the command line and sweep)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from golfflight.contract.columns import AIR_DENSITY
from golfflight.contract.figures import flat_numbers, flight_numbers
from golfflight.contract.inputs import air_of, conditions_of, ground_of, lands_off_the_flat, launch_of, reference_of
from golfflight.contract.requests import ShotRequest, TrajectoryRequest
from golfflight.contract.results import (
    POINT_MODELS,
    FlatFlight,
    NormalizedFlight,
    ShotFailure,
    ShotResult,
    TrajectoryPoint,
)
from golfflight.contract.trajectory import resample
from golfflight.contract.trajectory_size import refuse_long_trajectories
from golfflight.errors import FlightError
from golfflight.flight.conditions import Conditions
from golfflight.flight.engine import BatchFlights, FlightEngine, ShotFlight
from golfflight.flight.ground import GroundSpec
from golfflight.flight.per_shot import PerShot
from golfflight.flight.problem import LAUNCH_WIDTH, FlightProblem
from golfflight.flight.wind import CALM


def _trajectory(flight: ShotFlight, request: TrajectoryRequest) -> list[TrajectoryPoint]:
    if request.rate_hz is None:
        times, positions = flight.states.times_s, flight.states.positions
    else:
        times, positions = resample(flight.states, request.rate_hz)
    return [
        TrajectoryPoint.model_construct(t_s=t, x_m=x, y_m=y, z_m=z)
        for t, (x, y, z) in zip(times.tolist(), positions.tolist(), strict=True)
    ]


_POINT_NUMBERS = tuple(
    (name, point, tuple((key, f"{name}_{key}") for key in point.model_fields)) for name, point in POINT_MODELS.items()
)
"""Each point of a result, its model, and its coordinates' names in the model and among a flight's numbers
(x_m, landing_x_m), ..."""


def _points(numbers: dict) -> dict:
    """A flight's numbers with each point's (NAME_x_m, NAME_y_m, NAME_x_yd, NAME_y_yd) as the result's point."""
    fields = dict(numbers)
    for name, point, named in _POINT_NUMBERS:
        if named[0][1] in fields:
            fields[name] = point.model_construct(**{key: fields.pop(number) for key, number in named})
    return fields


def flight_fields(flight: ShotFlight, trajectory: TrajectoryRequest | None) -> dict:
    """The FlightResult fields of an engine flight rolled to rest (yards alongside metres)."""
    path = None if trajectory is None else _trajectory(flight, trajectory)
    return {**_points(flight_numbers(flight)), "trajectory": path}


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


def fly_request(
    engine: FlightEngine, shot: ShotRequest, *, keep_states: bool = False, putt: bool = False, flat: bool = True
) -> tuple[ShotResult, ShotFlight]:
    """One request on the engine's single-shot path (`FlightEngine.fly` of its one problem, `batch_of`: the shot, its
    normalized replay, its flat flight): its result and the flight it was read from (its states through the ground
    phase to rest when `keep_states`, for a renderer: the numbers and the picture of one flight). A `putt` rolls on
    the shot's ground from the start (`FlightEngine.putt`: no flight, so no normalized or flat flight); `flat` False
    leaves the flat flight out (a GSPro reply has no field for it). FlightError if it cannot land."""
    if putt:
        flight = engine.putt(launch_of(shot), ground_of(shot.ground), keep_states or shot.trajectory is not None)
        return result_of(shot, flight), flight
    batch = batch_of([shot], keep_states, flat)
    flight, normalized, flat_flight = batch.read(engine.fly(batch.problem))[0]
    if shot.trajectory is not None:
        refuse_long_trajectories([(shot.trajectory, own.states) for own in (flight, normalized) if own is not None])
    return result_of(shot, flight, normalized, flat_flight), flight


@dataclass(frozen=True)
class Batch:
    """One engine problem for `n` shots: their own flights, then their normalized replays' and their flat flights'
    appended; `replays` and `flats` say which shots those are, in the order appended. Made from requests
    (`batch_of`) or from a sweep's columns (`sweep.rows`), each through `of`; its flights go back by `read` (each
    shot's own, replay and flat flight) or into columns (`columns_of`)."""

    problem: FlightProblem
    n: int
    replays: np.ndarray
    flats: np.ndarray

    @classmethod
    def of(
        cls,
        launches: np.ndarray,
        conditions: PerShot[Conditions],
        grounds: PerShot[GroundSpec | None],
        replays: PerShot[Conditions | None],
        flats: np.ndarray,
        keep: np.ndarray | bool = False,
    ) -> Batch:
        """The batch of n shots' launches [n, LAUNCH_WIDTH], conditions and grounds: each shot whose `replays` entry
        is a reference's conditions replayed in them on its ground, each of `flats` flown alone to z = 0; `keep`
        (one flag, or [own flags n, replay flags]) says whose states are kept, never a flat flight's."""
        n = len(launches)
        replayed = np.flatnonzero(replays.column(lambda c: c is not None, bool))
        flats = np.asarray(flats, dtype=np.intp)
        if not len(replayed) and not len(flats):  # their own flights alone (most requests): nothing to append
            return cls(FlightProblem.of(launches, conditions, grounds, keep), n, replayed, flats)
        keep = np.broadcast_to(np.asarray(keep, dtype=bool), (n + len(replayed),))
        problem = FlightProblem.of(
            launches[np.concatenate([np.arange(n), replayed, flats])],
            conditions.plus(replays.take(replayed), conditions.take(flats)),
            grounds.plus(grounds.take(replayed), PerShot([None], np.zeros(len(flats), dtype=np.intp))),
            np.concatenate([keep, np.zeros(len(flats), dtype=bool)]),
        )
        return cls(problem, n, replayed, flats)

    def read(self, flights: list) -> list[tuple]:
        """Each shot's (own, normalized replay or None, flat or None) of the problem's flights, in order (a flight is
        a ShotFlight, or a FlightError from a batch)."""
        n, replays = self.n, len(self.replays)
        replayed = dict(zip(self.replays.tolist(), flights[n : n + replays], strict=True))
        flat = dict(zip(self.flats.tolist(), flights[n + replays :], strict=True))
        return [(flights[i], replayed.get(i), flat.get(i)) for i in range(n)]


_NONE = np.zeros(0, dtype=np.intp)
"""No shots: a batch's replays or flats where it has none."""


def batch_of(shots: list[ShotRequest], keep: bool = False, flat: bool = True) -> Batch:
    """The engine batch of `shots` (`Batch`), each request read once: its own states kept where `keep` or it asks
    for a trajectory, its replay's where it asks for one; flat flights of shots off the flat unless `flat` is False."""
    n = len(shots)
    launches = [launch_of(shot) for shot in shots]
    conditions = PerShot.each([conditions_of(shot) for shot in shots])
    grounds = PerShot.each([ground_of(shot.ground) for shot in shots])
    references = [reference_of(shot) for shot in shots]
    flats = [i for i, shot in enumerate(shots) if flat and lands_off_the_flat(shot)]
    traced = [shot.trajectory is not None for shot in shots]
    keep_rows = [keep or t for t in traced] + [t for t, r in zip(traced, references, strict=True) if r is not None]
    if not flats and len(keep_rows) == n:  # their own flights alone (most requests): the problem as it is
        return Batch(FlightProblem.of(launches, conditions, grounds, np.array(keep_rows, bool)), n, _NONE, _NONE)
    replays = PerShot.each([None if r is None else Conditions(air_of(r), CALM) for r in references])
    launches = np.array(launches, dtype=float).reshape(n, LAUNCH_WIDTH)
    return Batch.of(launches, conditions, grounds, replays, np.array(flats, dtype=np.intp), np.array(keep_rows, bool))


def _fly_group(
    engine: FlightEngine, shots: list[ShotRequest], keep: bool
) -> tuple[list[ShotResult | ShotFailure], list[ShotFlight | FlightError]]:
    """One engine batch for `shots`, their normalized replays and their flat flights; results in order, and each
    shot's own flight."""
    batch = batch_of(shots, keep)
    flights = batch.read(engine.fly_batch(batch.problem).shots())
    refuse_long_trajectories([
        (shot.trajectory, own.states) for shot, shot_flights in zip(shots, flights, strict=True)
        if shot.trajectory is not None for own in shot_flights[:2] if isinstance(own, ShotFlight)
    ])
    results: list[ShotResult | ShotFailure] = []
    for shot, own in zip(shots, flights, strict=True):
        failure = next((f for f in own if isinstance(f, FlightError)), None)
        results.append(ShotFailure(error=str(failure)) if failure else result_of(shot, *own))
    return results, [own[0] for own in flights]


@dataclass(frozen=True)
class ShotColumns:
    """A batch's results as columns over the shots (`columns_of`), named as `contract.columns.flat_row` names them:
    `values` holds an array for each flight, normalized_* and flat_* column, valid where `present` is True (the shot
    flew and, for normalized_* and flat_*, asked for that flight), and the air density each shot was flown in
    (`AIR_DENSITY`, valid for every shot); `errors` the error column (None where the shot flew)."""

    values: dict[str, np.ndarray]
    present: dict[str, np.ndarray]
    errors: list[str | None]


def columns_of(flights: BatchFlights, batch: Batch) -> ShotColumns:
    """The columns of a batch's flights (`ShotColumns`): a shot fails with the first error of its own flight, its
    replay, its flat flight."""
    n, replays, flats = batch.n, batch.replays, batch.flats
    replay_rows = np.arange(n, n + len(replays))
    flat_rows = np.arange(n + len(replays), n + len(replays) + len(flats))
    owner = np.concatenate([np.arange(n), replays, flats]).tolist()
    errors: list[str | None] = [None] * n
    for row in sorted(flights.errors):  # a shot's own row comes before its replay's, which comes before its flat's
        if errors[owner[row]] is None:
            errors[owner[row]] = flights.errors[row]
    flew = np.ones(n, dtype=bool)
    flew[[owner[row] for row in flights.errors]] = False
    values, present = {}, {}
    for prefix, numbers, rows, own in (
        ("", flight_numbers, np.arange(n), np.arange(n)),
        ("normalized_", flight_numbers, replay_rows, replays),
        ("flat_", flat_numbers, flat_rows, flats),
    ):
        mask = np.zeros(n, dtype=bool)
        mask[own] = True
        mask &= flew
        taken = flights if len(rows) == len(owner) else flights.take(rows)  # the whole batch: its own shots alone
        for name, column in numbers(taken).items():
            full = np.zeros(n, dtype=column.dtype)
            full[own] = column
            values[prefix + name], present[prefix + name] = full, mask
    conditions = batch.problem.air.take(np.arange(n))
    values[AIR_DENSITY], present[AIR_DENSITY] = conditions.column(lambda c: c.air.density_kg_m3), np.ones(n, bool)
    return ShotColumns(values, present, errors)


def fly_requests(
    engine: FlightEngine, shots: list[ShotRequest], shown: int = 0
) -> tuple[list[ShotResult | ShotFailure], dict[int, ShotFlight]]:
    """Many requests in engine batches (normalized replays and flat flights ride along): their results in order, and
    the flights of the last `shown` shots that flew, their states kept through the ground phase (for a renderer), by
    index. Shots asking for a trajectory or shown fly in a batch of their own, so the rest do not keep every
    integrator state."""
    first_shown = len(shots) - min(shown, len(shots))
    traced = [i for i, shot in enumerate(shots) if shot.trajectory is not None or i >= first_shown]
    plain = [i for i, shot in enumerate(shots) if shot.trajectory is None and i < first_shown]
    results: list[ShotResult | ShotFailure | None] = [None] * len(shots)
    kept: dict[int, ShotFlight] = {}
    for indices, keep in ((plain, False), (traced, True)):
        if not indices:
            continue
        group, flights = _fly_group(engine, [shots[i] for i in indices], keep)
        for i, result, flight in zip(indices, group, flights, strict=True):
            results[i] = result
            if i >= first_shown and not isinstance(flight, FlightError):
                kept[i] = flight
    return results, kept
