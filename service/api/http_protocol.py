"""uvicorn's HTTP protocol (httptools) with deadlines for a request's head and body, a size limit on its head and a
deadline on writes its client does not read.

uvicorn closes a connection idle between requests (its keep-alive timeout) but gives none to a request under way:
a client that sends half a request line, or a header a minute, or a body a byte at a time, holds its connection and
a file descriptor for as long as it likes. On a bay PC under a 1,024 open-files limit, 1,100 such requests made
/healthz unanswerable and reset the connector (issue 42). Here a request's head (request line and headers) must
arrive within HEAD_TIMEOUT_S of its first byte, and its body within BODY_TIMEOUT_S of the head; past either the
connection is closed with a 408. A connection that sends nothing at all is closed silently after HEAD_TIMEOUT_S, as
uvicorn closes one idle between requests: a 408 nobody asked for would be read as the answer to the client's next
request.

Neither uvicorn nor httptools bounds a head's size: httptools grows a header's value on every read, so a client
looping 8 MiB headers took the server to 3 GiB (issue 55). Here the bytes of a head are counted as they arrive and
a head over MAX_HEAD_BYTES is answered 431 and its connection closed before anything else reads it. A client that
stops reading its answer pauses the connection's writes (the transport's buffer is full); writes paused for
WRITE_TIMEOUT_S end the connection, so an answer nobody reads does not stay in memory.
"""

from __future__ import annotations

import asyncio

from golfflight.service.api.log_throttle import quieted
from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

HEAD_TIMEOUT_S = 10.0
"""Longest a request's line and headers may take to arrive: a client writes them in one go, in well under a second
even over a venue's Wi-Fi."""

BODY_TIMEOUT_S = 30.0
"""Longest a request's body may take after its head: the largest accepted (8 MiB) takes about a second on 100 Mbit/s,
seconds on a poor Wi-Fi link."""

MAX_HEAD_BYTES = 32 * 1024
"""Largest request line and headers together: a simulator's request head is a few hundred bytes and a browser's,
cookies included, a few KiB; nginx's default (`large_client_header_buffers 4 8k`) takes at most 32 KiB too."""

WRITE_TIMEOUT_S = 10.0
"""Longest a connection's writes may stay paused (its client reads nothing while more than the transport's 64 KiB
wait to be sent): a client that reads at all, even over a poor Wi-Fi link, takes some of it within milliseconds."""

TIMED_OUT = (b"HTTP/1.1 408 Request Timeout\r\ncontent-type: text/plain; charset=utf-8\r\ncontent-length: 46\r\n"
             b"connection: close\r\n\r\nthe request did not arrive in time: send again\n")


def head_too_large(limit: int) -> bytes:
    """The 431 that refuses a request whose line and headers pass `limit` bytes, saying the limit."""
    text = f"request line and headers over {limit:,} bytes refused: the limit is {limit:,} bytes\n".encode()
    return (b"HTTP/1.1 431 Request Header Fields Too Large\r\ncontent-type: text/plain; charset=utf-8\r\n"
            b"content-length: %d\r\nconnection: close\r\n\r\n%s" % (len(text), text))


class DeadlineHttpProtocol(HttpToolsProtocol):
    """`HttpToolsProtocol` whose requests must arrive in time and small: the head within `head_timeout_s` and
    `max_head_bytes`, the body within `body_timeout_s` after it, and whose answers must be read: writes paused for
    `write_timeout_s` close the connection (class attributes, so a test can change them in a subclass)."""

    head_timeout_s = HEAD_TIMEOUT_S
    body_timeout_s = BODY_TIMEOUT_S
    max_head_bytes = MAX_HEAD_BYTES
    write_timeout_s = WRITE_TIMEOUT_S

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        self._deadline: asyncio.TimerHandle | None = None
        self._write_deadline: asyncio.TimerHandle | None = None
        self._head_bytes: int | None = 0  # bytes of the head under way; None while a body is read
        quieted(self.logger)
        super().connection_made(transport)
        self._arm(self.head_timeout_s, requested=False)

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        self._read_in_time()
        super().connection_lost(exc)

    def data_received(self, data: bytes) -> None:
        """Parse `data`, counting it towards the head under way first: a head past `max_head_bytes` is refused
        with a 431 (the parser holds at most the limit and one read of it)."""
        if self._head_bytes is not None:
            self._head_bytes += len(data)
        super().data_received(data)
        if self._head_bytes is not None and self._head_bytes > self.max_head_bytes:
            self._refuse_head()

    def on_message_begin(self) -> None:
        super().on_message_begin()
        self._arm(self.head_timeout_s, requested=True)

    def on_headers_complete(self) -> None:
        self._head_bytes = None
        super().on_headers_complete()
        self._arm(self.body_timeout_s, requested=True)

    def on_message_complete(self) -> None:
        self._disarm()
        self._head_bytes = 0
        super().on_message_complete()

    def pause_writing(self) -> None:
        super().pause_writing()
        if self._write_deadline is None:
            self._write_deadline = self.loop.call_later(self.write_timeout_s, self._unread)

    def resume_writing(self) -> None:
        super().resume_writing()
        self._read_in_time()

    def _read_in_time(self) -> None:
        """Cancel the write deadline: the client read (or left)."""
        if self._write_deadline is not None:
            self._write_deadline.cancel()
            self._write_deadline = None

    def _unread(self) -> None:
        """End a connection whose client has read nothing for `write_timeout_s`, dropping what waits for it."""
        self._write_deadline = None
        self.transport.abort()

    def _refuse_head(self) -> None:
        self._head_bytes = None
        self._disarm()
        if not self.transport.is_closing():
            self.transport.write(head_too_large(self.max_head_bytes))
            self.transport.close()

    def _arm(self, seconds: float, requested: bool) -> None:
        """Close the connection in `seconds` unless disarmed first (`requested`: a request has begun)."""
        self._disarm()
        self._deadline = self.loop.call_later(seconds, self._too_late, requested)

    def _disarm(self) -> None:
        if self._deadline is not None:
            self._deadline.cancel()
            self._deadline = None

    def _too_late(self, requested: bool) -> None:
        """Close a connection whose request did not arrive in time: with a 408 once a request had begun
        (`requested`) and its answer had not, silently when it never sent one."""
        self._deadline = None
        if self.transport.is_closing():
            return
        answered = self.cycle is not None and self.cycle.response_started and not self.cycle.response_complete
        if requested and not answered:  # the cycle is the last request's until this one's head is complete
            self.transport.write(TIMED_OUT)
        self.transport.close()
