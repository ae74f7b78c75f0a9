"""How refusals read: every 4xx body names the field, the value and the allowed range, and POST /v1/gspro answers
in Open Connect's own form (Code 500, a Message); a body that is not valid JSON is refused saying where and what the
decoder expected (FastAPI's own detail is its character position as the field: `"1: JSON decode error"`); a body
sent without a JSON content type gets 415 saying so (FastAPI hands a model the raw bytes then, which read as "Input
should be a valid dictionary"); a route called before the model is ready gets 503. A 422 lists at most
`contract.refusals.LISTED_ERRORS` problems and counts the rest."""

from __future__ import annotations

from fastapi import FastAPI, Request
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from golfflight.contract.gspro import GSProReply, invalid_message, shot_number_of
from golfflight.contract.refusals import (
    NESTED_TOO_DEEPLY,
    NOT_JSON,
    RequestRefused,
    answer_to,
    body_detail,
    failure_detail,
    listed_errors,
    not_json,
)
from golfflight.contract.requests import RANGES
from golfflight.errors import GolfflightError
from golfflight.service.api.paths import GSPRO_PATH
from starlette.exceptions import HTTPException as StarletteHTTPException

JSON_CONTENT_TYPE = "the body must be JSON: send content-type: application/json"
"""The refusal (415) of a body sent without a JSON content type, followed by what was sent."""


def _gspro_error(message: str, status: int = 422, shot_number: int | None = None, code: int = 500) -> JSONResponse:
    reply = GSProReply(Code=code, Message=message, ShotNumber=shot_number)
    return JSONResponse(reply.model_dump(exclude_none=True), status)


def _content_type_refusal(request: Request, error: RequestValidationError) -> str | None:
    """Why a body was not read at all: FastAPI parses a body as JSON only under a JSON content type (application/json
    or */*+json) and otherwise hands the model the raw bytes; None when the body was read."""
    if not isinstance(error.body, bytes | bytearray):
        return None
    sent = request.headers.get("content-type")
    return f"{JSON_CONTENT_TYPE} ({f'got {sent!r}' if sent else 'none was sent'})"


def _json_refusal(error: RequestValidationError) -> str | None:
    """Why the body is not valid JSON (`not_json`: line, column and what was expected), from FastAPI's one
    `json_invalid` error (loc ("body", character position), the decoder's reason in ctx, the text as the error's
    body); None when the body parsed."""
    for detail in error.errors():
        if detail["type"] == "json_invalid" and isinstance(error.body, str) and len(detail["loc"]) == 2:
            return not_json(detail.get("ctx", {}).get("error", detail["msg"]), error.body, detail["loc"][1])
    return None


async def invalid_request(request: Request, error: RequestValidationError) -> JSONResponse:
    unread = _content_type_refusal(request, error)
    broken = _json_refusal(error)
    if request.url.path == GSPRO_PATH:
        if unread:
            return _gspro_error(unread, 415)
        return _gspro_error(broken or invalid_message(error.errors()), shot_number=shot_number_of(error.body))
    if unread:
        return JSONResponse({"detail": [body_detail(unread, "content_type")]}, 415)
    if broken:
        return JSONResponse({"detail": [body_detail(broken, "json_invalid")]}, 422)
    return JSONResponse({"detail": listed_errors(error.errors(), RANGES)}, 422)


async def http_error(request: Request, error: StarletteHTTPException) -> Response:
    if error.status_code != 400:
        return await http_exception_handler(request, error)
    message = NESTED_TOO_DEEPLY if isinstance(error.__cause__, RecursionError) else NOT_JSON
    if request.url.path == GSPRO_PATH:
        return _gspro_error(message)
    return JSONResponse({"detail": [body_detail(message, "json_invalid")]}, 422)


def failure_response(path: str, error: GolfflightError) -> JSONResponse:
    """The answer to one of our failures (`contract.refusals.FAILURES`): on POST /v1/gspro Open Connect's reply with
    its code; elsewhere a refusal's detail (4xx), or the reason alone when the service cannot answer now (503)."""
    answer = answer_to(error)
    if path == GSPRO_PATH:
        return _gspro_error(str(error), answer.http_status, code=answer.open_connect_code)
    if answer.http_status >= 500:
        return JSONResponse({"detail": str(error)}, answer.http_status)
    if isinstance(error, RequestRefused):
        return JSONResponse({"detail": error.details}, answer.http_status)
    return JSONResponse({"detail": [failure_detail(error, answer.kind)]}, answer.http_status)


async def failed(request: Request, error: GolfflightError) -> JSONResponse:
    return failure_response(request.url.path, error)


def install(app: FastAPI) -> None:
    """Register the handlers on an app."""
    app.add_exception_handler(RequestValidationError, invalid_request)
    app.add_exception_handler(StarletteHTTPException, http_error)
    app.add_exception_handler(GolfflightError, failed)
