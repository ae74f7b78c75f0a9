"""Responses the routers share: a pydantic model as JSON, and the error statuses every simulation route documents."""

from __future__ import annotations

from golfflight.service.api.guards import MAX_BODY_BYTES
from pydantic import BaseModel
from starlette.responses import Response


def json_response(model: BaseModel, status_code: int = 200) -> Response:
    """A model's JSON without its unset (None) fields."""
    return Response(model.model_dump_json(exclude_none=True), status_code, media_type="application/json")


ERROR_RESPONSES = {
    401: {"description": "the API key is required and was missing or wrong"},
    413: {"description": f"request body over {MAX_BODY_BYTES:,} bytes"},
    503: {"description": "the model is still loading, or failed to load (see /healthz)"},
}
