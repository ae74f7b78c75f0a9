"""The direct path for the simulation routes' usual request: a body sent as `application/json` that validates, with a
query of true/false flags at most, goes from the app's own middleware (metrics, body limit, API key, CORS) straight
to the endpoint. Any other request (a body that is refused, another content type, another query) goes on through
FastAPI's exception handling, router and request handling as before, so every refusal and the OpenAPI document stay
FastAPI's; a failure of ours on the direct path (the model not yet loaded, a shot that cannot land) is answered as
FastAPI's handler answers it (`errors.failure_response`).

Per single shot, FastAPI's request handling (body reading, a `json.loads`, the dependency solver) and the layers
around a route (exception middleware, exit stacks, the router) cost about as much as all of the service's other
work beside the flight (`docs/benchmarks.md`, issue 25). A route opts in by its class (`DirectRoute`);
`DirectLanes` is the innermost of the app's middleware and serves those routes' direct requests. A `RawBodyRoute`
(the batch route) hands its body over unparsed: its endpoint has it read and validated off the event loop.

Extending a router of DirectRoutes (`routes/shots.py`, `routes/gspro.py`) works as in any FastAPI app: a route that
takes more than one body model, the `Request` and bool query flags (a `Depends`, such as `dependencies.bay_runtime`
for the bay runtime, a path, header or cookie parameter, another query type, no body) is served by FastAPI's own
path, its dependencies solved there, and costs what the direct path saves; only the shipped simulation routes need
the direct path (`tests/test_direct_route.py` holds them on it). A direct endpoint reaches the runtime with
`service.runtime.runtime_of(http)`, a plain attribute read.
"""

from __future__ import annotations

from collections.abc import Iterable
from email.message import Message
from typing import Any
from urllib.parse import parse_qsl

from fastapi.routing import APIRoute
from golfflight.contract.refusals import listed_errors
from golfflight.errors import GolfflightError
from golfflight.service.api.errors import failure_response
from golfflight.service.api.request_body import read_body, replay
from pydantic import BaseModel, TypeAdapter, ValidationError
from starlette.requests import Request
from starlette.responses import JSONResponse, Response

FLAG_SPELLINGS = {b"true": True, b"false": False, b"1": True, b"0": False}
"""Spellings of a boolean query flag taken on the direct path; any other spelling goes through FastAPI's own
reading of it (which takes more and refuses the rest with a 422)."""

JSON = b"application/json"

FLAG = TypeAdapter(bool)
"""A query flag read as FastAPI reads one (lax: true/false, 1/0, yes/no, on/off, t/f, y/n, any case)."""


class DirectRoute(APIRoute):
    """An APIRoute whose valid requests `DirectLanes` hands straight to the endpoint when the endpoint is `async def`,
    returns a `Response` and takes one body model, the `Request` and boolean query flags, nothing else (`direct_path`
    True). Any other endpoint (dependencies, path, header or cookie parameters: what only FastAPI's path solves) is
    an ordinary APIRoute, `direct_path` False: FastAPI answers all its requests."""

    def __init__(self, path: str, endpoint: Any, **kwargs: Any):
        super().__init__(path, endpoint, **kwargs)
        dependant = self.dependant
        unsupported = [
            *dependant.dependencies, *dependant.path_params, *dependant.header_params, *dependant.cookie_params
        ] + [flag for flag in dependant.query_params if flag.field_info.annotation is not bool]
        self.direct_path = not unsupported and self.body_field is not None and dependant.request_param_name is not None
        if not self.direct_path:
            return
        self.body_model: type[BaseModel] = self.body_field.field_info.annotation
        self._names = self.body_field.name, dependant.request_param_name
        self._flags = {flag.alias.encode(): (flag.name, flag.field_info.default) for flag in dependant.query_params}

    def flags(self, query: bytes) -> dict[str, bool] | None:
        """The flags of a query such as `viewer=true`, defaults for the rest; None for anything else."""
        values = {name: default for name, default in self._flags.values()}
        for pair in query.split(b"&") if query else ():
            key, _, value = pair.partition(b"=")
            if key not in self._flags or value not in FLAG_SPELLINGS:
                return None
            values[self._flags[key][0]] = FLAG_SPELLINGS[value]
        return values

    async def direct(self, request: Request, body: bytes) -> Response | None:
        """The endpoint's response to a request with this body, or None when FastAPI's path must answer it."""
        flags = self.flags(request.scope["query_string"])
        if flags is None or _content_type(request.scope["headers"]) != JSON:
            return None
        try:
            model = self.body_model.model_validate_json(body)
        except ValidationError:
            return None  # FastAPI reads it again and refuses it in its own words
        return await self._answer(request, model, flags)

    async def _answer(self, request: Request, model: BaseModel | None, flags: dict[str, bool]) -> Response:
        body_name, request_name = self._names
        response = await self.endpoint(**{body_name: model, request_name: request}, **flags)
        if not isinstance(response, Response):
            raise TypeError(f"{self.path}: a DirectRoute endpoint returns a Response, not {type(response)}")
        return response


