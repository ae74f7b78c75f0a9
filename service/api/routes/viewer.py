"""GET /viewer (the live shot viewer page, its script and style) and GET /v1/events (its server-sent event stream).

Both are left out of the OpenAPI document: the page is no API, and an endless stream is no operation a client or a
fuzzer can call and validate; the stream's payload has its JSON Schema in service/viewer/event.schema.json.
"""

from __future__ import annotations

from fastapi import APIRouter, Depends, Header
from fastapi.responses import JSONResponse, Response, StreamingResponse
from golfflight.flight.engine import FlightEngine
from golfflight.service.api.state import ServiceState, ready_engine, service_state
from golfflight.service.viewer.feed import TooManyViewers
from golfflight.service.viewer.page import ASSETS, PAGE_PATH, SECURITY_HEADERS
from golfflight.service.viewer.stream import events, last_event_id

EVENTS_PATH = "/v1/events"

router = APIRouter(include_in_schema=False)


def _asset(name: str) -> Response:
    content, media_type = ASSETS[name]
    return Response(content, media_type=media_type, headers=SECURITY_HEADERS)


@router.get(PAGE_PATH)
async def page() -> Response:
    """The viewer (no key needed: it asks for one when the event stream wants it)."""
    return _asset("viewer.html")


@router.get(PAGE_PATH + "/{name}")
async def asset(name: str) -> Response:
    """The page's script or style; any other name is 404 (no file a client names is read)."""
    if name not in ASSETS or name == "viewer.html":
        return JSONResponse({"detail": "not found"}, 404)
    return _asset(name)


@router.get(EVENTS_PATH)
async def shot_events(
    engine: FlightEngine = Depends(ready_engine),
    state: ServiceState = Depends(service_state),
    last_event: str | None = Header(None, alias="last-event-id"),
) -> Response:
    """Every shot flown from now on (and the kept ones, or those after Last-Event-ID) as server-sent events."""
    try:
        viewer = state.feed.subscribe(last_event_id(last_event))
    except TooManyViewers as error:
        return JSONResponse({"detail": f"{error}: close one and try again"}, 503)
    headers = {"cache-control": "no-store", "x-accel-buffering": "no"}
    return StreamingResponse(events(state.feed, viewer, engine), media_type="text/event-stream", headers=headers)
