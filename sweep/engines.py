"""The ways a sweep's pieces are flown, each a generator of result tables in input order: `local_tables` (a pool of
processes on this machine, each with ONNX Runtime or its own torch engine), `ray_tables` (Ray Data on a local Ray
instance or an existing cluster) and `in_process_tables` (one engine in this process, whose parallelism is its
device's: the torch engine, a few pieces at once in threads so that the CPU's work overlaps the device's). Each worker
holds one `sweep.flyer.SweepWorker`, and at most a few pieces per worker are in flight, so memory stays bounded however long
the input is.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import re
import sys
import threading
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from contextlib import contextmanager
from multiprocessing import forkserver

from golfflight.errors import InputError
from golfflight.flight.environment_variables import environment
from golfflight.sweep.flyer import SweepWorker
from golfflight.sweep.stopping import exit_with_driver, group_signals_held

PIECES_PER_WORKER = 2
"""Pieces queued per local worker: one flying and one waiting, so a worker never idles while the driver writes."""

PIECES_IN_FLIGHT = 2
"""Pieces the in-process engine flies at once, each in a thread of its own: while one piece's flight keeps the device
busy, another's rows are checked and its landings rolled to rest, and the driver writes the last table (torch lets go
of Python's lock in its kernels and while it waits for the device, NumPy in its array work, pyarrow while it
writes)."""

WORKER_IMPORTS = ["golfflight.flight.engine", "golfflight.contract.flying", "golfflight.sweep.flyer"]
"""Modules the local pool's fork server imports before it forks the workers."""

_flyer: SweepWorker | None = None
"""The flyer of a local pool's worker process (made once by `_start_worker`)."""


def _start_worker(bundle_dir: str, sha256: str, source, make: Callable | None) -> None:
    """A local pool's worker: bound to the driver's life first (`sweep.stopping.exit_with_driver`), then its flyer."""
    global _flyer
    exit_with_driver()
    _flyer = SweepWorker(bundle_dir, sha256, source, make_engine=make)


def _fly(piece):
    return _flyer(piece)


def local_tables(source, bundle_dir: str, sha256: str, workers: int, make: Callable | None = None) -> Iterator:
    """Result tables of `source`'s pieces, flown by `workers` processes forked from a fresh server process that has
    imported the engine once (not from this one: the driver's Arrow and progress threads stay behind), each with
    ONNX Runtime or the engine `make` builds (`flight.torch_engine.TorchEngineMaker`: torch is imported, and a
    GPU taken, in each worker, never in the server)."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(WORKER_IMPORTS)
    with group_signals_held():  # the fork server and the resource tracker outlive a hangup to the process group
        forkserver.ensure_running()
        pool = ProcessPoolExecutor(
            workers,
            mp_context=context,
            initializer=_start_worker,
            initargs=(bundle_dir, sha256, source, make),
        )
    try:
        pending = deque()
        for piece in source.pieces():
            pending.append(pool.submit(_fly, piece))
            if len(pending) >= PIECES_PER_WORKER * workers:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
    except BaseException:  # a refused row, a failed write, a signal (`sweep.stopping`), or closed before the end
        _stop_workers(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _stop_workers(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's workers mid-piece: a sweep that stops early wants none of their results, and a piece can take
    seconds. A worker killed while it sends a result leaves half a message in the results' pipe, and the pool's
    manager thread would wait for the rest for ever (`shutdown` and the interpreter's exit with it): the driver closes
    its own copy of the pipe's write end, the only one left, so that the reader meets the pipe's end instead. Both
    are ProcessPoolExecutor's private attributes (Python 3.14's `terminate_workers` reads `_processes` too)."""
    for process in list((pool._processes or {}).values()):
        process.kill()
    pool._result_queue._writer.close()


def in_process_tables(source, flyer: SweepWorker, in_flight: int = PIECES_IN_FLIGHT) -> Iterator:
    """Result tables of `source`'s pieces flown by `flyer` in this process, `in_flight` pieces at once in threads, in
    input order (an engine that has the device to itself: a pool of processes would only share it; its engine
    takes pieces from several threads, `flight.torch_engine.TorchEngine`)."""
    pool = ThreadPoolExecutor(in_flight, thread_name_prefix="sweep-piece")
    try:
        pending = deque()
        for piece in source.pieces():
            pending.append(pool.submit(flyer, piece))
            if len(pending) > in_flight:  # one more waits, so a thread never idles while the driver writes
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


