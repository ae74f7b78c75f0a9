"""The payload of the viewer's event stream (`GET /v1/events`): one `ShotEvent` per shot (`event: shot`), and the
session the screens show (`event: session`, a `contract.session.SessionInfo`: first on every stream and whenever a new
session starts, when a screen empties), as JSON.

The JSON Schema beside this file (event.schema.json) is generated from these models by
`python -m golfflight.service.viewer`; a test keeps it current. The stream is left out of the OpenAPI document (an
endless response is no operation a client or a fuzzer can call and validate), so this schema is its contract.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

from golfflight.contract.bay import Player
from golfflight.contract.requests import AirRequest, GroundRequest, WindRequest
from golfflight.contract.results import ShotResult
from golfflight.contract.session import SessionInfo
from golfflight.service.runtime.feed import Source
from pydantic import BaseModel, Field, TypeAdapter

SCHEMA_PATH = Path(__file__).with_name("event.schema.json")


class LaunchNumbers(BaseModel):
    """The launch as flown, SI (whichever units the client sent)."""

    ball_speed_mps: float
    launch_angle_deg: float = Field(description="vertical, + = up")
    launch_direction_deg: float = Field(description="horizontal, + = right")
    spin_rpm: float = Field(description="total spin")
    spin_axis_deg: float = Field(description="+ = tilted right: the ball curves right")


class ShotEvent(BaseModel):
    """One shot for the viewer: its launch and the flight result answered, with the trajectory of that very flight
    (its states resampled for drawing, at most `frames.MAX_POINTS` points, passing exactly through the landing, each
    impact and the rest), and what it was flown in and with."""

    id: int = Field(ge=1, description="rising per service process; the event's SSE id (Last-Event-ID resumes after it)")
    source: Source
    received_unix_s: float = Field(description="when the shot arrived, seconds since 1970 (UTC)")
    shot_number: int | None = Field(None, description="the connector's ShotNumber (GSPro Open Connect)")
    session_shot: int | None = Field(None, ge=1, description="the shot's number in its session, from 1: what the "
                                     "screens number it (`id` runs on across sessions)")
    launch: LaunchNumbers
    flight: ShotResult = Field(description="the flight result the client got back (a /v1/shots result), its "
                               "trajectory the states it was computed from, through the bounces and roll to rest")
    player: Player | None = Field(None, description="who was at the mat: the bay's club and hand when the shot was "
                                  "flown (the bay's own shots: HTTP single shots, GSPro over HTTP and TCP)")
    putt: bool = Field(False, description="rolled on the ground from the start (the putter was selected)")
    club_data: dict[str, float | int | str | bool | None] | None = Field(
        None, description="the connector's ClubData as sent (GSPro Open Connect: Speed, AngleOfAttack, FaceToTarget, "
        "Lie, Loft, Path, SpeedAtImpact, VerticalFaceImpact, HorizontalFaceImpact, ClosureRate), not used by the flight"
    )
    air: AirRequest | None = Field(None, description="the air it flew in (none: ICAO standard air)")
    wind: WindRequest | None = Field(None, description="the wind it flew in (none: calm)")
    ground: GroundRequest | None = Field(None, description="the ground it came down, bounced and rolled on (none: a "
                                         "level fairway at the tee's height)")


ViewerEvent = Annotated[
    ShotEvent | SessionInfo,
    Field(description="An event of GET /v1/events: `event: shot` carries a ShotEvent, `event: session` a SessionInfo "
          "(the session the screens show: first on every stream, and again when a new session starts and the screens "
          "empty)."),
]


def schema_text() -> str:
    """The events' JSON Schema as written to SCHEMA_PATH."""
    schema = {"title": "ViewerEvent", **TypeAdapter(ViewerEvent).json_schema()}
    return json.dumps(schema, indent=2, sort_keys=True) + "\n"
