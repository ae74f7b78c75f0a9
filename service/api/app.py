"""The HTTP adapter of the bay runtime: `http_app` assembles FastAPI's "bigger applications" layout, the routers of
`service.api.routes` over the plain functions of the shot contract (`contract`) and the runtime (`service.runtime`,
on `app.state.runtime`, reached through `service.runtime.runtime_of`).

Single shots simulate inline in `async def` routes. Batches fly in the runtime's child process at a lower CPU
priority, so a fitting studio's thousands of shots neither hold the GIL nor take a core from a simulator bay's single
shots; more concurrency comes from `golfflight serve --workers N` (one process, one runtime each). In front of the
routes: CORS only for configured origins ($GOLFFLIGHT_CORS_ORIGINS), the optional API key ($GOLFFLIGHT_API_KEY; without
one, the Host and cross-site checks of `guards.HostCheck`), then a body-size limit, so that no body is read before the
key is checked; inside those, a valid simulation request goes straight to its endpoint
(`service.api.direct`); every refusal is a 4xx whose body names the field, the value and the allowed range
(`service.api.errors`). GET/PUT/PATCH /v1/bay hold the bay's conditions and player. /docs loads its script and style
from an installed package, not a CDN (`routes.docs`; ReDoc is off). The outermost middleware counts and times every
request for GET /metrics (Prometheus) and /v1/latency (`service.api.request_metrics`). The service's assembly
(`service.app`) adds the viewer's routes and the lifespan that loads the model and opens Open Connect.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import AbstractAsyncContextManager
from typing import Callable

from fastapi import APIRouter, FastAPI
from fastapi.middleware.cors import CORSMiddleware
from golfflight.service.api import errors
from golfflight.service.api.direct import DirectLanes
from golfflight.service.api.guards import MAX_BODY_BYTES, ApiKey, BodyLimit, HostCheck
from golfflight.service.api.paths import SIMULATION_PATHS
from golfflight.service.api.request_metrics import RequestMetrics
from golfflight.service.api.routes import bay as bay_routes
from golfflight.service.api.routes import docs, gspro, metrics, shots, status
from golfflight.service.runtime import BayRuntime
from starlette.routing import Mount, Route

from golfflight import __version__


def http_app(
    runtime: BayRuntime,
    *,
    lifespan: Callable[[FastAPI], AbstractAsyncContextManager[None]],
    api_key: str = "",
    cors_origins: Sequence[str] = (),
    more_routers: Sequence[APIRouter] = (),
    open_paths: frozenset[str] = frozenset(),
    allowed_hosts: Sequence[str] = (),
) -> FastAPI:
    """The HTTP app over `runtime`: its own routers and `more_routers` (the viewer's), `api_key` required on every
    route but /healthz and `open_paths` when given (without one, only requests to this machine's names and
    `allowed_hosts` are answered: `guards.HostCheck`), CORS for `cors_origins`, `lifespan` run around serving."""
    app = FastAPI(
        title="golfflight",
        version=__version__,
        summary="Golf ball flights from launch-monitor data: Phys-NN+ (a network inside the equations of motion).",
        lifespan=lifespan,
        docs_url=None,  # served by service.api.routes.docs from packaged files, not a CDN
        redoc_url=None,  # ReDoc's bundle fetches its logo from a CDN
    )
    app.state.runtime = runtime
    routers = (shots.router, gspro.router, bay_routes.router, status.router, metrics.router, *more_routers,
               docs.router)
    app.add_middleware(DirectLanes, routes=[route for router in routers for route in router.routes])  # innermost
    app.add_middleware(BodyLimit, limit=MAX_BODY_BYTES)  # inside the key: no body is read before the key is checked
    if api_key:
        app.add_middleware(ApiKey, key=api_key, open_paths=open_paths)
    else:
        app.add_middleware(HostCheck, allowed=frozenset(allowed_hosts), origins=frozenset(cors_origins))
    if cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=list(cors_origins),
            allow_methods=["GET", "POST", "PUT", "PATCH"],
            allow_headers=["content-type", "x-api-key", "authorization"],
        )
    errors.install(app)
    for router in routers:
        app.include_router(router)
    docs.mount_assets(app)
    routes = [route for router in routers for route in router.routes] + [
        r for r in app.routes if isinstance(r, (Route, Mount))
    ]
    counters, rolling = runtime.request_sinks()
    app.add_middleware(RequestMetrics, metrics=counters, routes=routes, rolling=rolling, timed_routes=SIMULATION_PATHS)
    return app