class RawBodyRoute(DirectRoute):
    """A DirectRoute whose endpoint reads and validates the raw body itself, elsewhere (`Request.body()`: a batch,
    in the batch process, off the event loop; issue 55). Its direct path takes every non-empty body FastAPI would
    read as JSON, unparsed (the body model None), with its flags read as FastAPI reads them, so that FastAPI's path,
    which parses and validates on the event loop, answers only a body refused unread (none, another content type)."""

    async def direct(self, request: Request, body: bytes) -> Response | None:
        """The endpoint's response to any JSON body; a 422 for a flag FastAPI would refuse; None (FastAPI's path)
        for no body or a body FastAPI would not read as JSON."""
        if not body or not _read_as_json(request.headers.get("content-type")):
            return None
        flags = {name: default for name, default in self._flags.values()}
        problems = []
        for key, value in parse_qsl(request.scope["query_string"].decode("latin-1"), keep_blank_values=True):
            if key.encode() in self._flags:
                try:
                    flags[self._flags[key.encode()][0]] = FLAG.validate_python(value)
                except ValidationError as error:
                    problems += [{**problem, "loc": ("query", key)} for problem in error.errors(include_url=False)]
        if problems:
            return JSONResponse({"detail": listed_errors(problems)}, 422)
        return await self._answer(request, None, flags)


class DirectLanes:
    """Pure ASGI, the innermost of the app's middleware: a request to one of `routes` (by method and exact path) is
    read whole and tried on its route's direct path; what that path leaves is passed on, its body replayed."""

    def __init__(self, app, routes: Iterable[APIRoute]):
        self.app = app
        direct = [route for route in routes if isinstance(route, DirectRoute) and route.direct_path]
        self.lanes = {(method, route.path): route for route in direct for method in route.methods}

    async def __call__(self, scope, receive, send):
        route = self.lanes.get((scope["method"], scope["path"])) if scope["type"] == "http" else None
        if route is None:
            await self.app(scope, receive, send)
            return
        messages, body = await read_body(receive)  # within the body limit: its middleware is outside this one
        scope["route"] = route  # as the router would set it: the metrics label the request by its template
        try:
            response = await route.direct(Request(scope, replay(messages, receive)), body)
        except GolfflightError as error:
            response = failure_response(scope["path"], error)
        if response is not None:
            await response(scope, receive, send)
            return
        await self.app(scope, replay(messages, receive), send)


def _read_as_json(content_type: str | None) -> bool:
    """Whether FastAPI reads a body sent with this content type as JSON: application/json or application/*+json,
    with any parameters."""
    if not content_type:
        return False
    message = Message()
    message["content-type"] = content_type
    subtype = message.get_content_subtype()
    return message.get_content_maintype() == "application" and (subtype == "json" or subtype.endswith("+json"))


def _content_type(headers: list[tuple[bytes, bytes]]) -> bytes | None:
    for name, value in headers:
        if name == b"content-type":
            return value.lower()
    return None
