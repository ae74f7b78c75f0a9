"""The served bay, assembled: one bay runtime (`service.runtime`) and its adapters, which import neither each other
nor this module: the HTTP app (`service.api`), the viewer's routes (`service.viewer`) and, given a connect address,
GSPro Open Connect over TCP (`service.open_connect`). `golfflight serve` runs what `create_app` returns.

The model loads during the lifespan's startup, before uvicorn opens the HTTP port and before the Open Connect port
accepts: the first request is served; /healthz answers 503 only if the model failed to load. A change of the bay's
player reaches every connector as Code 201 player information.
"""

from __future__ import annotations

import asyncio
from contextlib import asynccontextmanager
from functools import partial

from fastapi import FastAPI
from golfflight.contract.bay import Player
from golfflight.flight.bundle_location import model_dir
from golfflight.service.api.app import http_app
from golfflight.service.open_connect.server import ConnectAddress, OpenConnectServer
from golfflight.service.runtime import BayRuntime
from golfflight.service.runtime.bay import Bay
from golfflight.service.runtime.parent_watch import exit_with_parent
from golfflight.service.settings import ServiceSettings
from golfflight.service.viewer import routes as viewer_routes
from golfflight.service.viewer.page import PUBLIC_PATHS


def create_app(settings: ServiceSettings | None = None) -> FastAPI:
    """The service for `settings` (default: `ServiceSettings.from_env()`, the settings `serve` handed its workers or
    the GOLFFLIGHT_* variables): the bundle (`flight.bundle_location.model_dir` where none is named), the API key
    every route but /healthz and the viewer's page then requires, the browser origins allowed (none: CORS off), the
    Host names answered without a key, the bay file (`service.runtime.bay`; none: in memory only) and, given a
    connect port, GSPro Open Connect over TCP there."""
    settings = settings if settings is not None else ServiceSettings.from_env()
    runtime = BayRuntime(model_dir(settings.model), Bay(settings.bay_file))
    connect = ConnectAddress(settings.connect_port, settings.connect_host) if settings.connect_port else None

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        exit_with_parent()  # a worker of `serve --workers N` ends with its supervisor, however that dies
        tcp = OpenConnectServer(partial(runtime.fly_gspro, source="open-connect")) if connect else None
        if tcp:  # taken before the model loads: a port that cannot be had stops the startup at once
            await tcp.start(connect, listening=False)
            runtime.on_player_change(lambda changed: _tell(tcp, changed))
            runtime.add_reporter("open_connect", tcp.health)  # /healthz: connectors, refusals, evictions
        watching = asyncio.create_task(runtime.watch_bay())  # an edit of the bay file, a club change in it above all
        loading = asyncio.get_running_loop().run_in_executor(None, runtime.load)  # the event loop stays free
        try:
            # Loaded before either port accepts (uvicorn binds HTTP's once this startup returns): the first request
            # is served, not answered 503. A model that fails to load still lets the service start to say why.
            await asyncio.shield(loading)
            if tcp:
                await tcp.listen()
            yield
        finally:
            watching.cancel()
            if tcp:
                await tcp.close()
            await loading
            runtime.stop()

    return http_app(runtime, lifespan=lifespan, api_key=settings.api_key, cors_origins=list(settings.cors_origins),
                    more_routers=viewer_routes.ROUTERS, open_paths=PUBLIC_PATHS,
                    allowed_hosts=list(settings.allowed_hosts))


def _tell(tcp: OpenConnectServer, player: Player) -> None:
    """Code 201 player information to every connector."""
    tcp.send_player(player.club, player.handed)
