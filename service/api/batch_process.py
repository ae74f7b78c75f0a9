"""Batches fly in a child process of each server process, at a lower CPU priority than single shots.

With batches on a thread, a batch of 100 shared the GIL and the cores with the event loop, and single shots queued
behind it: p99 65 ms against 9.4 ms without batches (docs/reliability.md). A child process has its own GIL, and its
nice value lets the kernel run a waiting single shot first. The child loads and verifies the bundle itself. It gets
the request body the server has already validated and parses it again: bytes cross the process boundary for free,
while pickling 100 parsed shots held the server's GIL for over a millisecond.
"""

from __future__ import annotations

import asyncio
import multiprocessing
import os
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from golfflight.contract.flying import fly_shots
from golfflight.contract.requests import BatchRequest
from golfflight.contract.results import BatchResult
from golfflight.service.engine import FlightEngine

BATCH_NICE = 19
"""How much lower the batch process's CPU priority is (Linux nice increment): a single shot waiting for a core
gets it first, a batch still gets the cores nobody else wants."""

_engine: FlightEngine | None = None


def _start(bundle_dir: str) -> None:
    """Child initializer: lower the priority, ignore the terminal's Ctrl-C (the parent decides when the child
    stops, after its in-flight batch), load the bundle."""
    global _engine
    os.nice(BATCH_NICE)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    _engine = FlightEngine(bundle_dir)


def _ready() -> str:
    """The loaded model's ONNX hash: the parent checks the child serves the same model it does."""
    assert _engine is not None
    return _engine.sha256


def _fly_and_encode(body: bytes) -> tuple[bytes, float]:
    """The JSON response body for a valid batch request body, and the seconds its simulation took."""
    assert _engine is not None
    shots = BatchRequest.model_validate_json(body).shots
    started = time.perf_counter()
    results = fly_shots(_engine, shots)
    seconds = time.perf_counter() - started
    return BatchResult(results=results).model_dump_json(exclude_none=True).encode(), seconds


class BatchProcess:
    """One child process that flies batches, one at a time, replaced if it dies."""

    def __init__(self, bundle_dir: Path):
        self.bundle_dir = bundle_dir
        self._pool = self._new_pool()

    def _new_pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            max_workers=1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_start,
            initargs=(str(self.bundle_dir),),
        )

    def start(self) -> str:
        """Start the child and wait until it has loaded the model; returns the model's ONNX hash."""
        return self._pool.submit(_ready).result()

    async def submit(self, body: bytes) -> tuple[bytes, float]:
        """The encoded BatchResult of a validated BatchRequest body, and the simulation seconds. A child found dead
        (killed, out of memory) is replaced before the batch is sent; one that dies under this batch is replaced
        for the next and this one raises BrokenProcessPool."""
        pool = self._pool
        try:
            future = pool.submit(_fly_and_encode, body)
        except BrokenProcessPool:
            pool = self._replace(pool)
            future = pool.submit(_fly_and_encode, body)
        try:
            return await asyncio.wrap_future(future)
        except BrokenProcessPool:
            self._replace(pool)
            raise

    def _replace(self, broken: ProcessPoolExecutor) -> ProcessPoolExecutor:
        """A new pool in place of `broken`, unless a concurrent batch has replaced it already."""
        if self._pool is broken:
            broken.shutdown(wait=False)
            self._pool = self._new_pool()
        return self._pool

    def stop(self) -> None:
        """Let the batch in flight finish, then end the child."""
        self._pool.shutdown(wait=True)
