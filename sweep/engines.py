"""The two ways a sweep's pieces are flown, each a generator of result tables in input order: `local_tables` (a pool
of processes on this machine) and `ray_tables` (Ray Data on a local Ray instance or an existing cluster). Either
way each worker holds one `sweep.flyer.Flyer`, and at most a few pieces per worker are in flight, so memory stays
bounded however long the input is.
"""

from __future__ import annotations

import multiprocessing
import os
from collections import deque
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor

from sweep.flyer import Flyer

PIECES_PER_WORKER = 2
"""Pieces queued per local worker: one flying and one waiting, so a worker never idles while the driver writes."""

WORKER_IMPORTS = ["service.engine", "service.api.shots", "sweep.flyer"]
"""Modules the local pool's fork server imports before it forks the workers."""

_flyer: Flyer | None = None
"""The flyer of a local pool's worker process (made once by `_start_worker`)."""


def _start_worker(bundle_dir: str, sha256: str, source) -> None:
    global _flyer
    _flyer = Flyer(bundle_dir, sha256, source)


def _fly(piece):
    return _flyer(piece)


def local_tables(source, bundle_dir: str, sha256: str, workers: int) -> Iterator:
    """Result tables of `source`'s pieces, flown by `workers` processes forked from a fresh server process that has
    imported the engine once (not from this one: the driver's Arrow and progress threads stay behind)."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(WORKER_IMPORTS)
    pool = ProcessPoolExecutor(
        workers,
        mp_context=context,
        initializer=_start_worker,
        initargs=(bundle_dir, sha256, source),
    )
    try:
        pending = deque()
        for piece in source.pieces():
            pending.append(pool.submit(_fly, piece))
            if len(pending) >= PIECES_PER_WORKER * workers:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def ray_tables(source, bundle_dir: str, sha256: str, workers: int, address: str | None) -> Iterator:
    """Result tables of `source`'s pieces through Ray Data: `map_batches` with `Flyer` as a callable class on a pool
    of `workers` actors of one CPU each, order preserved. Connects to the cluster at `address` if given (and leaves
    it running), else starts a local Ray instance with a CPU for each worker and one for reading, and stops it
    after."""
    import logging

    import ray
    import ray.data

    from sweep.ray_input import PiecesDatasource

    if "RAY_DATA_LOG_LEVEL" not in os.environ:  # Ray Data's INFO lines and its note that our tqdm replaced its bars
        logging.getLogger("ray.data").setLevel(logging.WARNING)
        logging.getLogger("ray.data._internal.progress").setLevel(logging.ERROR)
    started = not ray.is_initialized()
    if started:
        ray.init(
            address=address,
            num_cpus=None if address else workers + 1,
            include_dashboard=False,
            logging_level="WARNING",
        )
    try:
        context = ray.data.DataContext.get_current()
        context.execution_options.preserve_order = True
        context.enable_progress_bars = False
        # The read task's worker exits when the input has been read (max_calls=1) instead of idling to the end with
        # Ray Data imported and the pieces it wrote: about 240 MB of RSS less for the rest of the sweep.
        read = ray.data.read_datasource(PiecesDatasource(source), ray_remote_args={"max_calls": 1})
        dataset = read.map_batches(
            Flyer,
            fn_constructor_args=(bundle_dir, sha256, source),
            compute=ray.data.ActorPoolStrategy(size=workers),
            batch_size=1,  # one piece (one row) a call: one engine batch of --chunk-rows shots
            batch_format="pyarrow",
            num_cpus=1,
        )
        yield from dataset.iter_batches(batch_size=None, batch_format="pyarrow")
    finally:
        if started:
            ray.shutdown()
