"""How a refused request reads: each problem names the field, the value sent and the allowed range, in the shape
every 4xx body, the GSPro reply and the command line's messages share."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import NamedTuple

from golfflight.contract.requests import RANGES
from golfflight.errors import FlightError, GolfflightError, InputError, ServiceError, refusal_text
from golfflight.flight.limits import Range, limit_text

NOT_JSON = "the body is not JSON text in UTF-8 (or UTF-16 or UTF-32, which are read too)"
"""The refusal of a body that cannot even be decoded (FastAPI's bare 400, said as a 422 like every other refusal)."""
NESTED_TOO_DEEPLY = ("the body is not valid JSON: nested too deeply to read (a request nests its objects and "
                     "lists four levels deep at most)")
"""The refusal of a body whose nesting exhausted Python's JSON parser (about a thousand levels)."""

LISTED_ERRORS = 20
"""Most problems one 422 lists; a last entry counts the rest. A 20 KB batch of 10,000 wrong shots listed every one
(2.8 MB, issue 55); a batch's problems are mostly one mistake repeated, and 20 entries are about 8 KB."""

QUOTED_CHARS = 40
"""Most characters of a value (or a field name) a refusal quotes; a longer one is cut, "…" in place of the rest, so
that a refusal never echoes a whole body."""


def _quoted(text: str) -> str:
    """`text` cut to QUOTED_CHARS characters."""
    return text if len(text) <= QUOTED_CHARS else text[: QUOTED_CHARS - 1] + "…"


def encodable(text: str) -> str:
    """`text` with its lone surrogates (which a JSON escape such as \\ud800 puts into a request's text, but which no
    UTF-8 body can carry out) written as backslash escapes, the six characters \\ud800."""
    return text.encode("utf-8", "backslashreplace").decode("utf-8")


def _shown(part):
    """A value or a field name as a refusal shows it: text cut (`_quoted`) and UTF-8 encodable (`encodable`)."""
    return encodable(_quoted(part)) if isinstance(part, str) else part


def _plain(value):
    """A request value as a UTF-8 JSON body can carry it: NaN and infinity as text; text, and a whole number too
    long to quote, cut and UTF-8 encodable (`_shown`); objects and lists left out. The message quotes text as Python
    writes it, a lone surrogate as its escape too."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, int) and not isinstance(value, bool) and len(str(value)) > QUOTED_CHARS:
        return _shown(str(value))
    if isinstance(value, str):
        return _shown(value)
    return value if isinstance(value, (int, float, bool)) or value is None else None


BOUNDS = {
    "less_than_equal": ("le", "less than or equal to", True),
    "greater_than_equal": ("ge", "greater than or equal to", False),
    "less_than": ("lt", "less than", True),
    "greater_than": ("gt", "greater than", False),
}
"""pydantic's error types of a bound passed: (the bound's key in the error's ctx, the words, whether a high end)."""


def _msg(error: dict) -> str:
    """pydantic's `msg`, its "Value error, " prefix dropped and a bound it quotes printed as every limit is
    (`flight.limits.limit_text`: pydantic prints a converted limit with all its float digits, 223.69362920544023)."""
    bound = BOUNDS.get(error["type"])
    limit = (error.get("ctx") or {}).get(bound[0]) if bound else None
    if isinstance(limit, int | float) and not isinstance(limit, bool):
        return f"Input should be {bound[1]} {limit_text(limit, high=bound[2])}"
    return encodable(error["msg"].removeprefix("Value error, "))


def describe_error(error: dict, ranges: dict[str, Range] = RANGES) -> dict:
    """One 422 detail: FastAPI's own `loc` and `type` and its `msg` (a bound in it printed as every limit is), plus
    the field as a dotted path, the value sent, the allowed range (from `ranges`, by field name), the batch index of
    the shot, and a `message` in plain words that says all of it (`errors.refusal_text`). An InputError that names
    its field, raised by a model's validator, gives its own field, value and range (`input_detail`)."""
    raised = (error.get("ctx") or {}).get("error")
    if isinstance(raised, InputError) and raised.field is not None:
        return input_detail(raised, error["type"], error["loc"])
    path = [_shown(p) for p in error["loc"] if p != "body"]
    field = ".".join(str(p) for p in path) or "body"
    msg = _msg(error)
    entry: dict = {"loc": [_shown(p) for p in error["loc"]], "msg": msg, "type": error["type"], "field": field}
    sent = error.get("input") if error["type"] != "missing" else None
    if _plain(sent) is not None:
        entry["value"] = _plain(sent)
    name = path[-1] if path else None
    if isinstance(name, str) and name in ranges and error["type"] != "extra_forbidden":
        entry["allowed"] = ranges[name].describe()
    return _finished(entry, path, sent)


def input_detail(error: InputError, kind: str, at: Sequence = ("body",)) -> dict:
    """One 422 detail of an InputError that names its field (`error.field`): the field under `at` (the location of
    the model whose validator raised it; the body by default), the value, the allowed range and the message, the same
    parts and words as `describe_error`'s, so the 422 body, the Open Connect reply and the command line agree."""
    loc = [_shown(p) for p in at] + [_shown(part) for part in error.field.split(".")]
    path = [p for p in loc if p != "body"]
    entry: dict = {"loc": loc, "msg": encodable(error.problem), "type": kind, "field": ".".join(str(p) for p in path)}
    if _plain(error.value) is not None:
        entry["value"] = _plain(error.value)
    if error.allowed:
        entry["allowed"] = error.allowed
    return _finished(entry, path, error.value)


def _finished(entry: dict, path: list, sent) -> dict:
    """`entry` with its batch index (`shot`) where the path starts in a batch's shots, and its `message`
    (`errors.refusal_text`: the field, the problem, the value sent, cut where long, and the allowed range)."""
    named = entry["field"]
    if len(path) >= 2 and path[0] == "shots" and isinstance(path[1], int):
        entry["shot"] = path[1]
        named = f"shot {path[1]}: {'.'.join(str(p) for p in path[2:]) or 'shot'}"
    shown = None if "value" not in entry else _quoted(sent) if isinstance(sent, str) else entry["value"]
    entry["message"] = refusal_text(named, entry["msg"], shown, entry.get("allowed"))
    return entry


def failure_detail(error: GolfflightError, kind: str) -> dict:
    """The 4xx detail of one of our failures: an InputError that names its field as `input_detail` writes it, any
    other as the body's (`body_detail`)."""
    if isinstance(error, InputError) and error.field is not None:
        return input_detail(error, kind)
    return body_detail(str(error), kind)


class Answer(NamedTuple):
    """How the service answers one kind of failure: the HTTP status, the Open Connect reply code and the detail's
    `type`."""

    http_status: int
    open_connect_code: int
    kind: str


FAILURES: dict[type[GolfflightError], Answer] = {
    InputError: Answer(422, 500, "input_error"),
    FlightError: Answer(422, 500, "flight_error"),
    ServiceError: Answer(503, 503, "service_unavailable"),
}
"""The one table from a failure to its answer, for HTTP and Open Connect alike: the caller's input and a shot that
cannot land are refused (HTTP 422, Open Connect's error Code 500); the service not able to answer now is 503 in both
(try again). Any other exception is a bug: HTTP 500, Open Connect Code 500."""

UNEXPECTED = Answer(500, 500, "internal_error")
"""The answer to an exception outside the family: a bug, said as such."""


def answer_to(error: BaseException) -> Answer:
    """`error`'s row of FAILURES (its nearest kind), or UNEXPECTED outside the family."""
    for kind in type(error).__mro__:
        if kind in FAILURES:
            return FAILURES[kind]
    return UNEXPECTED


class RequestRefused(InputError):
    """A request refused with these 422 details (`listed_errors`), found where the request was read (the batch
    process reads a batch's body off the event loop)."""

    def __init__(self, details: list[dict]):
        super().__init__(details[0]["message"])
        self.details = details

    def __reduce__(self):
        """Pickled with its details (the batch process sends a refusal back to its server)."""
        return RequestRefused, (self.details,)


def body_detail(message: str, kind: str) -> dict:
    """A 422/413 detail about the body as a whole (not one field), shaped like `describe_error`'s."""
    return {"loc": ["body"], "msg": message, "type": kind, "field": "body", "message": message}


def not_json(reason: str, text: str, position: int) -> str:
    """The refusal of a body that does not parse as JSON, saying where (line and column, counted as the JSON
    decoder counts them, or the end of a body cut short) and what the decoder expected there: FastAPI reports only
    the character position."""
    where = json.JSONDecodeError(reason, text, position)
    place = f"line {where.lineno} column {where.colno}"
    place = f"the end of the body ({place})" if position >= len(text) else place
    return f"the body is not valid JSON: {encodable(reason)} at {place}"


def describe_errors(errors, ranges: dict[str, Range] = RANGES) -> list[dict]:
    """422 details naming the field, the value and the allowed range (see `describe_error`)."""
    return [describe_error(error, ranges) for error in errors]


def listed_errors(errors: list[dict], ranges: dict[str, Range] = RANGES) -> list[dict]:
    """422 details of the first LISTED_ERRORS problems (`describe_error`), then one entry, type `more_errors`, that
    counts the rest (its `omitted`), so that a refusal stays small however many problems a body has."""
    listed = [describe_error(error, ranges) for error in errors[:LISTED_ERRORS]]
    omitted = len(errors) - len(listed)
    if omitted > 0:
        message = f"{omitted:,} more problems not listed (the first {LISTED_ERRORS} of {len(errors):,} are)"
        listed.append({**body_detail(message, "more_errors"), "omitted": omitted})
    return listed
