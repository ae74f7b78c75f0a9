"""GET /v1/bay (the bay's conditions) and PUT /v1/bay (replace them, kept in the bay file): what Open Connect shots
and HTTP shots without conditions of their own fly in (`service.api.bay`). Guarded by the API key when one is set,
validated by the same limits as a shot's conditions."""

from __future__ import annotations

from fastapi import APIRouter, Depends
from fastapi.responses import JSONResponse, Response
from golfflight.contract.bay import BayConditions
from golfflight.contract.refusals import body_detail
from golfflight.service.api.routes.responses import ERROR_RESPONSES, json_response
from golfflight.service.api.state import ServiceState, service_state

BAY_PATH = "/v1/bay"

router = APIRouter()
_responses = {k: v for k, v in ERROR_RESPONSES.items() if k != 503}


@router.get(BAY_PATH, response_model=BayConditions, response_model_exclude_none=True, responses=_responses)
async def get_bay(state: ServiceState = Depends(service_state)) -> Response:
    """The bay's air, wind, ground and display units."""
    return json_response(state.bay.conditions)


@router.put(BAY_PATH, response_model=BayConditions, response_model_exclude_none=True,
            responses={500: {"description": "the bay file could not be written; the bay is unchanged"}, **_responses})
async def put_bay(conditions: BayConditions, state: ServiceState = Depends(service_state)) -> Response:
    """Replace the bay's conditions (the whole object: an omitted field goes back to its default); written to the
    bay file first, so a failed write changes nothing."""
    try:
        return json_response(state.bay.set(conditions))
    except OSError as error:
        return JSONResponse({"detail": [body_detail(f"the bay file could not be written: {error}", "bay_file")]}, 500)
