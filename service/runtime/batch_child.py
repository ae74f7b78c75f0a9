"""What the batch child process of each server process runs (`service.runtime.batch_process` starts and feeds it):
load the bundle at a lower CPU priority, then fly each validated batch request body it is sent and encode its
result; end as soon as its server has gone. It imports the shot contract and the engine only, never the HTTP
package."""

from __future__ import annotations

import json
import os
import signal
import time

from golfflight.contract.flying import fly_requests
from golfflight.contract.requests import BatchRequest
from golfflight.contract.results import BatchResult, ShotResult
from golfflight.flight.engine import EulerStates, FlightEngine
from golfflight.service.runtime.parent_watch import exit_with_parent

BATCH_NICE = 19
"""How much lower the batch process's CPU priority is (Linux nice increment): a single shot waiting for a core
gets it first, a batch still gets the cores nobody else wants."""

Shown = dict[int, tuple[ShotResult, EulerStates, float]]
"""The shots of a batch its screens show, by index: result, the states it was read from, and its landing time."""

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


def parse_batch(body: bytes) -> BatchRequest:
    """A batch body as the HTTP app read it: pydantic's own JSON reader first, then Python's, which also takes a
    UTF-8 byte order mark, UTF-16 and UTF-32 as the app's does: the child accepts exactly what the app accepted."""
    try:
        return BatchRequest.model_validate_json(body)
    except ValueError:
        return BatchRequest.model_validate(json.loads(body))


def fly_and_encode(body: bytes, shown: int = 0) -> tuple[bytes, float, Shown]:
    """The JSON response body for a valid batch request body, the seconds its simulation took, and the last
    `shown` shots that flew with the states they were read from (for the bay's screens)."""
    assert _engine is not None
    shots = parse_batch(body).shots
    started = time.perf_counter()
    results, flights = fly_requests(_engine, shots, shown)
    seconds = time.perf_counter() - started
    kept = {i: (results[i], flight.states, flight.flight_time_s) for i, flight in flights.items()}
    return BatchResult(results=results).model_dump_json(exclude_none=True).encode(), seconds, kept
