"""Rolling latency figures of the running service (GET /v1/latency): server-side simulation time and whole requests,
single shots and batches apart, fed by the same measurements as /metrics' histograms (`service.runtime.metrics`,
whose `kind` label they share)."""

from __future__ import annotations

from collections import deque
from typing import Literal

import numpy as np

Kind = Literal["shot", "batch"]
"""A single shot (POST /v1/shots, POST /v1/gspro, Open Connect over TCP) or a batch (POST /v1/shots/batch)."""
KINDS: tuple[Kind, ...] = ("shot", "batch")

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

