"""Cut a TCP byte stream into the JSON objects a GSPro connector writes back to back, with no delimiter.

Objects are found by brace depth outside strings (escapes honoured) and parsed only once complete. Parsing the
growing buffer with `json.JSONDecoder.raw_decode` instead cannot tell an object cut mid-token (`{"IsHeartBeat": tr`)
from a broken one, nor where a broken object ends; counting braces answers both, so one bad object is refused and
the next one read. Bytes are scanned as they come: `{`, `}`, `"` and `\\` never occur inside a UTF-8 multi-byte
character, so no decoding is needed to find the ends.

A pause mid-object (`ObjectFramer.stall`, called by the server after a few seconds of silence) ends nothing by
itself: objects may arrive split across packets (docs/service.md), however late the rest. Only what comes next
decides: the rest of the object completes it (one object, one reply), while a new object (`{` that does not
complete the open one as valid JSON) gets the unfinished one refused once and is read from a clean start. Giving up
at the pause instead refused the piece and then framed its remainder as stray bytes and stray objects: five
replies for one delayed shot.

A UTF-8 byte order mark before an object is skipped, as `POST /v1/gspro` (Python's `json.loads` of bytes) skips it
before a body: a connector that writes one (.NET's UTF8Encoding with its preamble) gets its shot's one reply, where
the mark used to be refused as stray bytes, a second reply to the one shot.
"""

from __future__ import annotations

import copy
import json
import re
from dataclasses import dataclass

MAX_MESSAGE_BYTES = 64 * 1024
"""Largest object accepted; an Open Connect message is about 600 bytes."""
BOM = b"\xef\xbb\xbf"
"""The UTF-8 byte order mark, skipped where an object may begin."""

_IN_OBJECT = re.compile(rb'[{}"]')
_IN_STRING = re.compile(rb'["\\]')
_NOT_SPACE = re.compile(rb"[^ \t\r\n]")
_QUOTED = 40
"""Characters of refused input quoted in its refusal."""


def _quote(data: bytes) -> str:
    text = data.decode("utf-8", "replace")
    return repr(text if len(text) <= _QUOTED else text[:_QUOTED] + "...")


@dataclass(frozen=True)
class Refused:
    """Input that is not a JSON object (stray bytes, an object over the size limit, one given up half-sent)."""

    message: str


