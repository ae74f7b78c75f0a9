"""A batch request's raw body read and validated as the HTTP app reads any body, refusing it in the app's own words:
the batch process runs this, so that a large body is parsed and checked off the server's event loop (issue 55)."""

from __future__ import annotations

import json

from golfflight.contract.refusals import (
    NESTED_TOO_DEEPLY,
    NOT_JSON,
    RequestRefused,
    body_detail,
    listed_errors,
    not_json,
)
from golfflight.contract.requests import BatchRequest
from pydantic import ValidationError


def read_batch(body: bytes) -> BatchRequest:
    """The BatchRequest a non-empty body holds; RequestRefused with the 422 details FastAPI's path gives the same body
    (`json.loads`, then the model, each problem's `loc` starting with "body", at most LISTED_ERRORS listed).
    pydantic's own JSON reader goes first: it is the fast path for a valid body."""
    try:
        return BatchRequest.model_validate_json(body)
    except ValidationError:
        pass
    try:
        data = json.loads(body)
    except json.JSONDecodeError as error:
        raise RequestRefused([body_detail(not_json(error.msg, error.doc, error.pos), "json_invalid")]) from None
    except RecursionError:
        raise RequestRefused([body_detail(NESTED_TOO_DEEPLY, "json_invalid")]) from None
    except ValueError:  # not UTF-8, UTF-16 or UTF-32 text
        raise RequestRefused([body_detail(NOT_JSON, "json_invalid")]) from None
    try:
        return BatchRequest.model_validate(data)
    except ValidationError as error:
        problems = [{**problem, "loc": ("body", *problem["loc"])} for problem in error.errors(include_url=False)]
        raise RequestRefused(listed_errors(problems)) from None
