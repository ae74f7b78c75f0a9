"""What golfflight writes to a connector over TCP: the reply to each object it sends (a shot's reply, an error, or
nothing), and the player information pushed to it (Code 201).

Heartbeats and messages without ball data get no reply (GSPro sends none: a connector that waits for one would
resend). Everything that is not a valid message gets Code 500 with a Message saying what is wrong, as the HTTP
route's does (`contract.gspro.invalid_message`). Everything goes out as compact JSON with no delimiter. Each reply
says too whether its object was a valid message: a connection that sends them keeps its place (`server`).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import NamedTuple

from golfflight.contract.clubs import club_code
from golfflight.contract.gspro import GSProMessage, GSProReply, invalid_message, shot_number_of
from golfflight.errors import InputError
from golfflight.service.open_connect.framing import Refused
from pydantic import ValidationError

Answer = Callable[[GSProMessage], GSProReply]
"""Flies a message that carries BallData: the service's shared GSPro answer (timing, the engine, its readiness)."""

HANDED = ("RH", "LH")
"""The player's hand as GSPro writes it."""


def encoded(reply: GSProReply) -> bytes:
    """A reply as it goes on the wire."""
    return reply.model_dump_json(exclude_none=True).encode()


def player_information(club: str, handed: str) -> bytes:
    """The Code 201 object GSPro pushes when the player or the club changes, as it goes on the wire, the club as its
    GSPro code (connectors switch to putting on PT) whichever name it is given by (`contract.clubs.club_code`);
    InputError for a hand other than RH or LH or a club no name of which it is."""
    if handed not in HANDED:
        raise InputError(f"handed must be one of {', '.join(HANDED)}, got {handed!r}")
    player = {"Code": 201, "Message": "GSPro Player Information", "Player": {"Handed": handed, "Club": club_code(club)}}
    return json.dumps(player, separators=(",", ":")).encode()


NESTED_TOO_DEEPLY = ("not valid JSON: nested too deeply to read (an Open Connect message nests its objects two "
                     "levels deep)")
"""The refusal of an object nested past what Python's JSON parser reads (about a thousand levels)."""


class Replied(NamedTuple):
    """The reply to one framed object (None: nothing goes back), and whether the object was a valid message."""

    reply: GSProReply | None
    valid: bool


def _refused(message: str, shot_number: int | None = None) -> Replied:
    return Replied(GSProReply(Code=500, Message=message, ShotNumber=shot_number), False)


def _answered(message: GSProMessage, answer: Answer) -> Replied:
    """A valid message's reply: its flight's (`answer`), or none for a heartbeat or a message without ball data."""
    return Replied(None if message.BallData is None else answer(message), True)


def reply_to(item: bytes | Refused, answer: Answer) -> Replied:
    """The reply to one framed object (or refusal): None for a heartbeat or a message without ball data."""
    if isinstance(item, Refused):
        return _refused(item.message)
    try:  # parsed and validated in one pass by pydantic-core: a valid message is read once
        message = GSProMessage.model_validate_json(item)
    except ValidationError:
        return _read_by_python(item, answer)
    return _answered(message, answer)


def _read_by_python(item: bytes, answer: Answer) -> Replied:
    """`reply_to` for an object pydantic-core's own JSON reading refused: read by Python's json and validated, so
    a refusal says what it always said (the JSON error, or each field's problem: `invalid_message`) and whatever
    Python's parser takes that pydantic-core's does not (UTF-16, a lone surrogate in a string) flies as before."""
    try:
        data = json.loads(item)
    except ValueError as error:  # JSONDecodeError, or UnicodeDecodeError for bytes that are not UTF-8
        return _refused(f"not valid JSON: {error}")
    except RecursionError:
        return _refused(NESTED_TOO_DEEPLY)
    try:
        message = GSProMessage.model_validate(data)
    except ValidationError as error:
        return _refused(invalid_message(error.errors()), shot_number_of(data))
    return _answered(message, answer)
