"""Rolling latency figures of the running service (GET /v1/latency): server-side simulation time and whole requests,
fed by the same measurements as /metrics' histograms (`service.runtime.metrics`)."""

from __future__ import annotations

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

