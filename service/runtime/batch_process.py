"""Batches fly in a child process of each server process, at a lower CPU priority than single shots.

With batches on a thread, a batch of 100 shared the GIL and the cores with the event loop, and single shots queued
behind it: p99 65 ms against 9.4 ms without batches (docs/reliability.md). A child process has its own GIL, and its
nice value lets the kernel run a waiting single shot first. The child (`service.runtime.batch_child`, no HTTP code)
loads and verifies the bundle itself. It gets the request body the server has already validated and parses it
again: bytes cross the process boundary for free, while pickling 100 parsed shots held the server's GIL for over a
millisecond. Only the few shots a screen shows come back as objects, with their states.
"""

from __future__ import annotations

import asyncio
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from golfflight.service.runtime import batch_child


class BatchProcess:
    """One child process that flies batches, one at a time, replaced if it dies."""

    def __init__(self, bundle_dir: Path):
        self.bundle_dir = bundle_dir
        self._pool = self._new_pool()

    def _new_pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            max_workers=1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=batch_child.start,
            initargs=(str(self.bundle_dir),),
        )

    def start(self) -> str:
        """Start the child and wait until it has loaded the model; returns the model's ONNX hash."""
        return self._pool.submit(batch_child.ready).result()

    async def submit(self, body: bytes, shown: int = 0) -> tuple[bytes, float, batch_child.Shown]:
        """The encoded BatchResult of a validated BatchRequest body, the simulation seconds, and the last `shown`
        shots with their states (`batch_child.fly_and_encode`). A child found dead
        (killed, out of memory) is replaced before the batch is sent; one that dies under this batch is replaced
        for the next and this one raises BrokenProcessPool."""
        pool = self._pool
        try:
            future = pool.submit(batch_child.fly_and_encode, body, shown)
        except BrokenProcessPool:
            pool = self._replace(pool)
            future = pool.submit(batch_child.fly_and_encode, body, shown)
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