RAY_NOISE = (b"has constructor arguments in the object store and max_restarts > 0",)
"""Lines Ray's core worker prints in the driver (to its standard error, from C++: no logger to quiet) on every run,
about Ray Data's own actors, not the sweep's: Ray Data hands each actor of its pool its context and transform as
object references and lets it restart (ray-project/ray#53727). The sweep drops exactly these lines."""

LOG_HEAD = b"[dddd-dd-dd dd:dd:dd,ddd "
"""How a line of Ray's C++ log starts (`[2026-11-26 05:44:54,560 E 27196 27196] core_worker.cc:...`), d a digit."""


def _noise_lines(noise: tuple[bytes, ...]):
    head = re.escape(LOG_HEAD).replace(b"d", rb"\d")
    return re.compile(head + rb"[^\n]*?(?:" + b"|".join(re.escape(n) for n in noise) + rb")[^\n]*\n")


def _log_head_at(data: bytes, at: int) -> bool:
    """Whether a C++ log line starts, or may start (the data ends first), at `at`."""
    for char, want in zip(data[at : at + len(LOG_HEAD)], LOG_HEAD, strict=False):
        if not (chr(char).isdigit() if want == ord("d") else char == want):
            return False
    return True


def _unfinished_log_line(data: bytes) -> int:
    """Where an unfinished C++ log line begins in `data` (after its last newline), or len(data)."""
    at = data.rfind(b"\n") + 1
    while (at := data.find(b"[", at)) >= 0:
        if _log_head_at(data, at):
            return at
        at += 1
    return len(data)


@contextmanager
def ray_noise_filtered(noise: tuple[bytes, ...] = RAY_NOISE):
    """Standard error (file descriptor 2, which C++ writes to as well as Python) passed on through a pipe less Ray's
    log lines that hold one of `noise`; everything else, Ray's real errors included, goes through as it comes. Only
    the start of a C++ log line waits for the line's end (a progress bar's updates, ended by carriage returns, and
    Python's lines are passed on at once)."""
    try:
        sys.stderr.flush()
        original = os.dup(2)
    except (OSError, ValueError):  # no file descriptor 2 to filter
        yield
        return
    dropped = _noise_lines(noise)
    read_end, write_end = os.pipe()
    os.dup2(write_end, 2)
    os.close(write_end)

    def send(data: bytes) -> None:
        while data:
            data = data[os.write(original, data) :]

    def forward() -> None:
        held = b""
        while chunk := os.read(read_end, 65536):
            held = dropped.sub(b"", held + chunk)
            cut = _unfinished_log_line(held)
            send(held[:cut])
            held = held[cut:]
        send(held)

    thread = threading.Thread(target=forward, name="ray-stderr-filter", daemon=True)
    thread.start()
    try:
        yield
    finally:
        try:
            sys.stderr.flush()
        finally:
            os.dup2(original, 2)  # the pipe's last write end in this process: the thread reads to its end
            thread.join(timeout=5)  # a process Ray left running that inherited it would hold it open
            if not thread.is_alive():
                os.close(read_end)
            os.close(original)


def ray_tables(source, bundle_dir: str, sha256: str, workers: int | None, address: str | None,
               make_engine: Callable | None = None, gpus_per_actor: float = 0) -> Iterator:
    """Result tables of `source`'s pieces through Ray Data: `map_batches` with `SweepWorker` as a callable class on a pool
    of `workers` actors of one CPU each, order preserved. Each actor flies with ONNX Runtime, or with the engine
    `make_engine` builds on its node (the torch engine), asking Ray for `gpus_per_actor` GPUs instead of a CPU (a
    fraction: several actors share a GPU): then `workers` None is as many actors as the cluster's GPUs hold
    (`gpu_actors`), and one actor's engine is built on a GPU of the cluster before the sweep starts, so that a node
    without torch or CUDA is refused in one line.
    Connects to the cluster at `address` if given (and leaves it running), else starts a local Ray instance with a
    CPU for each worker and one for reading (every CPU and GPU of this machine for GPU actors), and stops it after."""
    import logging

    import ray
    import ray.data

    if environment().ray_data_log_level is None:  # Ray Data's INFO lines and its note that our tqdm replaced its bars
        logging.getLogger("ray.data").setLevel(logging.WARNING)
        logging.getLogger("ray.data._internal.progress").setLevel(logging.ERROR)
    with ray_noise_filtered():
        yield from _ray_tables(ray, source, bundle_dir, sha256, workers, address, make_engine, gpus_per_actor)


