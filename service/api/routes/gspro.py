"""POST /v1/gspro: a GSPro Open Connect v1 message over HTTP, answered as over TCP (`BayRuntime.fly_gspro`)."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import Response
from golfflight.contract.gspro import GSProMessage, GSProReply
from golfflight.contract.refusals import FAILURES
from golfflight.service.api.client_address import client_address
from golfflight.service.api.direct import DirectRoute
from golfflight.service.api.paths import GSPRO_PATH
from golfflight.service.api.routes.responses import ERROR_RESPONSES, json_response
from golfflight.service.runtime import runtime_of

GSPRO_STATUS = {200: 200, **{answer.open_connect_code: answer.http_status for answer in FAILURES.values()}}
"""HTTP status of each Open Connect reply code on POST /v1/gspro: 200 for a flight, else the failure's own
(`contract.refusals.FAILURES`: Code 500 is 422, Code 503 is 503)."""

router = APIRouter(route_class=DirectRoute)


@router.post(
    GSPRO_PATH,
    response_model=GSProReply,
    response_model_exclude_none=True,
    responses={
        422: {"model": GSProReply, "description": "an invalid message or a failed flight: Open Connect's Code 500"},
        **ERROR_RESPONSES,
    },
)
async def gspro(message: GSProMessage, http: Request) -> Response:
    """A GSPro Open Connect v1 message: a shot gets its flight with Code 200, a heartbeat just Code 200; an
    invalid message or a failed flight gets HTTP 422 with Open Connect's error reply (Code 500, a Message)."""
    if message.is_heartbeat:
        return json_response(GSProReply(Code=200, Message="heartbeat received"))
    if message.BallData is None:
        nothing = GSProReply(Code=200, Message="no ball data: nothing to fly", ShotNumber=message.ShotNumber)
        return json_response(nothing)
    reply = runtime_of(http).fly_gspro(message, client=client_address(http))
    return json_response(reply, GSPRO_STATUS[reply.Code])
