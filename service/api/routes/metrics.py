"""GET /metrics: the service's Prometheus metrics in the text exposition format (`service.runtime.metrics`), behind the
API key like every route but /healthz. Answered while the model loads too (the model's info metric appears once it
is loaded): a scrape should tell a loading server from a dead one."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import PlainTextResponse, Response
from golfflight.service.api.routes.responses import ERROR_RESPONSES
from golfflight.service.runtime import runtime_of
from golfflight.service.runtime.metrics import CONTENT_TYPE

METRICS_PATH = "/metrics"

router = APIRouter()


@router.get(METRICS_PATH, response_class=PlainTextResponse, responses={401: ERROR_RESPONSES[401]})
async def metrics(http: Request) -> Response:
    """Requests and errors by route, request and simulation latency histograms, shots per batch and the model's
    variant and hash (`golfflight_model_info`), summed over every worker of the server."""
    return Response(runtime_of(http).metrics(), media_type=CONTENT_TYPE)
