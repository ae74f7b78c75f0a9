"""How the HTTP routes reach the bay runtime (`service.runtime`): set on `app.state.runtime` by the service's
assembly (`service.app`), handed over as FastAPI dependencies or read directly on the simulation routes."""

from __future__ import annotations

from fastapi import Depends, Request
from golfflight.flight.engine import FlightEngine
from golfflight.service.runtime import BayRuntime


async def bay_runtime(request: Request) -> BayRuntime:
    """The app's runtime. `async def`, as every dependency here: FastAPI would run a plain `def` in its thread pool,
    a hop that costs more than a single shot's simulation."""
    return request.app.state.runtime


def runtime_of(request: Request) -> BayRuntime:
    """The app's runtime, for the simulation routes: a plain attribute read where a dependency costs FastAPI a
    dependency graph to solve on every request (about a tenth of a single shot's time over HTTP)."""
    return request.app.state.runtime


async def ready_engine(runtime: BayRuntime = Depends(bay_runtime)) -> FlightEngine:
    """The loaded engine; NotReady (503) while the model loads or after it failed to."""
    return runtime.ready_engine()
