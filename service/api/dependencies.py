"""FastAPI dependencies for routes a newcomer adds: the bay runtime as `Depends(bay_runtime)`. Such a route is served
by FastAPI's own path (`service.api.direct`); the shipped simulation routes read the runtime with `runtime_of`."""

from __future__ import annotations

from fastapi import Request
from golfflight.service.runtime import BayRuntime, runtime_of


async def bay_runtime(http: Request) -> BayRuntime:
    """The bay runtime the app was assembled with, as a dependency (`runtime_of` takes the request unannotated, so
    FastAPI would read it as a query parameter); `async def`, as FastAPI runs a plain `def` one in its thread pool."""
    return runtime_of(http)
