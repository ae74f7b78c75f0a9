"""The served bay, assembled: one bay runtime (`service.runtime`) and its adapters, which import neither each other
nor this module: the HTTP app (`service.api`), the viewer's routes (`service.viewer`) and, given a connect address,
GSPro Open Connect over TCP (`service.open_connect`). `golfflight serve` runs what `create_app` returns.

The model loads during the lifespan's startup, before uvicorn opens the HTTP port and before the Open Connect port
accepts: the first request is served; /healthz answers 503 only if the model failed to load. A change of the bay's
player reaches every connector as Code 201 player information.
"""

from __future__ import annotations

import asyncio
import os
from contextlib import asynccontextmanager

from fastapi import FastAPI
from golfflight.contract.bay import Player
from golfflight.flight.bundle_location import model_dir
from golfflight.service.api.app import http_app
from golfflight.service.api.guards import ALLOWED_HOSTS_ENV, API_KEY_ENV, CORS_ORIGINS_ENV
from golfflight.service.open_connect.server import ConnectAddress, OpenConnectServer
from golfflight.service.runtime import BayRuntime
from golfflight.service.runtime.bay import BAY_FILE_ENV, Bay
from golfflight.service.runtime.parent_watch import exit_with_parent
from golfflight.service.viewer import routes as viewer_routes
from golfflight.service.viewer.page import PUBLIC_PATHS


def _listed(text: str | None) -> list[str]:
    """The items of a comma-separated setting (origins, host names)."""
    return [origin.strip() for origin in (text or "").split(",") if origin.strip()]


def create_app(
    model: str | os.PathLike | None = None,
    *,
    api_key: str | None = None,
    cors_origins: list[str] | None = None,
    connect: ConnectAddress | None = None,
    bay: str | os.PathLike | None = None,
    allowed_hosts: list[str] | None = None,
) -> FastAPI:
    """The service for a model bundle (default: `flight.bundle_location.model_dir()`).

    `api_key` (default $GOLFFLIGHT_API_KEY) makes every route but /healthz and the viewer's page require it;
    `cors_origins` (default the comma-separated $GOLFFLIGHT_CORS_ORIGINS) are the browser origins allowed; none means
    CORS stays off. `connect` (default from $GOLFFLIGHT_CONNECT_PORT and _HOST) also listens for GSPro Open Connect
    over TCP there. `bay` (default $GOLFFLIGHT_BAY_FILE) is the file the bay's conditions are kept in
    (`service.runtime.bay`); none keeps them in memory only. Without an API key, only requests to this machine's names
    and `allowed_hosts` (default the comma-separated $GOLFFLIGHT_ALLOWED_HOSTS) are answered."""
    bay = bay if bay is not None else os.environ.get(BAY_FILE_ENV) or None
    runtime = BayRuntime(model_dir(model), Bay(bay))
    api_key = api_key if api_key is not None else os.environ.get(API_KEY_ENV, "")
    cors_origins = cors_origins if cors_origins is not None else _listed(os.environ.get(CORS_ORIGINS_ENV))
    connect = connect if connect is not None else ConnectAddress.from_env()
    allowed_hosts = allowed_hosts if allowed_hosts is not None else _listed(os.environ.get(ALLOWED_HOSTS_ENV))

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        exit_with_parent()  # a worker of `serve --workers N` ends with its supervisor, however that dies
        tcp = OpenConnectServer(lambda message: runtime.fly_gspro(message, "open-connect")) if connect else None
        if tcp:  # taken before the model loads: a port that cannot be had stops the startup at once
            await tcp.start(connect, listening=False)
            runtime.bay.on_player_change(lambda changed: _tell(tcp, changed))
            runtime.add_reporter("open_connect", tcp.health)  # /healthz: connectors, refusals, evictions
        watching = asyncio.create_task(runtime.bay.watch())  # an edit of the bay file, a club change in it above all
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

    return http_app(runtime, lifespan=lifespan, api_key=api_key, cors_origins=cors_origins,
                    more_routers=viewer_routes.ROUTERS, open_paths=PUBLIC_PATHS, allowed_hosts=allowed_hosts)


def _tell(tcp: OpenConnectServer, player: Player) -> None:
    """Code 201 player information to every connector."""
    tcp.send_player(player.club, player.handed)
