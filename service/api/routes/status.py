"""GET /healthz (readiness, no key needed), /v1/model (the card) and /v1/latency (rolling figures and a probe)."""

from __future__ import annotations

import time

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse, Response
from golfflight.service.api.routes.responses import ERROR_RESPONSES
from golfflight.service.runtime import runtime_of
from golfflight.weights_schema.model_card import ModelCard

NOT_SERVING = frozenset({"loading", "failed"})
"""The health statuses answered 503: no shot can fly yet."""

router = APIRouter()


@router.get("/healthz")
async def healthz(http: Request) -> JSONResponse:
    """Ready (200) once the model is loaded, with its variant and hash (not its directory: no key is needed here,
    and where the model lives is no caller's business); "degraded" (still 200: every shot flies)
    with `problems` saying what to repair, e.g. a bay file broken while serving; 503 while loading or if it
    failed."""
    health = runtime_of(http).health()
    return JSONResponse(health, 503 if health["status"] in NOT_SERVING else 200)


@router.get("/v1/model", response_model=ModelCard, responses=ERROR_RESPONSES)
async def model_card(http: Request) -> Response:
    """The loaded bundle's model card (every field, nulls included, as the card's schema requires)."""
    return Response(runtime_of(http).model().model_dump_json(), media_type="application/json")


@router.get("/v1/latency", responses=ERROR_RESPONSES)
async def latency(http: Request) -> JSONResponse:
    """Rolling p50/p95/p99 of simulation time and whole requests, and a probe shot timed now."""
    return JSONResponse(runtime_of(http).latency())
