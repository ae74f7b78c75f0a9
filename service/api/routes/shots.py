"""POST /v1/shots (inline: one shot takes well under a millisecond, less than a hop to a thread would cost) and
POST /v1/shots/batch (in the batch process, at a lower CPU priority: `service.api.batch_process`). A shot without
air, wind or ground of its own flies in the bay's (`service.api.bay`)."""

from __future__ import annotations

import time
from concurrent.futures.process import BrokenProcessPool

from fastapi import APIRouter, Query, Request
from fastapi.responses import JSONResponse, Response
from golfflight.contract.bay import CONDITION_FIELDS, in_bay
from golfflight.contract.flying import fly_shot
from golfflight.contract.refusals import body_detail
from golfflight.contract.requests import MAX_BATCH_SHOTS, MAX_BATCH_TRAJECTORIES, BatchRequest, ShotRequest
from golfflight.contract.results import BatchResult, ShotResult
from golfflight.flight.engine import FlightError
from golfflight.service.api.direct import DirectRoute
from golfflight.service.api.routes.responses import ERROR_RESPONSES, json_response
from golfflight.service.api.state import state_of

BATCH_PROCESS_DIED = "the batch process stopped while flying this batch (it has been restarted): send the batch again"

router = APIRouter(prefix="/v1/shots", route_class=DirectRoute)

ShowOnViewer = Query(
    False,
    description="also show this request's shot (a batch: its last 50 shots) on the bay's live viewer (GET /viewer); "
    "without it only the bay's own shots (GSPro Open Connect over TCP and POST /v1/gspro) appear there",
)


@router.post(
    "",
    response_model=ShotResult,
    response_model_exclude_none=True,
    responses={422: {"description": "invalid launch or conditions, or a shot that cannot land"}, **ERROR_RESPONSES},
)
async def shot(request: ShotRequest, http: Request, viewer: bool = ShowOnViewer) -> Response:
    """Fly one shot: launch in SI or launch-monitor units, optional wind, air, ground, normalized and trajectory;
    the bay's conditions (GET /v1/bay) where the shot gives none."""
    # `request` was validated once (`service.api.direct`); the state comes from the app (`state_of`), not dependencies
    state = state_of(http)
    engine = state.ready_engine()
    request = in_bay(request, state.bay.conditions)
    started = time.perf_counter()
    try:
        result = fly_shot(engine, request)
    except FlightError as error:
        return JSONResponse({"detail": [body_detail(str(error), "flight_error")]}, 422)
    finally:
        state.record_simulation("shot", time.perf_counter() - started)
    if viewer:
        state.feed.publish("http", request, result)
    return json_response(result)


@router.post(
    "/batch",
    response_model=BatchResult,
    response_model_exclude_none=True,
    responses=ERROR_RESPONSES,
    description=f"Fly up to {MAX_BATCH_SHOTS:,} shots together in one engine batch (at most "
    f"{MAX_BATCH_TRAJECTORIES} of them with a trajectory); results come back in order and a shot that cannot "
    "land gets an error entry of its own.",
)
async def batch(request: BatchRequest, http: Request, viewer: bool = ShowOnViewer) -> Response:
    """`request` is valid (a 422 otherwise); the batch process flies its raw body, or the shots with the bay's
    conditions filled in when the bay has any."""
    state = state_of(http)
    state.ready_engine()
    bay = state.bay.conditions
    if any(getattr(bay, name) is not None for name in CONDITION_FIELDS):
        request = BatchRequest(shots=[in_bay(shot, bay) for shot in request.shots])
        raw = request.model_dump_json(exclude_none=True).encode()
    else:
        raw = await http.body()
    try:
        body, seconds = await state.batches.submit(raw)
    except BrokenProcessPool:
        return JSONResponse({"detail": BATCH_PROCESS_DIED}, 503)
    state.record_simulation("batch", seconds)
    state.metrics.batch_shots.observe(len(request.shots))
    if viewer:
        state.feed.publish_batch(request.shots)
    return Response(body, media_type="application/json")
