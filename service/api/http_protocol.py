"""uvicorn's HTTP protocol (httptools) with deadlines for a request's head and body.

uvicorn closes a connection idle between requests (its keep-alive timeout) but gives none to a request under way:
a client that sends half a request line, or a header a minute, or a body a byte at a time, holds its connection and
a file descriptor for as long as it likes. On a bay PC under a 1,024 open-files limit, 1,100 such requests made
/healthz unanswerable and reset the connector (issue 42). Here a request's head (request line and headers) must
arrive within HEAD_TIMEOUT_S of its first byte, and its body within BODY_TIMEOUT_S of the head; past either the
connection is closed with a 408. A connection that sends nothing at all is closed silently after HEAD_TIMEOUT_S, as
uvicorn closes one idle between requests: a 408 nobody asked for would be read as the answer to the client's next
request.
"""

from __future__ import annotations

import asyncio

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

HEAD_TIMEOUT_S = 10.0
"""Longest a request's line and headers may take to arrive: a client writes them in one go, in well under a second
even over a venue's Wi-Fi."""

BODY_TIMEOUT_S = 30.0
"""Longest a request's body may take after its head: the largest accepted (8 MiB) takes about a second on 100 Mbit/s,
seconds on a poor Wi-Fi link."""

TIMED_OUT = (b"HTTP/1.1 408 Request Timeout\r\ncontent-type: text/plain; charset=utf-8\r\ncontent-length: 46\r\n"
             b"connection: close\r\n\r\nthe request did not arrive in time: send again\n")


class DeadlineHttpProtocol(HttpToolsProtocol):
    """`HttpToolsProtocol` whose requests must arrive in time: the head within `head_timeout_s`, the body within
    `body_timeout_s` after it (class attributes, so a test can shorten them in a subclass)."""

    head_timeout_s = HEAD_TIMEOUT_S
    body_timeout_s = BODY_TIMEOUT_S

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        self._deadline: asyncio.TimerHandle | None = None
        super().connection_made(transport)
        self._arm(self.head_timeout_s, requested=False)

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        super().connection_lost(exc)

    def on_message_begin(self) -> None:
        super().on_message_begin()
        self._arm(self.head_timeout_s, requested=True)

    def on_headers_complete(self) -> None:
        super().on_headers_complete()
        self._arm(self.body_timeout_s, requested=True)

    def on_message_complete(self) -> None:
        self._disarm()
        super().on_message_complete()

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
