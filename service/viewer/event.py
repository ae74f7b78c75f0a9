"""The payload of the viewer's event stream (`GET /v1/events`): one `ShotEvent` per shot, as JSON.

The JSON Schema beside this file (event.schema.json) is generated from these models by
`python -m golfflight.service.viewer`; a test keeps it current. The stream is left out of the OpenAPI document (an
endless response is no operation a client or a fuzzer can call and validate), so this schema is its contract.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

from golfflight.contract.results import ShotResult
from pydantic import BaseModel, Field

SCHEMA_PATH = Path(__file__).with_name("event.schema.json")

Source = Literal["http", "batch", "gspro-http", "open-connect"]
"""Where a shot came in: POST /v1/shots, POST /v1/shots/batch, POST /v1/gspro, GSPro Open Connect over TCP."""


class LaunchNumbers(BaseModel):
    """The launch as flown, SI (whichever units the client sent)."""

    ball_speed_mps: float
    launch_angle_deg: float = Field(description="vertical, + = up")
    launch_direction_deg: float = Field(description="horizontal, + = right")
    spin_rpm: float = Field(description="total spin")
    spin_axis_deg: float = Field(description="+ = tilted right: the ball curves right")


class ShotEvent(BaseModel):
    """One shot for the viewer: its launch and its flight result, the trajectory always included (resampled for
    drawing, at most `feed.MAX_POINTS` points; through the ground phase to rest when the result has one)."""

    id: int = Field(ge=1, description="rising per service process; the event's SSE id (Last-Event-ID resumes after it)")
    source: Source
    received_unix_s: float = Field(description="when the shot arrived, seconds since 1970 (UTC)")
    shot_number: int | None = Field(None, description="the connector's ShotNumber (GSPro Open Connect)")
    launch: LaunchNumbers
    flight: ShotResult = Field(description="the flight result the client got back (a /v1/shots result)")


def schema_text() -> str:
    """The event's JSON Schema as written to SCHEMA_PATH."""
    return json.dumps(ShotEvent.model_json_schema(), indent=2, sort_keys=True) + "\n"
