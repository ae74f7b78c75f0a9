"""The HTTP service: a FastAPI app factory with thin async routes over `service.api.shots`.

Single shots simulate inline in `async def` routes: one takes well under a millisecond, less than a hop to a
thread would cost. Batches fly in a child process at a lower CPU priority (`batch_process`), so a fitting studio's
thousands of shots neither hold the GIL nor take a core from a simulator bay's single shots; more concurrency
comes from `golfflight serve --workers N` (one process, one model and one batch process each).
The model loads in a background thread at startup; /healthz answers 503 until it is ready. In front of the routes:
a body-size limit, the optional API key ($GOLFFLIGHT_API_KEY) and CORS only for configured origins
($GOLFFLIGHT_CORS_ORIGINS); every refusal is a 4xx whose body names the field, the value and the allowed range.
Given a connect address, the lifespan also opens GSPro Open Connect over TCP on the same loop (`service.open_connect`).
"""

from __future__ import annotations

import asyncio
import gc
import os
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.middleware.cors import CORSMiddleware
from fastapi.responses import JSONResponse, Response
from pydantic import BaseModel
from starlette.exceptions import HTTPException as StarletteHTTPException

from golfflight import __version__
from service.api.batch_process import BatchProcess
from service.api.gspro import GSProMessage, GSProReply, fly_message, invalid_message
from service.api.guards import API_KEY_ENV, CORS_ORIGINS_ENV, MAX_BODY_BYTES, ApiKey, BodyLimit
from service.api.latency import RequestTimer, Rolling
from service.api.models import (
    MAX_BATCH_SHOTS,
    MAX_BATCH_TRAJECTORIES,
    RANGES,
    BatchRequest,
    BatchResult,
    ShotRequest,
    ShotResult,
    body_detail,
    describe_errors,
)
from service.api.shots import fly_shot
from service.engine import FlightEngine, FlightError
from service.model_location import model_dir
from service.open_connect.server import ConnectAddress, OpenConnectServer
from weights_schema.model_card import ModelCard

GSPRO_PATH = "/v1/gspro"
GSPRO_STATUS = {200: 200, 500: 422, 503: 503}
"""HTTP status of each Open Connect reply code on POST /v1/gspro."""
BATCH_PROCESS_DIED = "the batch process stopped while flying this batch (it has been restarted): send the batch again"
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
        self.batches = BatchProcess(bundle_dir)

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


class NotReady(Exception):
    """A simulation route was called before the model was loaded."""


def _json(model: BaseModel, status_code: int = 200) -> Response:
    return Response(model.model_dump_json(exclude_none=True), status_code, media_type="application/json")


def _flight_error(error: FlightError) -> JSONResponse:
    return JSONResponse({"detail": [body_detail(str(error), "flight_error")]}, 422)


def _origins(text: str | None) -> list[str]:
    return [origin.strip() for origin in (text or "").split(",") if origin.strip()]


ERROR_RESPONSES = {
    401: {"description": "the API key is required and was missing or wrong"},
    413: {"description": f"request body over {MAX_BODY_BYTES:,} bytes"},
    503: {"description": "the model is still loading, or failed to load (see /healthz)"},
}


