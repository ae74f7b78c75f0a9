"""The bay runtime: the one place a shot is flown in this bay. It owns the engine (loaded once, or why it failed),
the bay's conditions and player (`bay`), the batch process, the metrics and latency windows, and the shot feed the
screens draw. Its adapters (the HTTP routes `service.api`, GSPro Open Connect `service.open_connect`, the viewer
`service.viewer`) call it and import neither each other nor the HTTP app.

`fly` flies a request from a source in the bay's conditions and returns the result together with the flight it
was read from; a shot shown on the bay's screens is published with those very states (no second flight), so the
path drawn ends where the numbers say.
"""

from __future__ import annotations

import gc
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Literal

from golfflight.contract.bay import CONDITION_FIELDS, PUTTER, in_bay
from golfflight.contract.flying import flown_shot
from golfflight.contract.gspro import GSProMessage, GSProReply, failed_reply, shot_reply, shot_request
from golfflight.contract.requests import BatchRequest, ShotRequest
from golfflight.contract.results import ShotResult
from golfflight.errors import GolfflightError, ServiceError
from golfflight.flight.engine import FlightEngine, ShotFlight
from golfflight.service.runtime.batch_process import BatchProcess
from golfflight.service.runtime.bay import Bay
from golfflight.service.runtime.feed import Entry, ShotFeed, Source
from golfflight.service.runtime.latency import Rolling
from golfflight.service.runtime.metrics import ServiceMetrics

from golfflight import __version__

PLAYER_SOURCES = frozenset({"http", "gspro-http", "open-connect"})
"""Shots hit in this bay, tagged with the bay's player (batches are a studio's files, not the player's swings)."""

GSPRO_SOURCES = frozenset({"gspro-http", "open-connect"})
"""Shots from a launch monitor's connector: with the putter selected they are putts, as in GSPro."""

class NotReady(ServiceError):
    """A simulation was asked for before the model was loaded (HTTP: 503; Open Connect: Code 503)."""


@dataclass(frozen=True)
class Flown:
    """A shot flown in the bay: the request as flown (the bay's conditions filled in), the result answered, the
    flight it was read from (its states through the ground phase when the shot was shown) and its feed entry."""

    request: ShotRequest
    result: ShotResult
    flight: ShotFlight
    entry: Entry | None


class BayRuntime:
    """The engine once loaded (or why it failed), the batch process, the rolling latency figures, the Prometheus
    metrics, the shots the screens show and the bay's conditions."""

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
        self._reporters: dict[str, Callable[[], dict]] = {"batch_process": self.batches.health}

    def model_labels(self) -> dict[str, str] | None:
        """The loaded model's variant and ONNX SHA-256 and the package version (/metrics' info labels)."""
        if self.engine is None:
            return None
        return {"variant": self.engine.variant, "sha256": self.engine.sha256, "version": __version__}

    def record_simulation(self, kind: Literal["shot", "batch"], seconds: float) -> None:
        """One simulation's engine time, into /v1/latency's window and /metrics' histogram (its two label sets
        bound once, at start-up, not looked up per shot)."""
        self.simulation.add(seconds)
        self._simulation_seconds[kind].observe(seconds)

    def ready_engine(self) -> FlightEngine:
        """The loaded engine; NotReady while the model loads or after it failed to."""
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

    def stop(self) -> None:
        """Let the batch in flight finish, then end the batch process."""
        self.batches.stop()

    def problems(self) -> dict[str, str]:
        """What is degraded while shots still fly (GET /healthz): the bay file's problem, the batch process's (dead
        and restarting), if any."""
        problems = {"bay": self.bay.problem, "batch": self.batches.problem}
        return {name: problem for name, problem in problems.items() if problem}

    def add_reporter(self, name: str, report: Callable[[], dict]) -> None:
        """Have GET /healthz show `report()` under `name` (an adapter's own figures, e.g. Open Connect's connectors
        and refusals), without the runtime importing the adapter."""
        self._reporters[name] = report

    def reports(self) -> dict[str, dict]:
        """Each reporter's figures now, by name."""
        return {name: report() for name, report in self._reporters.items()}

    def fly(self, request: ShotRequest, source: Source, *, show: bool = True, shot_number: int | None = None,
            club_data: dict | None = None, flat: bool = True) -> Flown:
        """Fly `request` in the bay's conditions where it gives none of its own; with `show`, publish it to the
        screens with the states it was read from. A connector's shot with the putter selected is a putt. NotReady
        before the model is loaded; FlightError when it cannot land."""
        engine = self.ready_engine()
        bay = self.bay.conditions
        request = in_bay(request, bay)
        player = bay.player if source in PLAYER_SOURCES else None
        putt = source in GSPRO_SOURCES and bay.player.club == PUTTER
        started = time.perf_counter()
        try:
            result, flight = flown_shot(engine, request, keep_states=show, putt=putt, flat=flat)
        finally:
            self.record_simulation("shot", time.perf_counter() - started)
        entry = None
        if show:
            entry = self.feed.publish(source, request, result, flight.states, flight.flight_time_s,
                                      shot_number=shot_number, player=player, putt=putt,
                                      club_data=club_data)
        return Flown(request, result, flight, entry)

    def fly_gspro(self, message: GSProMessage, source: Source = "gspro-http") -> GSProReply:
        """A connector's shot (a message with BallData), over HTTP or TCP alike: Code 200 with its flight in the
        bay, shown on its screens; Code 500 saying why it cannot fly; Code 503 until the model is ready (the codes of
        `contract.refusals.FAILURES`)."""
        try:
            flown = self.fly(shot_request(message), source, shot_number=message.ShotNumber,
                             club_data=message.ClubData)
        except (ValueError, GolfflightError) as error:  # ValueError: pydantic's, for a message's values
            return failed_reply(message, error)
        return shot_reply(message, flown.result)

    async def fly_batch(self, request: BatchRequest, body: bytes, show: bool) -> bytes:
        """A validated batch's encoded BatchResult, flown in the batch process (the bay's conditions filled in
        where a shot gives none); with `show`, its last shots go to the screens with the states they came from.
        BatchProcessDied when the batch process died under it."""
        self.ready_engine()
        bay = self.bay.conditions
        if any(getattr(bay, name) is not None for name in CONDITION_FIELDS):
            request = BatchRequest.model_construct(shots=[in_bay(shot, bay) for shot in request.shots])
            body = request.model_dump_json(exclude_none=True).encode()
        shown = self.feed.history if show else 0
        encoded, seconds, kept = await self.batches.submit(body, shown)
        self.record_simulation("batch", seconds)
        self.metrics.batch_shots.observe(len(request.shots))
        for index, (result, states, flight_time_s) in sorted(kept.items()):
            self.feed.publish("batch", request.shots[index], result, states, flight_time_s)
        return encoded

