"""The HTTP service: `create_app` assembles FastAPI's "bigger applications" layout, the routers of
`service.api.routes` over the plain functions of the shot contract (`contract`), the engine reaching them through a
dependency (`service.api.state.ready_engine`, from `app.state`), or, on the single-shot routes, where FastAPI's
solving of dependencies was a tenth of a request, read directly (`state_of`, `ServiceState.ready_engine`).

Single shots simulate inline in `async def` routes. Batches fly in a child process at a lower CPU priority
(`batch_process`), so a fitting studio's thousands of shots neither hold the GIL nor take a core from a simulator
bay's single shots; more concurrency comes from `golfflight serve --workers N` (one process, one model and one batch
process each). The model loads during the lifespan's startup, before uvicorn opens the port (and before the Open
Connect port accepts): the first request is served; /healthz answers 503 only if the model failed to load. In front
of the routes: a body-size limit, the optional API key ($GOLFFLIGHT_API_KEY) and CORS only for configured origins
($GOLFFLIGHT_CORS_ORIGINS); inside those, a valid simulation request goes straight to its endpoint
(`service.api.direct`); every refusal is a 4xx whose body names the field, the value and the allowed range
(`service.api.errors`). Given a connect address, the lifespan also opens GSPro Open Connect over TCP on the same
loop (`service.open_connect`). Every shot flown, from any input, goes to the live viewer's feed (GET /viewer,
`service.viewer`). GET/PUT /v1/bay hold the simulator bay's air, wind and ground, which Open Connect shots and shots
without conditions of their own fly in (`service.api.bay`). /docs loads its script and style from an installed
package, not a CDN (`routes.docs`; ReDoc is off). The outermost middleware counts and times every request for
GET /metrics (Prometheus) and /v1/latency (`service.api.request_metrics`).
"""

from __future__ import annotations

import asyncio
import os
from contextlib import asynccontextmanager
from functools import partial
from importlib.metadata import version

from fastapi import FastAPI
from fastapi.middleware.cors import CORSMiddleware
from golfflight.flight.bundle_location import model_dir
from golfflight.service.api import errors
from golfflight.service.api.bay import BAY_FILE_ENV, Bay
from golfflight.service.api.direct import DirectLanes
from golfflight.service.api.guards import API_KEY_ENV, CORS_ORIGINS_ENV, MAX_BODY_BYTES, ApiKey, BodyLimit
from golfflight.service.api.request_metrics import RequestMetrics
from golfflight.service.api.routes import bay as bay_routes
from golfflight.service.api.routes import docs, gspro, metrics, shots, status, viewer
from golfflight.service.api.state import ServiceState
from golfflight.service.open_connect.server import ConnectAddress, OpenConnectServer
from starlette.routing import Mount, Route


def _origins(text: str | None) -> list[str]:
    return [origin.strip() for origin in (text or "").split(",") if origin.strip()]


def create_app(
    model: str | os.PathLike | None = None,
    *,
    api_key: str | None = None,
    cors_origins: list[str] | None = None,
    connect: ConnectAddress | None = None,
    bay: str | os.PathLike | None = None,
) -> FastAPI:
    """The service for a model bundle (default: `flight.bundle_location.model_dir()`).

    `api_key` (default $GOLFFLIGHT_API_KEY) makes every route but /healthz require it; `cors_origins` (default the
    comma-separated $GOLFFLIGHT_CORS_ORIGINS) are the browser origins allowed; none means CORS stays off. `connect`
    (default from $GOLFFLIGHT_CONNECT_PORT and _HOST) also listens for GSPro Open Connect over TCP there. `bay`
    (default $GOLFFLIGHT_BAY_FILE) is the file the bay's conditions are kept in (`service.api.bay`); none keeps them
    in memory only."""
    bay = bay if bay is not None else os.environ.get(BAY_FILE_ENV) or None
    state = ServiceState(model_dir(model), Bay(bay))
    api_key = api_key if api_key is not None else os.environ.get(API_KEY_ENV, "")
    cors_origins = cors_origins if cors_origins is not None else _origins(os.environ.get(CORS_ORIGINS_ENV))
    connect = connect if connect is not None else ConnectAddress.from_env()

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        tcp = OpenConnectServer(partial(state.gspro_reply, source="open-connect")) if connect else None
        if tcp:  # taken before the model loads: a port that cannot be had stops the startup at once
            await tcp.start(connect, listening=False)
        loading = asyncio.get_running_loop().run_in_executor(None, state.load)  # in a thread: the event loop stays free
        try:
            # Loaded before either port accepts (uvicorn binds HTTP's once this startup returns): the first request
            # is served, not answered 503. A model that fails to load still lets the service start to say why.
            await asyncio.shield(loading)
            if tcp:
                await tcp.listen()
            yield
        finally:
            if tcp:
                await tcp.close()
            await loading
            state.batches.stop()

    app = FastAPI(
        title="golfflight",
        version=version("golfflight"),
        summary="Golf ball flights from launch-monitor data: Phys-NN+ (a network inside the equations of motion).",
        lifespan=lifespan,
        docs_url=None,  # served by service.api.routes.docs from packaged files, not a CDN
        redoc_url=None,  # ReDoc's bundle fetches its logo from a CDN
    )
    app.state.service = state
    routers = (shots.router, gspro.router, bay_routes.router, status.router, metrics.router, viewer.router, docs.router)
    app.add_middleware(DirectLanes, routes=[route for router in routers for route in router.routes])  # innermost
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
    errors.install(app)
    for router in routers:
        app.include_router(router)
    docs.mount_assets(app)
    routes = [route for router in routers for route in router.routes] + [
        r for r in app.routes if isinstance(r, (Route, Mount))
    ]
    simulation_routes = {"/v1/shots", "/v1/shots/batch", gspro.GSPRO_PATH}
    app.add_middleware(
        RequestMetrics, metrics=state.metrics, routes=routes, rolling=state.requests, timed_routes=simulation_routes
    )
    return app
