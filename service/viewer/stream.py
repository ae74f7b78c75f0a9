"""The viewer's live feed as server-sent events (`GET /v1/events`).

Server-sent events rather than a WebSocket: the feed only flows from the service to the page, and SSE is a plain
HTTP GET, so the API key check, CORS and proxies treat it like any other route; uvicorn serves WebSockets only
with a `websockets` or `wsproto` package, which the serving install does not have. The page reads the stream with
fetch() rather than EventSource, which cannot send the X-API-Key header.

A stream stays open for as long as its client reads it, and sends a `: keep-alive` comment whenever KEEPALIVE_S
pass without a shot, so proxies and idle timeouts keep the connection and a client notices a dead service. uvicorn's
graceful shutdown waits for open responses, so an endless stream would hold up a SIGTERM for the whole grace
period: each stream watches the uvicorn server that serves it (found through the SIGTERM handler uvicorn installs,
`serving_server`) and ends within SHUTDOWN_POLL_S once it is told to stop; the page reconnects to the next server
with Last-Event-ID, losing nothing that is kept.
"""

from __future__ import annotations

import re
import signal
import time
from collections.abc import AsyncIterator, Callable
from typing import Protocol

from golfflight.service.runtime.feed import Viewer
from golfflight.service.viewer.frames import frame

KEEPALIVE_S = 15.0
"""Longest a stream stays silent: a `: keep-alive` comment is sent after this long without a shot."""

SHUTDOWN_POLL_S = 0.5
"""How often an idle stream looks whether the server is shutting down."""

RETRY_MS = 500
"""The reconnection delay the stream asks for (EventSource's `retry:` field, also read by our page)."""

KEEPALIVE_FRAME = ": keep-alive\n\n"


class Subscriptions(Protocol):
    """What hands out viewers and takes them back: the bay runtime (or, in tests, its shot feed)."""

    def unsubscribe(self, viewer: Viewer) -> None: ...


SHOT_ID = re.compile(r"[0-9]{1,18}")
"""A shot id as this service writes them: ASCII digits (`str.isdigit` also takes "²", which `int` refuses), short
enough for `int` (which refuses over 4,300 digits)."""


def last_event_id(header: str | None) -> int | None:
    """The Last-Event-ID a reconnecting page sends, or None when absent or not a shot id of ours (the page then
    gets every kept shot, as a new page does)."""
    if header is None or not SHOT_ID.fullmatch(header.strip()):
        return None
    return int(header.strip())


def serving_server() -> Callable[[], bool]:
    """A test for "the server is shutting down": uvicorn's Server installs its `handle_exit` as the SIGTERM handler
    while it serves in a process's main thread (`golfflight serve`, each of its workers), and sets `should_exit`
    there; a server run elsewhere (in a thread, in tests) is never seen as stopping, and its streams end when their
    clients close them."""
    server = getattr(signal.getsignal(signal.SIGTERM), "__self__", None)
    if server is None or not hasattr(server, "should_exit"):
        return lambda: False
    return lambda: bool(server.should_exit)


async def events(
    feed: Subscriptions,
    viewer: Viewer,
    lifetime_s: float | None = None,
    keepalive_s: float = KEEPALIVE_S,
    stopping: Callable[[], bool] | None = None,
) -> AsyncIterator[str]:
    """The viewer's session (first, and again whenever a new one starts) and shots as server-sent events, with a
    keep-alive comment after every `keepalive_s` without one, until `lifetime_s` has passed (None: until the client
    goes, the server shuts down or it gives its place to a new stream, saying so in a comment); unsubscribes it
    however it ends."""
    stopping = serving_server() if stopping is None else stopping
    ends = None if lifetime_s is None else time.monotonic() + lifetime_s
    try:
        yield f"retry: {RETRY_MS}\n\n"
        quiet_since = time.monotonic()
        while not stopping():
            now = time.monotonic()
            if ends is not None and now >= ends:
                return
            if now - quiet_since >= keepalive_s:
                yield KEEPALIVE_FRAME
                quiet_since = now = time.monotonic()
            wait = min(SHUTDOWN_POLL_S, keepalive_s - (now - quiet_since))
            if ends is not None:
                wait = min(wait, ends - now)
            entry = await viewer.next(max(wait, 0.0))
            if viewer.ended is not None:  # it gave its place to a new stream
                yield f": {viewer.ended}\n\n"
                return
            text = "" if entry is None else frame(entry)
            if text:  # empty: nothing came, or a shot that cannot be shown (`frame`)
                yield text
                quiet_since = time.monotonic()
    finally:
        feed.unsubscribe(viewer)
