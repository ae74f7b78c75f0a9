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
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from golfflight.contract.bay import CONDITION_FIELDS, BayConditions, Player, flown_in
from golfflight.contract.flying import fly_request
from golfflight.contract.gspro import GSProMessage, GSProReply, failed_reply, shot_reply, shot_request
from golfflight.contract.refusals import RequestRefused
from golfflight.contract.requests import ShotRequest
from golfflight.contract.results import ShotResult
from golfflight.contract.session import SessionList, SessionSummary
from golfflight.errors import GolfflightError, ServiceError
from golfflight.flight.engine import FlightEngine, ShotFlight
from golfflight.service.runtime.batch_process import BatchProcess
from golfflight.service.runtime.bay import Bay
from golfflight.service.runtime.feed import Entry, ShotFeed, Source, Viewer
from golfflight.service.runtime.latency import KINDS, Kind, Rolling
from golfflight.service.runtime.metrics import ServiceMetrics
from golfflight.service.runtime.sessions import Session
from golfflight.weights_schema.model_card import ModelCard

from golfflight import __version__

PROBE_SHOT = ShotRequest(ball_speed_mps=55.0, launch_angle_deg=16.0, spin_rpm=7100.0)
"""The shot /v1/latency times on demand: a tour-average 7-iron in standard air."""

GSPRO_SOURCES = frozenset({"gspro-http", "open-connect"})
"""Shots from the bay's launch monitor (its connector): hit with the bay's player's club, so with the putter selected
they are putts, as in GSPro. Any other shot is hit with the club it names, if any."""


def player_of(request: ShotRequest, source: Source, bay: BayConditions) -> Player | None:
    """Who hit a shot, as its session's club statistics count it: the bay's player for the bay's launch monitor;
    for any other shot the club it names (`ShotRequest.club`) with the bay player's hand, or no one."""
    if source in GSPRO_SOURCES:
        return bay.player
    if request.club is not None:
        return Player.model_construct(club=request.club, handed=bay.player.handed)
    return None


class NotReady(ServiceError):
    """A simulation was asked for before the model was loaded (HTTP: 503; Open Connect: Code 503)."""


