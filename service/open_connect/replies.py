"""What golfflight sends back for each object a connector writes over TCP: a shot's reply, an error, or nothing.

Heartbeats and messages without ball data get no reply (GSPro sends none: a connector that waits for one would
resend). Everything that is not a valid message gets Code 500 with a Message saying what is wrong, as the HTTP
route's does (`contract.gspro.invalid_message`).
"""

from __future__ import annotations

import json
from collections.abc import Callable

from golfflight.contract.gspro import GSProMessage, GSProReply, invalid_message
from golfflight.service.open_connect.framing import Refused
from pydantic import ValidationError

Answer = Callable[[GSProMessage], GSProReply]
"""Flies a message that carries BallData: the service's shared GSPro answer (timing, the engine, its readiness)."""


def reply_to(item: bytes | Refused, answer: Answer) -> GSProReply | None:
    """The reply to one framed object (or refusal); None for a heartbeat or a message without ball data."""
    if isinstance(item, Refused):
        return GSProReply(Code=500, Message=item.message)
    try:  # parsed and validated in one pass by pydantic-core: a valid message is read once
        message = GSProMessage.model_validate_json(item)
    except ValidationError:
        return _read_by_python(item, answer)
    return None if message.BallData is None else answer(message)


def _read_by_python(item: bytes, answer: Answer) -> GSProReply | None:
    """`reply_to` for an object pydantic-core's own JSON reading refused: read by Python's json and validated, so
    a refusal says what it always said (the JSON error, or each field's problem: `invalid_message`) and whatever
    Python's parser takes that pydantic-core's does not (UTF-16, a lone surrogate in a string) flies as before."""
    try:
        data = json.loads(item)
    except ValueError as error:  # JSONDecodeError, or UnicodeDecodeError for bytes that are not UTF-8
        return GSProReply(Code=500, Message=f"not valid JSON: {error}")
    except RecursionError:
        return GSProReply(Code=500, Message="not valid JSON: nested too deeply")
    try:
        message = GSProMessage.model_validate(data)
    except ValidationError as error:
        return GSProReply(Code=500, Message=invalid_message(error.errors()))
    return None if message.BallData is None else answer(message)
