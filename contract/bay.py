"""The simulator bay's conditions: the air, wind and ground a shot flies in when it brings none of its own, and the
units the bay's screen shows. A launch monitor's connector sends ball data only (GSPro Open Connect has no field for
the weather or the green): in a simulator the course's conditions come from the simulator, here from the bay.

Validated by the same request models and limits as a shot's conditions; a shot's own conditions win, field by field
(`in_bay`). The server keeps one, changed live and stored in a file (`service.api.bay.Bay`).
"""

from __future__ import annotations

from typing import Literal

from golfflight.contract.requests import AirRequest, GroundRequest, ShotRequest, Strict, WindRequest
from pydantic import Field

CONDITION_FIELDS = ("air", "wind", "ground")


class BayConditions(Strict):
    """What a shot without conditions of its own flies in, and the units the bay's screen shows; the same `air`,
    `wind` and `ground` objects as a shot request (omitted: ICAO standard air, calm, a level fairway)."""

    air: AirRequest | None = None
    wind: WindRequest | None = None
    ground: GroundRequest | None = None
    units: Literal["imperial", "metric"] = Field(
        "imperial", description="what the bay's screen shows: yards, mph and feet, or metres and m/s"
    )


def in_bay(shot: ShotRequest, bay: BayConditions) -> ShotRequest:
    """The shot with the bay's air, wind and ground wherever it gives none of its own."""
    updates = {name: getattr(bay, name) for name in CONDITION_FIELDS
               if getattr(shot, name) is None and getattr(bay, name) is not None}
    return shot.model_copy(update=updates) if updates else shot
