"""What the batch child process of each server process runs (`service.api.batch_process` starts and feeds it): load
the bundle at a lower CPU priority, then fly each validated batch request body it is sent and encode its result.
It imports the shot contract and the engine only, never the HTTP package."""

from __future__ import annotations

import os
import signal
import time

from golfflight.contract.flying import fly_shots
from golfflight.contract.requests import BatchRequest
from golfflight.contract.results import BatchResult
from golfflight.flight.engine import FlightEngine

BATCH_NICE = 19
"""How much lower the batch process's CPU priority is (Linux nice increment): a single shot waiting for a core
gets it first, a batch still gets the cores nobody else wants."""

_engine: FlightEngine | None = None


def start(bundle_dir: str) -> None:
    """Child initializer: lower the priority, ignore the terminal's Ctrl-C (the parent decides when the child
    stops, after its in-flight batch), load the bundle."""
    global _engine
    os.nice(BATCH_NICE)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    _engine = FlightEngine(bundle_dir)


def ready() -> str:
    """The loaded model's ONNX hash: the parent checks the child serves the same model it does."""
    assert _engine is not None
    return _engine.sha256


def fly_and_encode(body: bytes) -> tuple[bytes, float]:
    """The JSON response body for a valid batch request body, and the seconds its simulation took."""
    assert _engine is not None
    shots = BatchRequest.model_validate_json(body).shots
    started = time.perf_counter()
    results = fly_shots(_engine, shots)
    seconds = time.perf_counter() - started
    return BatchResult(results=results).model_dump_json(exclude_none=True).encode(), seconds
