"""Batches fly in a child process of each server process, at a lower CPU priority than single shots.

With batches on a thread, a batch of 100 shared the GIL and the cores with the event loop, and single shots queued
behind it: p99 65 ms against 9.4 ms without batches (docs/reliability.md). A child process has its own GIL, and its
nice value lets the kernel run a waiting single shot first. The child (`service.runtime.batch_child`, no HTTP code)
loads and verifies the bundle itself. It gets the raw request body and reads and validates it itself: bytes cross
the process boundary for free, while pickling 100 parsed shots held the server's GIL for over a millisecond, and
validating 10,000 invalid shots on the server's event loop held every other client for hundreds of milliseconds
(issue 55). Only the few shots a screen shows come back as objects, with their states, or a refusal's details.

Batches go to the child one at a time, the rest waiting here: a child that dies fails only the batch it was flying,
and the batches queued behind it go to its replacement (with several in the pool, a dead child failed them all).

A child that dies (killed, out of memory) is replaced at once, not at the next batch: a watcher thread waits on
the child's process, starts another and loads the model in it while single shots keep flying, and `problem` says
so until it is ready (GET /healthz: "degraded"). The child ends by itself when its server dies
(`batch_child.start`).
"""

from __future__ import annotations

import asyncio
import multiprocessing
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.connection import wait
from multiprocessing.process import BaseProcess
from pathlib import Path

from golfflight.contract.bay import BayConditions
from golfflight.contract.refusals import RequestRefused
from golfflight.errors import ServiceError
from golfflight.service.runtime import batch_child

RETRY_S = 5.0
"""Pause before trying again to start a batch process that failed to start (e.g. its bundle gone meanwhile)."""

EXIT_CODE_WAIT_S = 0.5
"""Longest a watcher waits for a dead child's exit code once its pipe has closed (the pool's own thread may be
collecting it at that moment)."""


BATCH_PROCESS_DIED = "the batch process stopped while flying this batch (it has been restarted): send the batch again"


class BatchProcessDied(ServiceError):
    """The batch process died while flying a batch; the next one goes to its replacement (HTTP 503)."""


class BatchProcess:
    """One child process that flies batches, one at a time, replaced at once if it dies."""

    def __init__(self, bundle_dir: Path):
        self.bundle_dir = bundle_dir
        self.problem: str | None = None
        self.restarts = 0
        self._sha256: str | None = None
        self._stopping = False
        self._lock = threading.Lock()
        self._one_at_a_time = asyncio.Lock()
        self._pool = self._new_pool()

    def _new_pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            max_workers=1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=batch_child.start,
            initargs=(str(self.bundle_dir),),
        )

    def start(self) -> str:
        """Start the child and wait until it has loaded the model; returns the model's ONNX hash. From then on a
        watcher thread replaces the child whenever it dies."""
        pool = self._pool
        self._sha256, process = _ready(pool)
        watcher = threading.Thread(target=self._keep_alive, args=(pool, process), name="batch watcher", daemon=True)
        watcher.start()
        return self._sha256

    def health(self) -> dict[str, int]:
        """GET /healthz's figures: how many times the child died and was restarted since the server started."""
        return {"restarts": self.restarts}

    async def submit(
        self, body: bytes, shown: int = 0, bay: BayConditions | None = None
    ) -> batch_child.FlownBatch | RequestRefused:
        """A raw batch request body flown in the child (`batch_child.fly_and_encode`: the `bay`'s conditions filled
        in, the last `shown` shots kept), or its refusal, once the batches sent before it are done. A child found
        dead (or its pool just replaced by the watcher) before the batch is sent is replaced first; one that dies
        under this batch is replaced for the batches waiting behind it, and this one raises BatchProcessDied."""
        async with self._one_at_a_time:
            pool = self._pool
            try:
                future = pool.submit(batch_child.fly_and_encode, body, shown, bay)
            except (BrokenProcessPool, RuntimeError):  # RuntimeError: the watcher has just shut it down, replaced
                pool = self._replace(pool)
                future = pool.submit(batch_child.fly_and_encode, body, shown, bay)
            try:
                return await asyncio.wrap_future(future)
            except BrokenProcessPool:
                self._replace(pool)
                raise BatchProcessDied(BATCH_PROCESS_DIED) from None

    def _keep_alive(self, pool: ProcessPoolExecutor, process: BaseProcess | None) -> None:
        """Thread: each time the child dies while the server runs, start another at once and load the model in
        it, with `problem` saying so until it is ready."""
        while True:
            code = _exit_code(process)
            if self._stopping:
                return
            self.restarts += 1
            self.problem = f"the batch process died (exit code {code}) and is restarting"
            pool, process = self._restarted(pool)

    def _restarted(self, dead: ProcessPoolExecutor) -> tuple[ProcessPoolExecutor, BaseProcess | None]:
        """A new pool in place of `dead` and its child, once that has loaded the model (tried again every RETRY_S
        while it fails to); no child once the server stops."""
        pool = self._replace(dead)
        while not self._stopping:
            try:
                sha256, process = _ready(pool)
            except (BrokenProcessPool, RuntimeError) as error:  # RuntimeError: shut down as the server stops
                if not self._stopping:
                    self.problem = f"the batch process died and does not start again ({error}); retrying"
                    time.sleep(RETRY_S)
                    pool = self._replace(pool)
                continue
            self.problem = None if sha256 == self._sha256 else (
                "the restarted batch process loaded a different model (the bundle changed on disk): restart the server"
            )
            return pool, process
        return pool, None

    def _replace(self, broken: ProcessPoolExecutor) -> ProcessPoolExecutor:
        """A new pool in place of `broken`, unless another thread has replaced it already or the server stops."""
        with self._lock:
            if self._pool is broken and not self._stopping:
                broken.shutdown(wait=False)
                self._pool = self._new_pool()
            return self._pool

    def stop(self) -> None:
        """Let the batch in flight finish, then end the child, and replace it no more."""
        with self._lock:
            self._stopping = True
        self._pool.shutdown(wait=True)


def _ready(pool: ProcessPoolExecutor) -> tuple[str, BaseProcess | None]:
    """Wait until `pool`'s child has loaded the model: the model's hash and the child's process (None if it has
    ended already)."""
    sha256, pid = pool.submit(batch_child.ready).result()
    return sha256, next((child for child in multiprocessing.active_children() if child.pid == pid), None)


def _exit_code(process: BaseProcess | None) -> int | str:
    """Wait until `process` has ended; its exit code (negative: the signal that ended it), or "unknown"."""
    if process is None:
        return "unknown"
    wait([process.sentinel])
    deadline = time.monotonic() + EXIT_CODE_WAIT_S
    while process.exitcode is None and time.monotonic() < deadline:
        time.sleep(0.005)
    return "unknown" if process.exitcode is None else process.exitcode
