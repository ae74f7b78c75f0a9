"""The HTTP service: a FastAPI app factory with thin async routes over `service.api.shots`.

Routes are `async def` and simulate inline: one shot takes well under a millisecond, less than a hop to a
worker thread would cost, so concurrency comes from `golfflight serve --workers N` (one process, one model each).
The model loads in a background thread at startup; /healthz answers 503 until it is ready.
"""

from __future__ import annotations

import asyncio
import os
import threading
import time
from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from pydantic import BaseModel

from golfflight import __version__
from service.api.gspro import GSProMessage, GSProReply, launch_from_ball_data
from service.api.latency import RequestTimer, Rolling
from service.api.models import (
    MAX_BATCH_SHOTS,
    BatchRequest,
    BatchResult,
    ShotRequest,
    ShotResult,
    describe_errors,
)
from service.api.shots import flight_fields, fly_shot, fly_shots
from service.engine import FlightEngine, FlightError
from service.model_location import model_dir
from weights_schema.model_card import ModelCard

GSPRO_PATH = "/v1/gspro"
PROBE_SHOT = ShotRequest(ball_speed_mps=55.0, launch_angle_deg=16.0, spin_rpm=7100.0)
"""The shot /v1/latency times on demand: a tour-average 7-iron in standard air."""


class ServiceState:
    """What the routes share: the engine once loaded (or why it failed) and the rolling latency figures."""

    def __init__(self, bundle_dir: Path):
        self.bundle_dir = bundle_dir
        self.engine: FlightEngine | None = None
        self.error: str | None = None
        self.simulation = Rolling()
        self.requests = Rolling()
        self.loaded = threading.Event()

    def load(self) -> None:
        try:
            self.engine = FlightEngine(self.bundle_dir)
        except Exception as error:  # noqa: BLE001 - reported by /healthz, the service stays up to say so
            self.error = f"{type(error).__name__}: {error}"
        finally:
            self.loaded.set()


class NotReady(Exception):
    """A simulation route was called before the model was loaded."""


def _json(model: BaseModel, status_code: int = 200) -> Response:
    return Response(model.model_dump_json(exclude_none=True), status_code, media_type="application/json")


def create_app(model: str | os.PathLike | None = None) -> FastAPI:
    """The service for a model bundle (default: `service.model_location.model_dir()`)."""
    state = ServiceState(model_dir(model))

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        loading = asyncio.get_running_loop().run_in_executor(None, state.load)
        yield
        await loading

    app = FastAPI(
        title="golfflight",
        version=__version__,
        summary="Golf ball flights from launch-monitor data: Phys-NN+ (a network inside the equations of motion).",
        lifespan=lifespan,
    )
    app.state.service = state
    app.add_middleware(RequestTimer, rolling=state.requests, prefixes=("/v1/shots", GSPRO_PATH))

    def engine() -> FlightEngine:
        if state.engine is None:
            raise NotReady(state.error or "the model is still loading")
        return state.engine

    @app.exception_handler(RequestValidationError)
    async def invalid_request(request: Request, error: RequestValidationError) -> JSONResponse:
        details = describe_errors(error.errors())
        if request.url.path == GSPRO_PATH:
            message = "; ".join(d["message"] for d in details)
            return JSONResponse(GSProReply(Code=500, Message=message).model_dump(exclude_none=True), 500)
        return JSONResponse({"detail": details}, 422)

    @app.exception_handler(NotReady)
    async def not_ready(request: Request, error: NotReady) -> JSONResponse:
        if request.url.path == GSPRO_PATH:
            return JSONResponse({"Code": 503, "Message": str(error)}, 503)
        return JSONResponse({"detail": str(error)}, 503)

    @app.post(
        "/v1/shots",
        response_model=ShotResult,
        response_model_exclude_none=True,
        responses={422: {"description": "invalid launch or conditions, or a shot that cannot land"}},
    )
    async def shot(request: ShotRequest) -> Response:
        """Fly one shot: launch in SI or launch-monitor units, optional wind, air, normalized and trajectory."""
        flying = engine()
        started = time.perf_counter()
        try:
            result = fly_shot(flying, request)
        except FlightError as error:
            return JSONResponse({"detail": [{"field": "body", "message": str(error)}]}, 422)
        finally:
            state.simulation.add(time.perf_counter() - started)
        return _json(result)

    @app.post(
        "/v1/shots/batch",
        response_model=BatchResult,
        response_model_exclude_none=True,
        description=f"Fly up to {MAX_BATCH_SHOTS:,} shots together in one engine batch; results come back in order "
        "and a shot that cannot land gets an error entry of its own.",
    )
    async def batch(request: BatchRequest) -> Response:
        flying = engine()
        started = time.perf_counter()
        results = fly_shots(flying, request.shots)
        state.simulation.add(time.perf_counter() - started)
        return _json(BatchResult(results=results))

    @app.post(GSPRO_PATH, response_model=GSProReply, response_model_exclude_none=True)
    async def gspro(message: GSProMessage) -> Response:
        """A GSPro Open Connect v1 message: a shot gets its flight with Code 200, a heartbeat just Code 200."""
        if message.is_heartbeat:
            return _json(GSProReply(Code=200, Message="heartbeat received"))
        if message.BallData is None or not message.ShotDataOptions.ContainsBallData:
            return _json(GSProReply(Code=200, Message="no ball data: nothing to fly", ShotNumber=message.ShotNumber))
        flying = engine()
        started = time.perf_counter()
        try:
            launch = launch_from_ball_data(message.BallData)
            flight = flying.fly(launch)
        except (ValueError, FlightError) as error:
            return _json(GSProReply(Code=500, Message=str(error), ShotNumber=message.ShotNumber), 500)
        finally:
            state.simulation.add(time.perf_counter() - started)
        result = ShotResult.model_construct(**flight_fields(flight, None))
        return _json(GSProReply(Code=200, Message="shot received", ShotNumber=message.ShotNumber, Flight=result))

    @app.get("/healthz")
    async def healthz() -> JSONResponse:
        """Ready (200) once the model is loaded, with its variant and hash; 503 while loading or if it failed."""
        if state.engine is None:
            status = "failed" if state.error else "loading"
            return JSONResponse({"status": status, "error": state.error, "model_dir": str(state.bundle_dir)}, 503)
        flying = state.engine
        return JSONResponse(
            {
                "status": "ready",
                "model": {
                    "variant": flying.variant,
                    "sha256": flying.sha256,
                    "dir": str(state.bundle_dir),
                    "load_seconds": flying.load_seconds,
                },
                "version": __version__,
            }
        )

    @app.get("/v1/model", response_model=ModelCard)
    async def model_card() -> Response:
        """The loaded bundle's model card."""
        return _json(engine().card)

    @app.get("/v1/latency")
    async def latency() -> JSONResponse:
        """Rolling p50/p95/p99 of simulation time and whole requests, and a probe shot timed now."""
        flying = engine()
        started = time.perf_counter()
        fly_shot(flying, PROBE_SHOT)
        probe_ms = (time.perf_counter() - started) * 1e3
        return JSONResponse(
            {
                "simulation": state.simulation.summary(),
                "request": state.requests.summary(),
                "probe": {"shot": PROBE_SHOT.model_dump(exclude_none=True), "simulation_ms": probe_ms},
            }
        )

    return app