def gpu_actors(resources: dict, workers: int | None, gpus_per_actor: float) -> int:
    """The actors of a sweep on GPUs: `workers`, or as many as the cluster's GPUs (`resources`,
    `ray.cluster_resources()`) hold at `gpus_per_actor` each (1: one a GPU; 0.5: two) and its CPUs at one each beside
    the one that reads (Ray Data gives a GPU actor a CPU too); InputError where the cluster lists no GPU or fewer GPUs
    or CPUs than the actors need (an actor Ray cannot place, or a read with no CPU left, would wait for ever)."""
    gpus, cpus = int(resources.get("GPU", 0)), int(resources.get("CPU", 0))
    if gpus < gpus_per_actor:
        raise InputError(
            "--engine ray --device cuda: the Ray cluster lists no GPU (ray.cluster_resources() has none); start its "
            "nodes with their GPUs (ray start --num-gpus N, or a KubeRay worker group with nvidia.com/gpu), or sweep "
            "on CPUs without --device"
        )
    by_gpus = math.floor(gpus / gpus_per_actor + 1e-9)
    most = min(by_gpus, cpus - 1)
    if most < 1:
        raise InputError(f"--engine ray --device cuda: the Ray cluster lists {cpus} CPUs; each GPU actor takes one "
                         "and reading the launches one more")
    if workers is not None and workers > by_gpus:
        raise InputError(f"--workers {workers}: the Ray cluster lists {gpus} GPUs, and each actor takes "
                         f"{gpus_per_actor:g} (leave --workers out for {most} actors)")
    if workers is not None and workers > most:
        raise InputError(f"--workers {workers}: the Ray cluster lists {cpus} CPUs, and each actor takes one beside "
                         f"the one that reads (leave --workers out for {most} actors)")
    return most if workers is None else workers


def _engine_problem(make_engine: Callable, bundle_dir: str) -> str | None:
    """Why `make_engine` cannot build an engine here (a Ray task on a GPU node, as an actor would), or None."""
    try:
        make_engine(bundle_dir)
    except Exception as error:  # noqa: BLE001 - whatever stops an actor: no torch, no CUDA device, no bundle
        return f"{type(error).__name__}: {error}"
    return None


def check_actor_engine(ray, make_engine: Callable, bundle_dir: str, gpus: float) -> None:
    """Build one engine as an actor would, in a Ray task asking for `gpus` GPUs, before any actor starts; InputError
    saying why where it fails (a node without torch fails before the task runs: the error's last line says so)."""
    task = ray.remote(num_cpus=1, num_gpus=gpus, max_retries=0)(_engine_problem)
    try:
        problem = ray.get(task.remote(make_engine, bundle_dir))
    except Exception as error:  # noqa: BLE001 - Ray's own types: the task could not run (a module it lacks)
        problem = str(error).strip().splitlines()[-1]
    if problem:
        raise InputError(f"--engine ray: a worker of the Ray cluster cannot build the torch engine ({problem}); "
                         f"every node needs the train extra (torch), and a GPU node its CUDA driver")


def _ray_tables(ray, source, bundle_dir: str, sha256: str, workers: int | None, address: str | None,
                make_engine: Callable | None, gpus_per_actor: float) -> Iterator:
    from golfflight.sweep.ray_input import PiecesDatasource

    started = not ray.is_initialized()
    if started:
        ray.init(
            address=address,
            num_cpus=None if address or workers is None else workers + 1,
            include_dashboard=False,
            logging_level="WARNING",
        )
    try:
        if gpus_per_actor:
            workers = gpu_actors(ray.cluster_resources(), workers, gpus_per_actor)
            check_actor_engine(ray, make_engine, bundle_dir, gpus_per_actor)
        context = ray.data.DataContext.get_current()
        context.execution_options.preserve_order = True
        context.enable_progress_bars = False
        # The read task's worker exits when the input has been read (max_calls=1) instead of idling to the end with
        # Ray Data imported and the pieces it wrote: about 240 MB of RSS less for the rest of the sweep. The named
        # parameter of the Ray the `ray` extra pins (its ray_remote_args is deprecated there and goes away in 2.64).
        read = ray.data.read_datasource(PiecesDatasource(source), max_calls=1)
        dataset = read.map_batches(
            SweepWorker,
            fn_constructor_args=(bundle_dir, sha256, source, None, make_engine),
            compute=ray.data.ActorPoolStrategy(size=workers),
            batch_size=1,  # one piece (one row) a call: one engine batch of --chunk-rows shots
            batch_format="pyarrow",
            # A CPU each, or GPUs only: Ray Data warns that both at once is experimental for its map workers.
            **({"num_gpus": gpus_per_actor} if gpus_per_actor else {"num_cpus": 1}),
        )
        yield from dataset.iter_batches(batch_size=None, batch_format="pyarrow")
    finally:
        if started:
            ray.shutdown()
