"""Rolling latency figures of the running service: server-side simulation time and whole requests."""

from __future__ import annotations

import time
from collections import deque

import numpy as np

WINDOW = 10_000
"""Most recent samples kept per figure."""


class Rolling:
    """The last WINDOW durations (seconds) of one kind, summarised as milliseconds percentiles."""

    def __init__(self, window: int = WINDOW):
        self._samples: deque[float] = deque(maxlen=window)

    def add(self, seconds: float) -> None:
        self._samples.append(seconds)

    def summary(self) -> dict[str, float | int | None]:
        if not self._samples:
            return {"count": 0, "p50_ms": None, "p95_ms": None, "p99_ms": None}
        p50, p95, p99 = np.percentile(np.fromiter(self._samples, float), [50, 95, 99]) * 1e3
        return {"count": len(self._samples), "p50_ms": float(p50), "p95_ms": float(p95), "p99_ms": float(p99)}


class RequestTimer:
    """Pure ASGI middleware timing whole requests on the simulation routes (receipt to last byte sent)."""

    def __init__(self, app, rolling: Rolling, prefixes: tuple[str, ...]):
        self.app, self.rolling, self.prefixes = app, rolling, prefixes

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http" or not scope["path"].startswith(self.prefixes):
            await self.app(scope, receive, send)
            return
        started = time.perf_counter()
        try:
            await self.app(scope, receive, send)
        finally:
            self.rolling.add(time.perf_counter() - started)
