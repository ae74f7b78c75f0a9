"""POST /v1/shots (inline: one shot takes well under a millisecond, less than a hop to a thread would cost) and
POST /v1/shots/batch (read, validated and flown in the batch process, at a lower CPU priority, off the event loop:
`service.runtime.batch_process`). A shot without air, wind or ground of its own flies in the bay's
(`service.runtime.bay`)."""

from __future__ import annotations

from fastapi import APIRouter, Query, Request
from fastapi.responses import Response
from golfflight.contract.requests import MAX_BATCH_SHOTS, MAX_BATCH_TRAJECTORIES, BatchRequest, ShotRequest
from golfflight.contract.results import BatchResult, ShotResult
from golfflight.service.api.client_address import client_address
from golfflight.service.api.direct import DirectRoute, RawBodyRoute
from golfflight.service.api.routes.responses import ERROR_RESPONSES, json_response
from golfflight.service.runtime import runtime_of

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
    # `request` was validated once (`service.api.direct`); the runtime comes from the app (`runtime_of`)
    return json_response(runtime_of(http).fly(request, "http", show=viewer, client=client_address(http)).result)


async def batch(request: BatchRequest, http: Request, viewer: bool = ShowOnViewer) -> Response:
    """The batch process reads, validates and flies the raw body (the bay's conditions filled in where a shot gives
    none) or refuses it; `request` gives FastAPI the schema and is None on the direct path (`RawBodyRoute`)."""
    body = await runtime_of(http).fly_batch(await http.body(), show=viewer, client=client_address(http))
    return Response(body, media_type="application/json")


router.add_api_route(
    "/batch",
    batch,
    methods=["POST"],
    route_class_override=RawBodyRoute,
    response_model=BatchResult,
    response_model_exclude_none=True,
    responses=ERROR_RESPONSES,
    description=f"Fly up to {MAX_BATCH_SHOTS:,} shots together in one engine batch (at most "
    f"{MAX_BATCH_TRAJECTORIES} of them with a trajectory); results come back in order and a shot that cannot "
    "land gets an error entry of its own.",
)