class ObjectFramer:
    """Feed it the bytes of one connection as they arrive; it hands back each complete top-level object (bytes, not
    yet parsed) and a `Refused` for whatever is not one, in stream order. Memory stays under `limit` bytes: an
    object that outgrows it is refused at once and the rest of it skipped. `stall` marks a pause mid-object (see the
    module's notes)."""

    def __init__(self, limit: int = MAX_MESSAGE_BYTES):
        self.limit = limit
        self._reset()

    def _reset(self) -> None:
        self._held = b""  # the first bytes of a BOM that ended the last piece, between objects
        self._object = bytearray()
        self._depth = 0
        self._in_string = False
        self._escaped = False
        self._oversized = False
        self._stalled = False

    @property
    def partial(self) -> bool:
        """Whether an object has begun and not yet ended."""
        return self._depth > 0

    @property
    def stalled(self) -> bool:
        """Whether the open object's sender paused (`stall`) and nothing has come since."""
        return self._stalled

    def stall(self) -> None:
        """The sender went quiet mid-object: the next bytes that come decide whether they are its rest or a new
        object (`feed`). Nothing is refused yet. No effect between objects."""
        self._stalled = self.partial

    def give_up(self) -> Refused | None:
        """Drop the object begun and not finished, so the next object starts clean; the refusal, or None for an
        object already refused for its size."""
        refusal = Refused(f"incomplete JSON object {_quote(self._object)}: a new object began before its end")
        oversized = self._oversized
        self._reset()
        return None if oversized else refusal

    def feed(self, data: bytes) -> list[bytes | Refused]:
        """Complete objects and refusals found in `data` (plus what earlier calls left unfinished)."""
        data, self._held = self._held + data, b""
        whole = self._whole_object(data)
        if whole is not None:
            return [whole]
        found: list[bytes | Refused] = []
        position = 0
        first = _NOT_SPACE.search(data) if self._stalled else None
        if first is not None:  # the first word since a pause mid-object (whitespace alone decides nothing)
            self._stalled = False
            if data[first.start()] == ord("{") and not self._completed_by(data):
                refusal = self.give_up()
                found += [refusal] if refusal else []
                position = first.start()
        while position < len(data):
            if self._depth == 0:
                position = self._top_level(data, position, found)
            else:
                position = self._inside(data, position, found)
        return found

    def _whole_object(self, data: bytes) -> bytes | None:
        """`data` itself, stripped, when it is exactly one whole JSON object arriving between objects: what a
        connector writes for a shot, in one piece. Python's C parser checks that in microseconds where the brace
        count below steps through every quote in Python; anything else (a piece, several objects, invalid JSON)
        gets None and the brace count, which then frames it exactly as it always did."""
        if self._depth or self._stalled or len(data) > self.limit:
            return None
        text = data.strip(b" \t\r\n")
        text = text.removeprefix(BOM).lstrip(b" \t\r\n")
        if not (text.startswith(b"{") and text.endswith(b"}")):
            return None
        try:
            json.loads(text.decode("utf-8"))  # as text: json.loads would take UTF-16 or UTF-32 bytes too
        except (ValueError, RecursionError):  # UnicodeDecodeError is a ValueError
            return None
        return text

    def _completed_by(self, data: bytes) -> bool:
        """Whether `data` (after a pause, opening with `{`) ends the open object as valid JSON: then it is the
        object's rest (a `{` continues one after a colon, or inside a string), otherwise a new object."""
        if self._oversized:
            return False  # refused already; its end cannot be checked
        probe = copy.copy(self)
        probe._object = bytearray(self._object)
        found = probe.feed(data)
        if not found or not isinstance(found[0], bytes):
            return False
        try:
            json.loads(found[0])
        except (ValueError, RecursionError):
            return False
        return True

    def _top_level(self, data: bytes, position: int, found: list[bytes | Refused]) -> int:
        """Skip whitespace and a byte order mark; open the next object, or refuse the stray bytes up to it."""
        start = _NOT_SPACE.search(data, position)
        if start is None:
            return len(data)
        begin = start.start()
        if data[begin] == ord("{"):
            self._depth, self._object = 1, bytearray(b"{")
            return begin + 1
        if data.startswith(BOM, begin):
            return begin + len(BOM)
        if BOM.startswith(data[begin:]):  # a mark cut by the end of the piece: its rest comes with the next
            self._held = data[begin:]
            return len(data)
        end = data.find(b"{", begin)
        end = len(data) if end < 0 else end
        stray = _quote(data[begin:end].rstrip())
        found.append(Refused(f"expected a JSON object starting with '{{', got {stray}"))
        return end

    def _inside(self, data: bytes, position: int, found: list[bytes | Refused]) -> int:
        """Advance through an open object to its end or the end of `data`."""
        if self._escaped:  # the byte after a backslash that ended the previous chunk
            self._escaped = False
            self._keep(data, position, position + 1, found)
            return position + 1
        pattern = _IN_STRING if self._in_string else _IN_OBJECT
        hit = pattern.search(data, position)
        if hit is None:
            self._keep(data, position, len(data), found)
            return len(data)
        end, byte = hit.end(), data[hit.start()]
        if byte == ord("\\"):
            if end == len(data):
                self._escaped = True
            else:
                end += 1
        elif byte == ord('"'):
            self._in_string = not self._in_string
        else:
            self._depth += 1 if byte == ord("{") else -1
        self._keep(data, position, end, found)
        if self._depth == 0:
            if not self._oversized:
                found.append(bytes(self._object))
            self._object, self._oversized = bytearray(), False
        return end

    def _keep(self, data: bytes, start: int, end: int, found: list[bytes | Refused]) -> None:
        """Add data[start:end] to the open object unless it is being skipped for its size."""
        if self._oversized:
            return
        self._object += data[start:end]
        if len(self._object) > self.limit:
            found.append(Refused(f"message over {self.limit:,} bytes: skipped to its end"))
            self._object, self._oversized = bytearray(), True
