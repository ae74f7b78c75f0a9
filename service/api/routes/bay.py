"""GET /v1/bay (the bay's conditions and player), PUT /v1/bay (replace them) and PATCH /v1/bay (change the parts
named), kept in the bay file: what Open Connect shots and HTTP shots without conditions of their own fly in, and
who plays (`service.runtime.bay`; a change of player reaches every connector as Code 201). Guarded by the API key
when one is set, validated by the same limits as a shot's conditions."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse, Response
from golfflight.contract.bay import BayConditions, BayUpdate
from golfflight.contract.refusals import body_detail
from golfflight.service.api.routes.responses import ERROR_RESPONSES, json_response
from golfflight.service.runtime import runtime_of

BAY_PATH = "/v1/bay"

router = APIRouter()
_responses = {k: v for k, v in ERROR_RESPONSES.items() if k != 503}
_write_failed = {500: {"description": "the bay file could not be written; the bay is unchanged"}}


def _not_written(error: OSError) -> JSONResponse:
    return JSONResponse({"detail": [body_detail(f"the bay file could not be written: {error}", "bay_file")]}, 500)


@router.get(BAY_PATH, response_model=BayConditions, response_model_exclude_none=True, responses=_responses)
async def get_bay(http: Request) -> Response:
    """The bay's air, wind, ground, player and display units."""
    return json_response(runtime_of(http).bay())


@router.put(BAY_PATH, response_model=BayConditions, response_model_exclude_none=True,
            responses={**_write_failed, **_responses})
async def put_bay(conditions: BayConditions, http: Request) -> Response:
    """Replace the bay's conditions (the whole object: an omitted field goes back to its default); written to the
    bay file first, so a failed write changes nothing. Repairs a bay file broken or removed while serving."""
    try:
        return json_response(runtime_of(http).set_bay(conditions))
    except OSError as error:
        return _not_written(error)


@router.patch(BAY_PATH, response_model=BayConditions, response_model_exclude_none=True,
              responses={**_write_failed, **_responses})
async def patch_bay(update: BayUpdate, http: Request) -> Response:
    """Change the parts named and leave the rest: `{"units": "metric"}`, `{"player": {"club": "PT"}}`,
    `{"wind": null}` (calm); a part given replaces that part whole (air, wind, ground), the player's fields merge.
    Written to the bay file first, as PUT."""
    try:
        return json_response(runtime_of(http).update_bay(update.applied_to))
    except OSError as error:
        return _not_written(error)
