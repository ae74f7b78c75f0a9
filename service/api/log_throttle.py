"""uvicorn's warnings about a client's malformed requests, at most one line each per LOG_EVERY_S: one client looping
garbage wrote 31,168 "Invalid HTTP request received." lines in 10 s (issue 55), a log that hides everything else."""

from __future__ import annotations

import logging
import time

LOG_EVERY_S = 10.0
"""Least time between two lines of one such warning; each line says how many were held back since the last."""

QUIETED = frozenset({"Invalid HTTP request received.", "Unsupported upgrade request."})
"""uvicorn's warnings that any client can cause at will, once per request."""


class OncePerInterval(logging.Filter):
    """Lets a record whose message is in `messages` through at most once per `every_s`, with the count held back
    since the last; every other record passes."""

    def __init__(self, messages: frozenset[str] = QUIETED, every_s: float = LOG_EVERY_S):
        super().__init__()
        self.messages, self.every_s = messages, every_s
        self._last: dict[str, float] = {}
        self._held: dict[str, int] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        message = record.msg
        if message not in self.messages:
            return True
        now = time.monotonic()
        if message in self._last and now - self._last[message] < self.every_s:
            self._held[message] = self._held.get(message, 0) + 1
            return False
        self._last[message] = now
        held = self._held.pop(message, 0)
        if held:
            record.msg = f"{message} ({held:,} more since the last such line)"
        return True


THROTTLE = OncePerInterval()
"""The one filter of the process, shared by every connection."""


def quieted(logger: logging.Logger) -> None:
    """Put THROTTLE on `logger` (uvicorn's error logger), once."""
    if THROTTLE not in logger.filters:
        logger.addFilter(THROTTLE)
