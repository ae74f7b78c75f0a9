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

An object cut short and followed at once by a new one, with no pause (a connector that wrote half a message and
then its next), is found by JSON's own grammar, checked where the brace count stops anyway: a string may begin only
after `{`, `[`, `,` or `:`, an object or array only after `:`, `[` or a comma in an array. The first byte where
neither can begin marks the cut: a `{` there is the new object; a quote there means the cut fell inside a string,
which the new object's first quote closed, so the new object began at the last `{` before it. A cut right after a
key's colon leaves the new message a valid member of the old: a member whose first key is one of a message's own
(`_MESSAGE_START`), closing less than MEMBER_DEPTH deep, is taken for it. Either way the unfinished object gets one
refusal and the new one is read from its start. Before, the new object was framed as part of the unfinished one:
no reply, and its resend got two (issue 55).

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

_IN_OBJECT = re.compile(rb'[{}\[\]"]')
_BRACE, _BRACKET, _BRACKET_END, _QUOTE, _BACKSLASH = b'{[]"\\'
_OPENING = b'{["'
"""Where a value (or a key) begins: JSON allows it only after certain bytes (`_MAY_FOLLOW`)."""
_MAY_FOLLOW = {_QUOTE: b"{[,:", _BRACE: b":[", _BRACKET: b":["}
"""What JSON lets a string, an object or an array (the key) begin after, outside strings and whitespace: a string
after `{`, `[`, `,` or `:`; an object or array after `:` or `[` (or `,` in an array: `_in_array_after_comma`)."""
_MESSAGE_START = re.compile(
    rb'\{[ \t\r\n]*"(?:DeviceID|Units|ShotNumber|APIversion|BallData|ClubData|ShotDataOptions)"')