def runtime_of(request) -> BayRuntime:
    """The bay runtime an app was assembled with (`app.state.runtime`, set by `service.app`): how every adapter's
    route reaches it, a plain attribute read (a FastAPI dependency would cost a dependency graph solved per request,
    about a tenth of a single shot's time over HTTP)."""
    return request.app.state.runtime


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
    metrics, the shots the screens show and the bay's conditions. A facade: its adapters and the assembly call its
    public methods and touch nothing else (`tests/test_runtime_facade.py`)."""

    def __init__(self, bundle_dir: Path, bay: Bay | None = None):
        self._bundle_dir = bundle_dir
        self._bay = bay or Bay()
        self._engine: FlightEngine | None = None
        self._error: str | None = None
        self._simulation = {kind: Rolling() for kind in KINDS}
        self._requests = {kind: Rolling() for kind in KINDS}
        self._batches = BatchProcess(bundle_dir)
        self._feed = ShotFeed()
        self._metrics = ServiceMetrics(self._model_labels)
        self._simulation_seconds = {kind: self._metrics.simulation_seconds.labels(kind) for kind in KINDS}
        self._reporters: dict[str, Callable[[], dict]] = {"batch_process": self._batches.health}

    def _model_labels(self) -> dict[str, str] | None:
        """The loaded model's variant and ONNX SHA-256 and the package version (/metrics' info labels)."""
        if self._engine is None:
            return None
        return {"variant": self._engine.variant, "sha256": self._engine.sha256, "version": __version__}

    def _record_simulation(self, kind: Kind, seconds: float) -> None:
        """One simulation's engine time, into /v1/latency's window of its kind and /metrics' histogram (its two
        label sets bound once, at start-up, not looked up per shot)."""
        self._simulation[kind].add(seconds)
        self._simulation_seconds[kind].observe(seconds)

    def _ready_engine(self) -> FlightEngine:
        """The loaded engine; NotReady while the model loads or after it failed to."""
        if self._engine is None:
            raise NotReady(self._error or "the model is still loading")
        return self._engine

    def load(self) -> None:
        """Load the model here and in the batch process; either failing leaves the service up to say why."""
        try:
            engine = FlightEngine(self._bundle_dir)
            if self._batches.start() != engine.sha256:
                raise RuntimeError("the batch process loaded a different model (the bundle changed during startup)")
            self._engine = engine
            gc.freeze()  # the app and the model are here for good: keep them out of every later collection's scan
        except Exception as error:  # noqa: BLE001 - reported by /healthz, the service stays up to say so
            self._error = f"{type(error).__name__}: {error}"

    def stop(self) -> None:
        """Let the batch in flight finish, then end the batch process."""
        self._batches.stop()

    def _problems(self) -> dict[str, str]:
        """What is degraded while shots still fly (GET /healthz): the bay file's problem, the batch process's (dead
        and restarting), if any."""
        problems = {"bay": self._bay.problem, "batch": self._batches.problem}
        return {name: problem for name, problem in problems.items() if problem}

    def add_reporter(self, name: str, report: Callable[[], dict]) -> None:
        """Have GET /healthz show `report()` under `name` (an adapter's own figures, e.g. Open Connect's connectors
        and refusals), without the runtime importing the adapter."""
        self._reporters[name] = report

    def _reports(self) -> dict[str, dict]:
        """Each reporter's figures now, by name."""
        return {name: report() for name, report in self._reporters.items()}

    def fly(self, request: ShotRequest, source: Source, *, show: bool = True, shot_number: int | None = None,
            club_data: dict | None = None, flat: bool = True, client: str = "") -> Flown:
        """Fly `request` in the bay's conditions where it gives none of its own, its result saying what it flew in
        (`contract.bay.flown_in`); with `show`, publish it to the screens with the states it was read from, in the
        session memory's share of `source` and address `client`. A connector's shot with the putter selected is a
        putt, unless no putt can leave as it did. NotReady before the model is loaded; FlightError when it cannot
        land."""
        engine = self._ready_engine()
        bay = self._bay.conditions
        request, echo = flown_in(request, bay, connector=source in GSPRO_SOURCES)
        started = time.perf_counter()
        try:
            result, flight = fly_request(engine, request, keep_states=show, putt=echo.putt, flat=flat)
        finally:
            self._record_simulation("shot", time.perf_counter() - started)
        result.flown_in = echo
        entry = None
        if show:
            entry = self._feed.publish(source, request, result, flight.states, flight.flight_time_s,
                                      client, shot_number=shot_number, player=player_of(request, source, bay),
                                      putt=echo.putt, club_data=club_data)
        return Flown(request, result, flight, entry)

    def fly_gspro(self, message: GSProMessage, source: Source = "gspro-http", client: str = "") -> GSProReply:
        """A connector's shot (a message with BallData) from address `client`, over HTTP or TCP alike: Code 200 with
        its flight in the bay, shown on its screens; Code 500 saying why it cannot fly; Code 503 until the model is
        ready (the codes of `contract.refusals.FAILURES`)."""
        try:
            flown = self.fly(shot_request(message), source, shot_number=message.ShotNumber,
                             club_data=message.ClubData, client=client)
        except (ValueError, GolfflightError) as error:  # ValueError: pydantic's, for a message's values
            return failed_reply(message, error)
        return shot_reply(message, flown.result)

    async def fly_batch(self, body: bytes, show: bool, client: str = "") -> bytes:
        """A raw batch request body's encoded BatchResult, read, validated and flown in the batch process (the bay's
        conditions filled in where a shot gives none, each result saying what it flew in); with `show`, its last
        shots go to the screens with the states they came from, each counted in the club it names, if any, in the
        session memory's share of address `client`. RequestRefused with its 422 details when the body is invalid or
        asks for too many trajectory points; BatchProcessDied when the batch process died under it."""
        self._ready_engine()
        bay = self._bay.conditions
        filled = bay if any(getattr(bay, name) is not None for name in CONDITION_FIELDS) else None
        answer = await self._batches.submit(body, self._feed.history if show else 0, filled)
        if isinstance(answer, RequestRefused):
            raise answer
        self._record_simulation("batch", answer.seconds)
        self._metrics.batch_shots.observe(answer.shots)
        for _, (shot, result, states, flight_time_s) in sorted(answer.shown.items()):
            self._feed.publish("batch", shot, result, states, flight_time_s, client,
                               player=player_of(shot, "batch", bay))
        return answer.body

    def latency(self) -> dict:
        """GET /v1/latency: the rolling p50/p95/p99 of single shots' simulation time and whole requests, those of
        batches apart (`batch`: one 10,000-shot batch takes seconds, and mixed in it read as every shot's p99), and
        PROBE_SHOT flown now on the served single-shot path (in standard air, shown nowhere, left out of the
        windows)."""
        engine = self._ready_engine()
        started = time.perf_counter()
        fly_request(engine, PROBE_SHOT)
        probe_ms = (time.perf_counter() - started) * 1e3
        return {
            "simulation": self._simulation["shot"].summary(),
            "request": self._requests["shot"].summary(),
            "batch": {"simulation": self._simulation["batch"].summary(), "request": self._requests["batch"].summary()},
            "probe": {"shot": PROBE_SHOT.model_dump(exclude_none=True), "simulation_ms": probe_ms},
        }

    def health(self) -> dict:
        """GET /healthz: "loading" or "failed" (with the error) until the model is loaded; then "ready", or
        "degraded" with `problems` saying what to repair while every shot still flies (a bay file broken while
        serving, a batch process restarting); the model's variant and hash and each reporter's figures."""
        if self._engine is None:
            return {"status": "failed" if self._error else "loading", "error": self._error}
        engine = self._engine
        model = {"variant": engine.variant, "sha256": engine.sha256, "load_seconds": engine.load_seconds}
        problems = self._problems()
        answer = {"status": "degraded" if problems else "ready", "model": model, "version": __version__,
                  **self._reports()}
        return {**answer, "problems": problems} if problems else answer

    def model(self) -> ModelCard:
        """The loaded bundle's model card; NotReady before it is loaded."""
        return self._ready_engine().card

    def metrics(self) -> bytes:
        """GET /metrics: every metric in Prometheus's text format (every worker's, several workers sharing)."""
        return self._metrics.exposition()

    def request_sinks(self) -> tuple[ServiceMetrics, dict[Kind, Rolling]]:
        """Where the HTTP adapter counts and times each request: the Prometheus metrics and /v1/latency's request
        windows, one a kind (`service.api.request_metrics`)."""
        return self._metrics, self._requests

    def bay(self) -> BayConditions:
        """The bay's conditions and player now."""
        return self._bay.conditions

    def bay_file(self) -> Path | None:
        """The bay file (None: the bay is in memory only)."""
        return self._bay.path

    def set_bay(self, conditions: BayConditions) -> BayConditions:
        """Replace the bay's conditions (kept in its file, if it has one); BayFileError when the file cannot be
        written."""
        return self._bay.set(conditions)

    def update_bay(self, change: Callable[[BayConditions], BayConditions]) -> BayConditions:
        """Change the bay's conditions by `change` (a PATCH), as one step against concurrent changes."""
        return self._bay.update(change)

    def on_player_change(self, listener: Callable[[Player], None]) -> None:
        """Call `listener` with the bay's player whenever it changes (Open Connect's Code 201)."""
        self._bay.on_player_change(listener)

    async def watch_bay(self) -> None:
        """Follow the bay file's edits until cancelled."""
        await self._bay.watch()

    def subscribe(self, after_id: int | None = None, client: str = "") -> Viewer:
        """A screen's queue of the bay's shots, for a stream from address `client` (`ShotFeed.subscribe`: when every
        place is taken, one gives way); NotReady before the model is loaded."""
        self._ready_engine()
        return self._feed.subscribe(after_id, client)

    def unsubscribe(self, viewer: Viewer) -> None:
        """A screen has gone."""
        self._feed.unsubscribe(viewer)

    def start_session(self, player: str | None = None) -> Session:
        """Start a new session (its player's name optional): the bay's screens empty, earlier sessions stay."""
        return self._feed.start_session(player)

    def session(self, session_id: int | None = None) -> Session | None:
        """A kept session (the current one without an id), or None."""
        return self._feed.sessions.get(session_id)

    def sessions(self) -> SessionList:
        """The sessions kept, oldest first, and the caps."""
        return self._feed.sessions.listing()

    def session_summary(self, session: Session) -> SessionSummary:
        """A session's clubs: mean and spread of carry, total, apex and lateral, gaps, 95 % ellipses."""
        return self._feed.sessions.summary(session)
