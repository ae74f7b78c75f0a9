"""The viewer's live feed as server-sent events (`GET /v1/events`).

Server-sent events rather than a WebSocket: the feed only flows from the service to the page, and SSE is a plain
HTTP GET, so the API key check, CORS and proxies treat it like any other route; uvicorn serves WebSockets only
with a `websockets` or `wsproto` package, which the serving install does not have. The page reads the stream with
fetch() rather than EventSource, which cannot send the X-API-Key header.

Each stream ends after LIFETIME_S and the page reconnects at once with Last-Event-ID, losing nothing (the feed
keeps its last shots): uvicorn's graceful shutdown waits for open responses, so an endless stream would hold a
SIGTERM up for the whole grace period.
"""

from __future__ import annotations

import time
from collections.abc import AsyncIterator

from service.engine import FlightEngine
from service.viewer.feed import ShotFeed, Viewer

LIFETIME_S = 5.0
"""How long one stream stays open before the page reconnects."""

RETRY_MS = 500
"""The reconnection delay the stream asks for (EventSource's `retry:` field, also read by our page)."""


def last_event_id(header: str | None) -> int | None:
    """The Last-Event-ID a reconnecting page sends, or None when absent or not a shot id."""
    return int(header) if header is not None and header.strip().isdigit() else None


async def events(
    feed: ShotFeed, viewer: Viewer, engine: FlightEngine, lifetime_s: float = LIFETIME_S
) -> AsyncIterator[str]:
    """The viewer's shots as server-sent events until `lifetime_s` has passed; unsubscribes it however it ends."""
    ends = time.monotonic() + lifetime_s
    try:
        yield f"retry: {RETRY_MS}\n\n"
        while (left := ends - time.monotonic()) > 0:
            entry = await viewer.next(left)
            frame = None if entry is None else feed.frame(entry, engine)
            if frame is not None:
                yield frame
    finally:
        feed.unsubscribe(viewer)
