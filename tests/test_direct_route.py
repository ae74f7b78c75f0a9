"""`DirectRoute` and `DirectLanes`: a valid single shot, batch or GSPro message reaches its endpoint without FastAPI's
router and request handling, gets the same answer as through them, and everything else is still answered by FastAPI
(issue 25)."""

from __future__ import annotations

import json

import pytest
from fastapi import APIRouter, Depends, Header
from fastapi.routing import APIRoute
from golfflight.contract.gspro import GSProMessage
from golfflight.contract.requests import BatchRequest, ShotRequest
from golfflight.service.api.dependencies import bay_runtime
from golfflight.service.api.direct import DirectRoute
from golfflight.service.app import create_app
from golfflight.service.runtime import BayRuntime
from pydantic import ValidationError

from tests.servers import running

SHOT = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
JSON = {"content-type": "application/json"}


@pytest.fixture(scope="module")
def client():
    with running(create_app()) as http:
        yield http


@pytest.fixture
def fastapi_requests(monkeypatch) -> list[str]:
    """The paths of requests that FastAPI's router handed to a route (the direct path never reaches the router)."""
    seen: list[str] = []
    handle = APIRoute.handle

    async def counted(route, scope, receive, send):
        seen.append(scope["path"])
        return await handle(route, scope, receive, send)

    monkeypatch.setattr(APIRoute, "handle", counted)
    return seen


def test_valid_requests_reach_the_endpoint_directly_with_fastapis_answer(client, fastapi_requests):
    batch = {"shots": [SHOT, {**SHOT, "ball_speed_mps": 70.0}]}
    message = {"DeviceID": "t", "ShotNumber": 3, "BallData": {"Speed": 120.0, "VLA": 16.0, "TotalSpin": 7000.0}}
    sent = [("/v1/shots", SHOT), ("/v1/shots?viewer=false", SHOT), ("/v1/shots?viewer=true", SHOT),
            ("/v1/shots/batch", batch), ("/v1/gspro", message)]
    direct = [client.post(path, content=json.dumps(body), headers=JSON) for path, body in sent]
    assert [answer.status_code for answer in direct] == [200] * len(sent)
    assert fastapi_requests == []
    # The same bodies under a content type the direct path leaves to FastAPI: the same answers, through FastAPI,
    # but for the batch, which the batch process reads under any JSON content type (issue 55).
    charset = {"content-type": "application/json; charset=utf-8"}
    through = [client.post(path, content=json.dumps(body), headers=charset) for path, body in sent]
    assert fastapi_requests == [path.partition("?")[0] for path, _ in sent if path != "/v1/shots/batch"]
    assert [answer.json() for answer in through] == [answer.json() for answer in direct]


def test_anything_else_is_answered_by_fastapi(client, fastapi_requests):
    refused = client.post("/v1/shots", content=json.dumps({**SHOT, "spin_rpm": -1.0}), headers=JSON)
    assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == ["body", "spin_rpm"]
    flag = client.post("/v1/shots?viewer=maybe", content=json.dumps(SHOT), headers=JSON)
    assert flag.status_code == 422 and flag.json()["detail"][0]["loc"] == ["query", "viewer"]
    spelled = client.post("/v1/shots?viewer=yes", content=json.dumps(SHOT), headers=JSON)
    assert spelled.status_code == 200
    broken = client.post("/v1/shots/batch", content=b'{"shots": [', headers=JSON)
    assert broken.status_code == 422
    plain = {"content-type": "text/plain"}
    unread = client.post("/v1/shots/batch", content=json.dumps({"shots": [SHOT]}), headers=plain)
    assert unread.status_code == 415
    assert fastapi_requests == ["/v1/shots", "/v1/shots", "/v1/shots", "/v1/shots/batch"]


ODD_BODIES = [
    '{"ball_speed_mps": NaN, "launch_angle_deg": 16, "spin_rpm": 7100}',
    '{"ball_speed_mps": Infinity, "launch_angle_deg": 16, "spin_rpm": 7100}',
    '{"ball_speed_mps": 1e400, "launch_angle_deg": 16, "spin_rpm": 7100}',
    '{"ball_speed_mps": "55", "launch_angle_deg": 16, "spin_rpm": 7100}',
    '{"ball_speed_mps": true, "launch_angle_deg": 16, "spin_rpm": 7100}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "spin_rpm": 3000}',
    '{"ball_speed_mps": 55, "launch_angle_deg": -0.0, "spin_rpm": 7100, "unknown": [1, {"a": null}]}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "trajectory": {}}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "trajectory": {"rate_hz": "30"}}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "wind": {"speed_mps": 3, "from_deg": 90}}',
    '{"ball_speed_mph": 120.5, "launch_angle_deg": 16, "spin_rpm": 7100, "ground": {"surface": "fairway"}}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "air": {"temperature_c": "\\u0031\\u0035"}}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "normalized": true}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "normalized": "true"}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100, "normalized": 1}',
    '{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100}  ',
    "[]",
    "55",
    '"text"',
]


@pytest.mark.parametrize("model", [ShotRequest, BatchRequest, GSProMessage])
@pytest.mark.parametrize("text", ODD_BODIES)
def test_reading_the_bytes_accepts_nothing_fastapi_refuses_nor_reads_it_otherwise(model, text):
    """The direct path reads a body with `model_validate_json`; FastAPI's path with `json.loads`, then validates
    the Python value. Whatever the first accepts, the second accepts too, as the same request."""
    if model is BatchRequest:
        text = f'{{"shots": [{text}]}}'
    elif model is GSProMessage:
        text = f'{{"ShotNumber": 1, "BallData": {text.replace("ball_speed_mps", "Speed")}}}'
    try:
        direct = model.model_validate_json(text)
    except ValidationError:
        return  # refused on the direct path: FastAPI's path answers it
    assert model.model_validate(json.loads(text)) == direct


def test_a_newcomers_route_with_depends_is_served_by_fastapi_beside_the_direct_ones(fastapi_requests):
    """A route added to a router of DirectRoutes, as `routes/shots.py` builds them, with a `Depends` (the bay
    runtime), a path and a header parameter: FastAPI solves and answers it, on a real server, while the shipped
    routes stay on the direct path."""
    router = APIRouter(prefix="/v1/extra", route_class=DirectRoute)

    @router.post("/carry/{unit}")
    async def carry(request: ShotRequest, unit: str, runtime: BayRuntime = Depends(bay_runtime),
                    player: str = Header("guest")) -> dict:
        flown = runtime.fly(request, "http", show=False, client=None).result
        return {"carry": flown.carry_m if unit == "m" else flown.carry_m / 0.9144, "player": player}

    app = create_app()
    app.include_router(router)
    with running(app) as client:
        extended = client.post("/v1/extra/carry/yd", content=json.dumps(SHOT), headers={**JSON, "player": "ana"})
        shot = client.post("/v1/shots", content=json.dumps(SHOT), headers=JSON)
        refused = client.post("/v1/extra/carry/yd", content=json.dumps({**SHOT, "spin_rpm": -1.0}), headers=JSON)
    assert extended.status_code == 200 and shot.status_code == 200
    assert extended.json() == {"carry": pytest.approx(shot.json()["carry_m"] / 0.9144), "player": "ana"}
    assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == ["body", "spin_rpm"]
    assert [path for path in fastapi_requests if path != "/healthz"] == ["/v1/extra/carry/yd"] * 2  # not /v1/shots
    assert [route.direct_path for route in router.routes] == [False]
