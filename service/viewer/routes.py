"""GET /viewer (the live shot viewer page, its scripts and style), GET /v1/events (its server-sent event stream) and
the sessions' routes (`sessions`: start one, list them, a session's CSV and summary): the viewer's adapter on the bay
runtime, mounted by the service's assembly (`service.app`).

The page and the stream are left out of the OpenAPI document: the page is no API, and an endless stream is no
operation a client or a fuzzer can call and validate; the stream's payload has its JSON Schema in
service/viewer/event.schema.json.
"""

from __future__ import annotations

from fastapi import APIRouter, Header, Request
from fastapi.responses import JSONResponse, Response, StreamingResponse
from golfflight.service.runtime import runtime_of
from golfflight.service.viewer import sessions
from golfflight.service.viewer.page import ASSETS, PAGE_PATH, SECURITY_HEADERS
from golfflight.service.viewer.stream import events, last_event_id

EVENTS_PATH = "/v1/events"

router = APIRouter()

ROUTERS = (router, sessions.router)
"""The viewer's routers, for the service's assembly to mount."""


def _asset(name: str) -> Response:
    content, media_type = ASSETS[name]
    return Response(content, media_type=media_type, headers=SECURITY_HEADERS)


@router.get(PAGE_PATH, include_in_schema=False)
async def page() -> Response:
    """The viewer (no key needed: it asks for one when the event stream wants it)."""
    return _asset("viewer.html")


@router.get(PAGE_PATH + "/{name}", include_in_schema=False)
async def asset(name: str) -> Response:
    """The page's script or style; any other name is 404 (no file a client names is read)."""
    if name not in ASSETS or name == "viewer.html":
        return JSONResponse({"detail": "not found"}, 404)
    return _asset(name)


@router.get(EVENTS_PATH, include_in_schema=False)
async def shot_events(request: Request, last_event: str | None = Header(None, alias="last-event-id")) -> Response:
    """The current session, then every shot flown from now on (and its kept ones, or those after Last-Event-ID) as
    server-sent events; a new session is announced as it starts."""
    runtime = runtime_of(request)
    client = request.client.host if request.client else ""
    viewer = runtime.subscribe(last_event_id(last_event), client)  # NotReady: 503 (contract.refusals)
    headers = {"cache-control": "no-store", "x-accel-buffering": "no"}
    return StreamingResponse(events(runtime, viewer), media_type="text/event-stream", headers=headers)
