"""What the batch child process of each server process runs (`service.runtime.batch_process` starts and feeds it):
load the bundle at a lower CPU priority, then read, validate and fly each raw batch request body it is sent and
encode its result, or its refusal (off the server's event loop: issue 55); end as soon as its server has gone. It
imports the shot contract and the engine only, never the HTTP package."""

from __future__ import annotations

import os
import signal
import time
from typing import NamedTuple

from golfflight.contract.batch_body import read_batch
from golfflight.contract.bay import BayConditions, flown_in_all
from golfflight.contract.flying import fly_requests
from golfflight.contract.refusals import RequestRefused
from golfflight.contract.requests import ShotRequest
from golfflight.contract.results import BatchResult, ShotResult
from golfflight.flight.engine import EulerStates, FlightEngine
from golfflight.service.runtime.parent_watch import exit_with_parent

BATCH_NICE = 19
"""How much lower the batch process's CPU priority is (Linux nice increment): a single shot waiting for a core
gets it first, a batch still gets the cores nobody else wants."""

ENCODED_AT_ONCE = 500
"""Results encoded together in a batch's answer (`encode_results`): small enough that a slice's objects cost little
beside the text, large enough that the slices cost nothing in time."""

Shown = dict[int, tuple[ShotRequest, ShotResult, EulerStates, float]]
"""The shots of a batch its screens show, by index: the shot as flown (the bay's conditions filled in), its result,
the states it was read from, and its landing time."""


class FlownBatch(NamedTuple):
    """A batch flown: the JSON response body, the seconds its simulation took, its number of shots, and the shots
    its screens show (`Shown`)."""

    body: bytes
    seconds: float
    shots: int
    shown: Shown

_engine: FlightEngine | None = None


def start(bundle_dir: str) -> None:
    """Child initializer: end with the server, lower the priority, ignore the terminal's Ctrl-C and SIGTERM (the
    parent decides when the child stops, after its in-flight batch), load the bundle."""
    global _engine
    exit_with_parent()
    os.nice(BATCH_NICE)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    _engine = FlightEngine(bundle_dir)


def ready() -> tuple[str, int]:
    """The loaded model's ONNX hash and this process's id: the parent checks the child serves the same model it
    does, and watches the process."""
    assert _engine is not None
    return _engine.sha256, os.getpid()


def _for_screens(result: ShotResult) -> ShotResult:
    """A shown shot's result as the screens keep it (`feed.ShotFeed.publish`): no trajectory or normalized flight,
    which would cross to the server for nothing (50 shown shots with trajectories: 150,000 points, 125 MiB of the server's peak)."""
    return result.model_copy(update={"trajectory": None, "normalized": None})


def fly_and_encode(body: bytes, shown: int = 0, bay: BayConditions | None = None) -> FlownBatch | RequestRefused:
    """A raw batch request body flown (`FlownBatch`), the `bay`'s conditions filled in where a shot gives none and
    each result saying what it flew in (`contract.bay.flown_in_all`), the last `shown` shots kept with their
    states; or its refusal, the 422 details the HTTP app would give (`read_batch`, `contract.trajectory_size`),
    returned rather than raised so that it crosses back to the server whole."""
    assert _engine is not None
    try:
        bay = bay or BayConditions()
        shots, echoes = flown_in_all(read_batch(body).shots, bay)
        started = time.perf_counter()
        results, flights = fly_requests(_engine, shots, shown)
    except RequestRefused as refused:  # the body, or the trajectory points it asks for (`contract.trajectory_size`)
        return refused
    seconds = time.perf_counter() - started
    for result, echo in zip(results, echoes, strict=True):
        if isinstance(result, ShotResult):
            result.flown_in = echo
    kept = {i: (shots[i], _for_screens(results[i]), flight.states, flight.flight_time_s)
            for i, flight in flights.items()}
    return FlownBatch(encode_results(results), seconds, len(shots), kept)


def encode_results(results: list) -> bytes:
    """The BatchResult JSON of `results`, encoded ENCODED_AT_ONCE at a time, each slice's objects let go once
    encoded (its entries set to None): the answer's text grows as its objects go, where encoding all at once held both
    (about 90 MiB more for 10,000 shots with 300,000 trajectory points)."""
    pieces = []
    for start in range(0, len(results), ENCODED_AT_ONCE):
        piece = BatchResult.model_construct(results=results[start : start + ENCODED_AT_ONCE])
        pieces.append(piece.__pydantic_serializer__.to_json(piece, exclude_none=True)[len(b'{"results":[') : -2])
        results[start : start + ENCODED_AT_ONCE] = [None] * len(piece.results)
        del piece
    return b'{"results":[' + b",".join(pieces) + b"]}"
