"""A route whose usual request skips FastAPI's request machinery: a body sent as `application/json` that validates,
read once from its bytes by pydantic-core (`model_validate_json`), with a query of true/false flags at most, goes
straight to the endpoint. Any other request (a body that is refused, another content type, another query) takes
FastAPI's own path, so every refusal, and the OpenAPI document, stay FastAPI's.

FastAPI's path per request (its body reading, a `json.loads`, the dependency solver, endpoint introspection) was
about a third of the app's own time for a single shot (`docs/benchmarks.md`, issue 25).
"""

from __future__ import annotations

from collections.abc import Callable, Coroutine
from typing import Any

from fastapi.routing import APIRoute
from pydantic import BaseModel, ValidationError
from starlette.requests import Request
from starlette.responses import Response

FLAG_SPELLINGS = {b"true": True, b"false": False, b"1": True, b"0": False}
"""Spellings of a boolean query flag taken on the direct path; any other spelling goes through FastAPI's own
reading of it (which takes more and refuses the rest with a 422)."""

JSON = b"application/json"


class DirectRoute(APIRoute):
    """An APIRoute for an `async def` endpoint that returns a `Response` and whose parameters are one body model, the
    `Request` and boolean query flags, nothing else (no dependencies, path, header or cookie parameters: those only
    FastAPI's path solves)."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        full = super().get_route_handler()
        dependant = self.dependant
        unsupported = [
            *dependant.dependencies, *dependant.path_params, *dependant.header_params, *dependant.cookie_params
        ] + [flag for flag in dependant.query_params if flag.field_info.annotation is not bool]
        if unsupported or self.body_field is None or dependant.request_param_name is None:
            raise TypeError(f"{self.path}: DirectRoute takes one body model, the Request and bool query flags only")
        model: type[BaseModel] = self.body_field.field_info.annotation
        body_name, request_name = self.body_field.name, dependant.request_param_name
        flags = {flag.alias.encode(): (flag.name, flag.field_info.default) for flag in dependant.query_params}
        defaults = {name: default for name, default in flags.values()}
        endpoint = self.endpoint

        def query_flags(query: bytes) -> dict[str, bool] | None:
            """The flags of a query such as `viewer=true`; None for anything else (FastAPI reads that one)."""
            values = dict(defaults)
            for pair in query.split(b"&") if query else ():
                key, _, value = pair.partition(b"=")
                if key not in flags or value not in FLAG_SPELLINGS:
                    return None
                values[flags[key][0]] = FLAG_SPELLINGS[value]
            return values

        async def handler(request: Request) -> Response:
            scope = request.scope
            values = query_flags(scope["query_string"])
            if values is None or _content_type(scope["headers"]) != JSON:
                return await full(request)
            try:
                body = model.model_validate_json(await request.body())
            except ValidationError:
                return await full(request)  # FastAPI reads it again and refuses it in its own words
            response = await endpoint(**{body_name: body, request_name: request}, **values)
            if not isinstance(response, Response):
                raise TypeError(f"{self.path}: a DirectRoute endpoint returns a Response, not {type(response)}")
            return response

        return handler


def _content_type(headers: list[tuple[bytes, bytes]]) -> bytes | None:
    for name, value in headers:
        if name == b"content-type":
            return value.lower()
    return None