"""An object whose first key is one of an Open Connect message's own, never a key of one of its members."""
MEMBER_DEPTH = 3
"""How deep a message's members go (a message, its BallData, a value): an object that closes deeper is no message
cut short (and looking deeper would cost the framing of a hostile nest of objects its square)."""
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
        self._containers = bytearray()  # the open object's containers, outermost first: `{` or `[`
        self._last = 0  # the last byte of the open object outside strings and whitespace (`"` for a string's end)
        self._opened: list[int] = []  # where in _object each open container began
        self._in_string = False
        self._escaped = False
        self._oversized = False
        self._stalled = False

    @property
    def partial(self) -> bool:
        """Whether an object has begun and not yet ended."""
        return bool(self._containers)

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
        self._scan(data, position, found)
        return found

    def _scan(self, data: bytes, position: int, found: list[bytes | Refused]) -> None:
        """Frame `data` from `position` on, adding what it completes or refuses to `found`."""
        while position < len(data):
            if not self._containers:
                position = self._top_level(data, position, found)
            else:
                position = self._inside(data, position, found)

    def _whole_object(self, data: bytes) -> bytes | None:
        """`data` itself, stripped, when it is exactly one whole JSON object arriving between objects: what a
        connector writes for a shot, in one piece. Python's C parser checks that in microseconds where the brace
        count below steps through every quote in Python; anything else (a piece, several objects, invalid JSON)
        gets None and the brace count, which then frames it exactly as it always did."""
        if self._containers or self._stalled or len(data) > self.limit:
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
        probe._object, probe._containers = bytearray(self._object), bytearray(self._containers)
        probe._opened = list(self._opened)
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
            self._containers, self._object, self._last = bytearray(b"{"), bytearray(b"{"), ord("{")
            self._opened = [0]
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
        """Advance through an open object to its next `{}[]"` (in a string, its end or an escape), its end or the
        end of `data`."""
        if self._escaped:  # the byte after a backslash that ended the previous chunk
            self._escaped = False
            self._keep(data, position, position + 1, found)
            return position + 1
        if self._in_string:
            return self._through_string(data, position, found)
        hit = _IN_OBJECT.search(data, position)
        stop = len(data) if hit is None else hit.start()
        if stop > position:
            self._note(data, position, stop)
        if hit is None:
            self._keep(data, position, stop, found)
            return stop
        byte = data[stop]
        if byte in _OPENING and self._last not in _MAY_FOLLOW[byte] and not self._in_array_after_comma(byte):
            self._keep(data, position, stop, found)
            position = stop
            if self._restart(byte == _BRACE, found):
                return stop
        if byte == _QUOTE:
            self._in_string, self._last = True, _QUOTE
            self._keep(data, position, stop + 1, found)
            return stop + 1
        began = self._nest(byte, len(self._object) + stop - position)
        self._keep(data, position, stop + 1, found)
        if began > 0 and len(self._containers) < MEMBER_DEPTH and self._message_inside(began, found):
            return stop + 1
        if not self._containers:
            if not self._oversized:
                found.append(bytes(self._object))
            self._object, self._oversized = bytearray(), False
        return stop + 1

    def _through_string(self, data: bytes, position: int, found: list[bytes | Refused]) -> int:
        """Advance through a string to its end, an escape (and the byte it escapes) or the end of `data`."""
        hit = _IN_STRING.search(data, position)
        end = len(data) if hit is None else hit.end()
        if hit is not None and data[hit.start()] == _BACKSLASH:
            if end == len(data):
                self._escaped = True
            else:
                end += 1
        elif hit is not None:
            self._in_string = False
        self._keep(data, position, end, found)
        return end

    def _note(self, data: bytes, start: int, stop: int) -> None:
        """Bytes outside strings between two of `{}[]"`: their last one that is not whitespace, if any, is now the
        last significant byte."""
        kept = data[start:stop].rstrip(b" \t\r\n")
        if kept:
            self._last = kept[-1]

    def _nest(self, byte: int, at: int) -> int:
        """A container opens (`{`, `[`, at `at` in the object) or closes: `}` closes up to its `{` (as the brace
        count always did), `]` only an open `[`. Where the object a `}` closed began, -1 for anything else."""
        self._last = byte
        if byte == _BRACE or byte == _BRACKET:
            self._containers.append(byte)
            self._opened.append(at)
            return -1
        if byte == _BRACKET_END:
            if self._containers[-1:] == b"[":
                self._close()
            return -1
        while self._containers and self._containers[-1] != _BRACE:
            self._close()
        return self._close() if self._containers else -1

    def _close(self) -> int:
        """Close the innermost container; where it began."""
        self._containers.pop()
        return self._opened.pop()

    def _in_array_after_comma(self, byte: int) -> bool:
        """Whether an object or array (`byte`) begins after a comma in an array: allowed where `_MAY_FOLLOW` does not
        say."""
        return byte != _QUOTE and self._last == ord(",") and self._containers[-1:] == b"["

    def _message_inside(self, began: int, found: list[bytes | Refused]) -> bool:
        """Whether the object that just closed inside the open one (`began` there; the caller looks only at members
        less than MEMBER_DEPTH deep) is a whole message of its own: its first key is one of a message's own, which
        no member of a message has, and it is valid JSON. Then the open object was cut right after a key's colon,
        where an object may begin, and a new message followed at once: the cut object is given up (one refusal) and
        the message found."""
        if self._oversized or not _MESSAGE_START.match(self._object, began):
            return False
        member = bytes(self._object[began:])
        try:
            json.loads(member)
        except (ValueError, RecursionError):
            return False
        del self._object[began:]
        refusal = self.give_up()
        found += [refusal, member] if refusal else [member]
        return True

    def _restart(self, at_brace: bool, found: list[bytes | Refused]) -> bool:
        """The open object broke where no value can begin: a new object began there (`at_brace`), or, at a quote,
        at the last `{` kept before it (the object was cut inside a string, which the new object's first quote
        closed). Give the broken object up (one refusal) and frame the new one's bytes kept so far; False, changing
        nothing, where no `{` but the object's own opened after it (it is framed on and refused once whole, as
        before)."""
        begin = len(self._object) if at_brace else self._object.rfind(b"{", 1)
        if self._oversized or begin < 1:
            return False
        tail = bytes(self._object[begin:])
        del self._object[begin:]
        refusal = self.give_up()
        found += [refusal] if refusal else []
        self._scan(tail, 0, found)
        return True

    def _keep(self, data: bytes, start: int, end: int, found: list[bytes | Refused]) -> None:
        """Add data[start:end] to the open object unless it is being skipped for its size."""
        if self._oversized:
            return
        self._object += data[start:end]
        if len(self._object) > self.limit:
            found.append(Refused(f"message over {self.limit:,} bytes: skipped to its end"))
            self._object, self._oversized = bytearray(), True
