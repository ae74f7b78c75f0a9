"""GET /healthz (readiness, no key needed), /v1/model (the card) and /v1/latency (rolling figures and a probe)."""

from __future__ import annotations

import re
import time
from pathlib import Path

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse, Response
from golfflight.service.api.routes.responses import ERROR_RESPONSES
from golfflight.service.runtime import runtime_of
from golfflight.weights_schema.model_card import ModelCard

NOT_SERVING = frozenset({"loading", "failed"})
"""The health statuses answered 503: no shot can fly yet."""

DIRECTORIES = re.compile(r"(?<![\w.])(?:[A-Za-z]:|~)?[\\/](?:[^\s:'\"\\/]*[\\/])*")
"""The directories of an absolute path without spaces in a message (POSIX or Windows; not the "/" of "m/s")."""

router = APIRouter()


def without_directories(value: object, known: Path | None = None) -> object:
    """`value` (health's figures) with every path in its text cut to its file name: `known` (the bay file's, whose
    directories may hold spaces) exactly, any other path without spaces by its separators."""
    if isinstance(value, str):
        if known is not None:
            value = value.replace(str(known), known.name)
        return DIRECTORIES.sub("", value)
    if isinstance(value, dict):
        return {key: without_directories(item, known) for key, item in value.items()}
    if isinstance(value, list):
        return [without_directories(item, known) for item in value]
    return value


@router.get("/healthz")
async def healthz(http: Request) -> JSONResponse:
    """Ready (200) once the model is loaded, with its variant and hash (not its directory: no key is needed here,
    and where the model lives is no caller's business); "degraded" (still 200: every shot flies)
    with `problems` saying what to repair, e.g. a bay file broken while serving, naming files without their
    directories (no key is needed here: the server's log has the whole path); 503 while loading or if it failed."""
    runtime = runtime_of(http)
    health = without_directories(runtime.health(), runtime.bay_file())
    return JSONResponse(health, 503 if health["status"] in NOT_SERVING else 200)


@router.get("/v1/model", response_model=ModelCard, responses=ERROR_RESPONSES)
async def model_card(http: Request) -> Response:
    """The loaded bundle's model card (every field, nulls included, as the card's schema requires)."""
    return Response(runtime_of(http).model().model_dump_json(), media_type="application/json")


@router.get("/v1/latency", responses=ERROR_RESPONSES)
async def latency(http: Request) -> JSONResponse:
    """Rolling p50/p95/p99 of simulation time and whole requests, and a probe shot timed now."""
    return JSONResponse(runtime_of(http).latency())
