"""The bay's sessions over HTTP: POST /v1/sessions (start one: the screens empty), GET /v1/sessions (those kept, with
their shots), GET /v1/session.csv (a session's shots in `golfflight simulate`'s columns) and GET /v1/session/summary
(its clubs: count, mean and spread, carry gaps, dispersion ellipses). The current session without `?session=ID`.
Sessions and their bounds are the runtime's (`service.runtime.sessions`); the models are `contract.session`.
"""

from __future__ import annotations

from collections.abc import AsyncIterator

from fastapi import APIRouter, Query, Request
from fastapi.responses import JSONResponse, Response, StreamingResponse
from golfflight.contract.session import NewSession, SessionInfo, SessionList, SessionSummary
from golfflight.service.runtime import runtime_of
from golfflight.service.runtime.sessions import Session
from golfflight.service.viewer.loop_turns import LoopTurns
from golfflight.service.viewer.session_csv import session_csv_slices

SESSIONS_PATH = "/v1/sessions"
SESSION_PATH = "/v1/session.csv"
SUMMARY_PATH = "/v1/session/summary"

router = APIRouter()

_NOT_KEPT = {404: {"description": "no such session is kept (ids restart with the service; the oldest are forgotten)"}}
_ERRORS = {401: {"description": "the API key is required and was missing or wrong"}}

SessionId = Query(None, ge=1, description="a session's id (GET /v1/sessions); the current session without one")


def _json(model, status_code: int = 200) -> Response:
    return Response(model.model_dump_json(exclude_none=True), status_code, media_type="application/json")


def _session(request: Request, session_id: int | None) -> Session | JSONResponse:
    """The session asked for (the current one without an id), or the 404 that says it is not kept."""
    found = runtime_of(request).session(session_id)
    if found is None:
        return JSONResponse({"detail": f"session {session_id} is not kept: GET {SESSIONS_PATH} lists those that are"},
                            404)
    return found


@router.post(SESSIONS_PATH, status_code=201, response_model=SessionInfo, response_model_exclude_none=True,
             responses=_ERRORS)
async def new_session(request: Request, new: NewSession | None = None) -> Response:
    """Start a new session, the player's name optional: the bay's shots go to it from now on, and every screen of
    the bay empties (its shot list, paths, dispersion and summary); the sessions before it stay listed."""
    session = runtime_of(request).start_session(None if new is None else new.player)
    return _json(session.info(current=True), 201)


@router.get(SESSIONS_PATH, response_model=SessionList, response_model_exclude_none=True, responses=_ERRORS)
async def sessions(request: Request) -> Response:
    """The sessions kept, oldest first, each with its shots kept, and the caps."""
    return _json(runtime_of(request).sessions())


@router.get(SUMMARY_PATH, response_model=SessionSummary, response_model_exclude_none=True,
            responses={**_NOT_KEPT, **_ERRORS})
async def summary(request: Request, session: int | None = SessionId) -> Response:
    """A session's clubs in the bag's order: shots, mean and sample standard deviation of carry, total, apex and
    lateral (metres), the carry gap to the next shorter club, and the 95 % ellipses of landing and rest points."""
    found = _session(request, session)
    if isinstance(found, Response):
        return found
    return _json(runtime_of(request).session_summary(found))


@router.get(SESSION_PATH, response_class=Response,
            responses={200: {"content": {"text/csv": {}}}, **_NOT_KEPT, **_ERRORS})
async def session_csv(request: Request, session: int | None = SessionId) -> Response:
    """A session's shots (the shots the bay's screens were sent in it, at most the service's 10,000 over all
    sessions) as CSV in `golfflight simulate`'s columns: launch and conditions in, the result out, with the shot's
    id, time, session, player, source, club and putt; simulate flies it again to the same carries. Streamed from a
    snapshot in short slices (`session_csv_slices`): shots keep flying meanwhile."""
    found = _session(request, session)
    if isinstance(found, Response):
        return found
    snapshot = list(found.shots)
    name = f"golfflight-session-{found.id}.csv"
    headers = {"content-disposition": f'attachment; filename="{name}"', "cache-control": "no-store"}
    text = _until_gone(request, session_csv_slices(snapshot, player=found.player, turns=_csv_turns(request)))
    return StreamingResponse(text, media_type="text/csv; charset=utf-8", headers=headers)


def _csv_turns(request: Request) -> LoopTurns:
    """The turns every download of the service's CSV shares (`session_csv_slices`)."""
    state = request.app.state
    if not hasattr(state, "csv_turns"):
        state.csv_turns = LoopTurns()
    return state.csv_turns


async def _until_gone(request: Request, pieces: AsyncIterator[str]) -> AsyncIterator[str]:
    """The text of `pieces` until the client has gone (uvicorn drops what is sent after): no CSV is made for
    nobody."""
    async for piece in pieces:
        if await request.is_disconnected():
            return
        if piece:
            yield piece