def create_app(
    model: str | os.PathLike | None = None,
    *,
    api_key: str | None = None,
    cors_origins: list[str] | None = None,
    connect: ConnectAddress | None = None,
) -> FastAPI:
    """The service for a model bundle (default: `service.model_location.model_dir()`).

    `api_key` (default $GOLFFLIGHT_API_KEY) makes every route but /healthz require it; `cors_origins` (default the
    comma-separated $GOLFFLIGHT_CORS_ORIGINS) are the browser origins allowed; none means CORS stays off. `connect`
    (default from $GOLFFLIGHT_CONNECT_PORT and _HOST) also listens for GSPro Open Connect over TCP there."""
    state = ServiceState(model_dir(model))
    api_key = api_key if api_key is not None else os.environ.get(API_KEY_ENV, "")
    cors_origins = cors_origins if cors_origins is not None else _origins(os.environ.get(CORS_ORIGINS_ENV))
    connect = connect if connect is not None else ConnectAddress.from_env()

    def gspro_reply(message: GSProMessage) -> GSProReply:
        """A GSPro shot's reply over HTTP and TCP alike (timed into /v1/latency); Code 503 until the model is ready."""
        if state.engine is None:
            return GSProReply(Code=503, Message=state.error or "the model is still loading")
        started = time.perf_counter()
        try:
            return fly_message(state.engine, message)
        finally:
            state.simulation.add(time.perf_counter() - started)

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        tcp = OpenConnectServer(gspro_reply) if connect else None
        if tcp:
            await tcp.start(connect)  # before the model loads: a port that cannot be had stops the startup cleanly
        loading = asyncio.get_running_loop().run_in_executor(None, state.load)
        yield
        if tcp:
            await tcp.close()
        await loading
        state.batches.stop()

    app = FastAPI(
        title="golfflight",
        version=__version__,
        summary="Golf ball flights from launch-monitor data: Phys-NN+ (a network inside the equations of motion).",
        lifespan=lifespan,
    )
    app.state.service = state
    app.add_middleware(RequestTimer, rolling=state.requests, prefixes=("/v1/shots", GSPRO_PATH))
    if api_key:
        app.add_middleware(ApiKey, key=api_key)
    if cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=cors_origins,
            allow_methods=["GET", "POST"],
            allow_headers=["content-type", "x-api-key", "authorization"],
        )
    app.add_middleware(BodyLimit, limit=MAX_BODY_BYTES)

    def engine() -> FlightEngine:
        if state.engine is None:
            raise NotReady(state.error or "the model is still loading")
        return state.engine

    @app.exception_handler(RequestValidationError)
    async def invalid_request(request: Request, error: RequestValidationError) -> JSONResponse:
        if request.url.path == GSPRO_PATH:
            message = invalid_message(error.errors())
            return JSONResponse(GSProReply(Code=500, Message=message).model_dump(exclude_none=True), 422)
        return JSONResponse({"detail": describe_errors(error.errors(), RANGES)}, 422)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, error: StarletteHTTPException) -> Response:
        if error.status_code != 400:
            return await http_exception_handler(request, error)
        message = "the body is not JSON text in UTF-8"  # FastAPI's 400 for a body it cannot even decode
        if request.url.path == GSPRO_PATH:
            return JSONResponse(GSProReply(Code=500, Message=message).model_dump(exclude_none=True), 422)
        return JSONResponse({"detail": [body_detail(message, "json_invalid")]}, 422)

    @app.exception_handler(NotReady)
    async def not_ready(request: Request, error: NotReady) -> JSONResponse:
        return JSONResponse({"detail": str(error)}, 503)

    @app.post(
        "/v1/shots",
        response_model=ShotResult,
        response_model_exclude_none=True,
        responses={422: {"description": "invalid launch or conditions, or a shot that cannot land"}, **ERROR_RESPONSES},
    )
    async def shot(request: ShotRequest) -> Response:
        """Fly one shot: launch in SI or launch-monitor units, optional wind, air, normalized and trajectory."""
        flying = engine()
        started = time.perf_counter()
        try:
            result = fly_shot(flying, request)
        except FlightError as error:
            return _flight_error(error)
        finally:
            state.simulation.add(time.perf_counter() - started)
        return _json(result)

    @app.post(
        "/v1/shots/batch",
        response_model=BatchResult,
        response_model_exclude_none=True,
        responses=ERROR_RESPONSES,
        description=f"Fly up to {MAX_BATCH_SHOTS:,} shots together in one engine batch (at most "
        f"{MAX_BATCH_TRAJECTORIES} of them with a trajectory); results come back in order and a shot that cannot "
        "land gets an error entry of its own.",
    )
    async def batch(request: BatchRequest, http: Request) -> Response:
        """FastAPI has validated `request` (a 422 otherwise); the batch process flies its raw body."""
        engine()
        try:
            body, seconds = await state.batches.fly(await http.body())
        except BrokenProcessPool:
            return JSONResponse({"detail": BATCH_PROCESS_DIED}, 503)
        state.simulation.add(seconds)
        return Response(body, media_type="application/json")

    @app.post(
        GSPRO_PATH,
        response_model=GSProReply,
        response_model_exclude_none=True,
        responses={
            422: {"model": GSProReply, "description": "an invalid message or a failed flight: Open Connect's Code 500"},
            **ERROR_RESPONSES,
        },
    )
    async def gspro(message: GSProMessage) -> Response:
        """A GSPro Open Connect v1 message: a shot gets its flight with Code 200, a heartbeat just Code 200; an
        invalid message or a failed flight gets HTTP 422 with Open Connect's error reply (Code 500, a Message)."""
        if message.is_heartbeat:
            return _json(GSProReply(Code=200, Message="heartbeat received"))
        if message.BallData is None:
            return _json(GSProReply(Code=200, Message="no ball data: nothing to fly", ShotNumber=message.ShotNumber))
        reply = gspro_reply(message)
        return _json(reply, GSPRO_STATUS[reply.Code])

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

    @app.get("/v1/model", response_model=ModelCard, responses=ERROR_RESPONSES)
    async def model_card() -> Response:
        """The loaded bundle's model card (every field, nulls included, as the card's schema requires)."""
        return Response(engine().card.model_dump_json(), media_type="application/json")

    @app.get("/v1/latency", responses=ERROR_RESPONSES)
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
