"""GET /healthz (readiness, no key needed), /v1/model (the card) and /v1/latency (rolling figures and a probe)."""

from __future__ import annotations

import time

from fastapi import APIRouter, Depends
from fastapi.responses import JSONResponse, Response
from golfflight.contract.flying import fly_shot
from golfflight.contract.requests import ShotRequest
from golfflight.flight.engine import FlightEngine
from golfflight.service.api.dependencies import bay_runtime, ready_engine
from golfflight.service.api.routes.responses import ERROR_RESPONSES
from golfflight.service.runtime import BayRuntime
from golfflight.weights_schema.model_card import ModelCard

from golfflight import __version__

PROBE_SHOT = ShotRequest(ball_speed_mps=55.0, launch_angle_deg=16.0, spin_rpm=7100.0)
"""The shot /v1/latency times on demand: a tour-average 7-iron in standard air."""

router = APIRouter()


@router.get("/healthz")
async def healthz(runtime: BayRuntime = Depends(bay_runtime)) -> JSONResponse:
    """Ready (200) once the model is loaded, with its variant and hash (not its directory: no key is needed here,
    and where the model lives is no caller's business); "degraded" (still 200: every shot flies)
    with `problems` saying what to repair, e.g. a bay file broken while serving; 503 while loading or if it
    failed."""
    if runtime.engine is None:
        status = "failed" if runtime.error else "loading"
        return JSONResponse({"status": status, "error": runtime.error}, 503)
    engine = runtime.engine
    model = {
        "variant": engine.variant,
        "sha256": engine.sha256,
        "load_seconds": engine.load_seconds,
    }
    problems = runtime.problems()
    answer = {"status": "degraded" if problems else "ready", "model": model, "version": __version__,
              **runtime.reports()}
    return JSONResponse({**answer, "problems": problems} if problems else answer)


@router.get("/v1/model", response_model=ModelCard, responses=ERROR_RESPONSES)
async def model_card(engine: FlightEngine = Depends(ready_engine)) -> Response:
    """The loaded bundle's model card (every field, nulls included, as the card's schema requires)."""
    return Response(engine.card.model_dump_json(), media_type="application/json")


@router.get("/v1/latency", responses=ERROR_RESPONSES)
async def latency(
    engine: FlightEngine = Depends(ready_engine), runtime: BayRuntime = Depends(bay_runtime)
) -> JSONResponse:
    """Rolling p50/p95/p99 of simulation time and whole requests, and a probe shot timed now."""
    started = time.perf_counter()
    fly_shot(engine, PROBE_SHOT)
    probe_ms = (time.perf_counter() - started) * 1e3
    return JSONResponse(
        {
            "simulation": runtime.simulation.summary(),
            "request": runtime.requests.summary(),
            "probe": {"shot": PROBE_SHOT.model_dump(exclude_none=True), "simulation_ms": probe_ms},
        }
    )
