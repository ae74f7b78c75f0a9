"""What the routes share, and the dependencies that hand it to them: the service state on `app.state` and its
engine once loaded (`NotReady`, a 503, before that)."""

from __future__ import annotations

import gc
import threading
import time
from importlib.metadata import version
from pathlib import Path
from typing import Literal

from fastapi import Depends, Request
from golfflight.contract.gspro import GSProMessage, GSProReply, fly_message
from golfflight.flight.engine import FlightEngine
from golfflight.service.api.batch_process import BatchProcess
from golfflight.service.api.bay import Bay
from golfflight.service.api.latency import Rolling
from golfflight.service.api.metrics import ServiceMetrics
from golfflight.service.viewer.event import Source
from golfflight.service.viewer.feed import ShotFeed


class NotReady(Exception):
    """A simulation route was called before the model was loaded."""


class ServiceState:
    """The engine once loaded (or why it failed), the batch process, the rolling latency figures, the Prometheus
    metrics, the shots the viewer shows and the bay's conditions."""

    def __init__(self, bundle_dir: Path, bay: Bay | None = None):
        self.bundle_dir = bundle_dir
        self.bay = bay or Bay()
        self.engine: FlightEngine | None = None
        self.error: str | None = None
        self.simulation = Rolling()
        self.requests = Rolling()
        self.loaded = threading.Event()
        self.batches = BatchProcess(bundle_dir)
        self.feed = ShotFeed()
        self.metrics = ServiceMetrics(self.model_labels)
        self._simulation_seconds = {kind: self.metrics.simulation_seconds.labels(kind) for kind in ("shot", "batch")}

    def model_labels(self) -> dict[str, str] | None:
        """The loaded model's variant and ONNX SHA-256 and the package version (/metrics' info labels)."""
        if self.engine is None:
            return None
        return {"variant": self.engine.variant, "sha256": self.engine.sha256, "version": version("golfflight")}

    def record_simulation(self, kind: Literal["shot", "batch"], seconds: float) -> None:
        """One simulation's engine time, into /v1/latency's window and /metrics' histogram (its two label sets
        bound once, at start-up, not looked up per shot)."""
        self.simulation.add(seconds)
        self._simulation_seconds[kind].observe(seconds)

    def ready_engine(self) -> FlightEngine:
        """The loaded engine; NotReady (503) while the model loads or after it failed to."""
        if self.engine is None:
            raise NotReady(self.error or "the model is still loading")
        return self.engine

    def load(self) -> None:
        """Load the model here and in the batch process; either failing leaves the service up to say why."""
        try:
            engine = FlightEngine(self.bundle_dir)
            if self.batches.start() != engine.sha256:
                raise RuntimeError("the batch process loaded a different model (the bundle changed during startup)")
            self.engine = engine
            gc.freeze()  # the app and the model are here for good: keep them out of every later collection's scan
        except Exception as error:  # noqa: BLE001 - reported by /healthz, the service stays up to say so
            self.error = f"{type(error).__name__}: {error}"
        finally:
            self.loaded.set()

    def gspro_reply(self, message: GSProMessage, source: Source = "gspro-http") -> GSProReply:
        """A GSPro shot's reply over HTTP and TCP alike, flown in the bay's conditions (timed into /v1/latency, shown
        by the viewer as coming from `source`); Code 503 until the model is ready."""
        if self.engine is None:
            return GSProReply(Code=503, Message=self.error or "the model is still loading")
        started = time.perf_counter()
        try:
            reply = fly_message(self.engine, message, self.bay.conditions)
        finally:
            self.record_simulation("shot", time.perf_counter() - started)
        self.feed.publish_gspro(source, message, reply)
        return reply


async def service_state(request: Request) -> ServiceState:
    """The app's `ServiceState` (set by `create_app`). `async def`, as every dependency here: FastAPI would run a
    plain `def` in its thread pool, a hop that costs more than a single shot's simulation."""
    return request.app.state.service


def state_of(request: Request) -> ServiceState:
    """The app's `ServiceState`, for the simulation routes: a plain attribute read where a dependency costs FastAPI a
    dependency graph to solve on every request (about a tenth of a single shot's time over HTTP)."""
    return request.app.state.service


async def ready_engine(state: ServiceState = Depends(service_state)) -> FlightEngine:
    """The loaded engine; NotReady (503) while the model loads or after it failed to."""
    return state.ready_engine()
