"""The simulator bay's conditions: the air, wind and ground a shot flies in when it brings none of its own, the
player at the mat (GSPro's club and handedness) and the units the bay's screen shows. A launch monitor's connector
sends ball data only (GSPro Open Connect has no field for the weather or the green): in a simulator the course's
conditions and the club selected come from the simulator, here from the bay.

Validated by the same request models and limits as a shot's conditions; a shot's own conditions win (`in_bay`): its
air quantity by quantity (a shot giving only a temperature keeps the bay's altitude; `{}` is standard air), its wind and ground whole (a
wind or a ground is one thing: a green's stimp means nothing on the shot's rough). The server keeps one, changed live and stored in a file (`service.runtime.bay.Bay`). A partial update
(`BayUpdate`, PATCH /v1/bay) replaces the parts it names and leaves the rest; the player's two fields merge one by
one.
"""

from __future__ import annotations

from typing import Literal

from golfflight.contract.clubs import PUTTER, ClubName
from golfflight.contract.inputs import launch_of
from golfflight.contract.putter import not_a_putt
from golfflight.contract.requests import AirRequest, GroundRequest, ShotRequest, Strict, WindRequest
from golfflight.contract.results import ConditionSource, FlownIn
from pydantic import Field

CONDITION_FIELDS = ("air", "wind", "ground")


class Player(Strict):
    """Who is at the mat: the club selected (any name `contract.clubs` takes, kept as its GSPro code) and the hand
    they play. Connectors hear of every change as Open Connect's Code 201 player information."""

    club: ClubName = Field("DR", description="the club selected, as its GSPro code")
    handed: Literal["RH", "LH"] = Field("RH", description="right- or left-handed")


class BayConditions(Strict):
    """What a shot without conditions of its own flies in, who plays, and the units the bay's screen shows; the same
    `air`, `wind` and `ground` objects as a shot request (omitted: ICAO standard air, calm, a level fairway)."""

    air: AirRequest | None = None
    wind: WindRequest | None = None
    ground: GroundRequest | None = None
    player: Player = Field(default_factory=Player)
    units: Literal["imperial", "metric"] = Field(
        "imperial", description="what the bay's screen shows: yards, mph and feet, or metres and m/s"
    )


class PlayerUpdate(Strict):
    """The player's fields to change; an omitted one keeps its value."""

    club: ClubName | None = Field(None, description="the club selected, as its GSPro code")
    handed: Literal["RH", "LH"] | None = None


class BayUpdate(Strict):
    """A partial change of the bay (PATCH /v1/bay): each part named replaces that part (null clears air, wind or
    ground back to standard air, calm, a level fairway); a part left out stays as it is; `player` changes only
    the fields it gives."""

    air: AirRequest | None = None
    wind: WindRequest | None = None
    ground: GroundRequest | None = None
    player: PlayerUpdate | None = None
    units: Literal["imperial", "metric"] | None = None

    def applied_to(self, bay: BayConditions) -> BayConditions:
        """`bay` with this update's parts in place; validated as a whole again."""
        given = self.model_dump(exclude_unset=True)
        parts = {name: getattr(self, name) for name in CONDITION_FIELDS if name in given}
        if self.units is not None:
            parts["units"] = self.units
        if self.player is not None:
            parts["player"] = bay.player.model_copy(update=self.player.model_dump(exclude_none=True))
        return BayConditions.model_validate({**dict(bay), **parts})


AIR_QUANTITIES = (("temperature_c", "temperature_f"), ("altitude_m", "altitude_ft", "pressure_hpa"),
                  ("humidity_pct",))
"""The air's weather quantities, each in the forms a request may give it (a density replaces them all)."""


def air_in_bay(own: AirRequest, bay: AirRequest) -> AirRequest:
    """A shot's air over the bay's, quantity by quantity: each quantity the shot gives (in any of its forms) replaces
    the bay's, the others stay the bay's; a density given by the shot replaces the bay's air whole, and the shot's
    weather replaces a density the bay gives. An empty air (`{}`) is the standard atmosphere, the bay's air aside."""
    given = own.model_dump(exclude_none=True)
    if not given or "density_kg_m3" in given:
        return own
    kept = {name: value for name, value in bay.model_dump(exclude_none=True).items() if name != "density_kg_m3"}
    for forms in AIR_QUANTITIES:
        if any(form in given for form in forms):
            kept = {name: value for name, value in kept.items() if name not in forms}
    return AirRequest(**kept, **given)


def in_bay(shot: ShotRequest, bay: BayConditions) -> ShotRequest:
    """The shot with the bay's air, wind and ground wherever it gives none of its own (its air merged quantity by
    quantity, `air_in_bay`)."""
    updates = {name: getattr(bay, name) for name in CONDITION_FIELDS
               if getattr(shot, name) is None and getattr(bay, name) is not None}
    if shot.air is not None and bay.air is not None:
        updates["air"] = air_in_bay(shot.air, bay.air)
    return shot.model_copy(update=updates) if updates else shot


DEFAULTS = {"air": AirRequest(), "wind": WindRequest(speed_mps=0.0), "ground": GroundRequest()}
"""What a shot flies in where neither it nor the bay gives a condition, as the echo writes it (`flown_in`)."""


def _source(shot: ShotRequest, bay: BayConditions, flown: ShotRequest, name: str) -> ConditionSource:
    """Where the condition `name` of `flown` (the shot in the bay) came from."""
    own, bays = getattr(shot, name), getattr(bay, name)
    if own is None:
        return "default" if bays is None else "bay"
    return "shot and bay" if getattr(flown, name) != own else "shot"


def flown_in(shot: ShotRequest, bay: BayConditions, connector: bool = False) -> tuple[ShotRequest, FlownIn]:
    """The shot as flown in the bay (`in_bay`) and what it flew in: each condition, where it came from, and whether it
    rolls as a putt: a connector's shot with the putter selected does, unless no putt can leave as it did
    (`contract.putter.not_a_putt`, whose reason becomes the note)."""
    flown = in_bay(shot, bay)
    note = not_a_putt(launch_of(shot)) if connector and bay.player.club == PUTTER else None
    putt = connector and bay.player.club == PUTTER and note is None
    echo = {name: getattr(flown, name) or DEFAULTS[name] for name in CONDITION_FIELDS}
    sources = {f"{name}_from": _source(shot, bay, flown, name) for name in CONDITION_FIELDS}
    return flown, FlownIn.model_construct(**echo, **sources, putt=putt, note=note)


def flown_in_all(shots: list[ShotRequest], bay: BayConditions) -> tuple[list[ShotRequest], list[FlownIn]]:
    """`flown_in` of a batch's shots (none a connector's), the echo of those that give no condition of their own
    made once and shared: most of a batch's shots give none, and one echo each cost a 10,000-shot batch 0.3 s."""
    flown, echoes, bare = [], [], None
    for shot in shots:
        if shot.air is None and shot.wind is None and shot.ground is None:
            if bare is None:
                bare = flown_in(shot, bay)[1]
            flown.append(in_bay(shot, bay))
            echoes.append(bare)
        else:
            request, echo = flown_in(shot, bay)
            flown.append(request)
            echoes.append(echo)
    return flown, echoes
