"""End a process spawned by `multiprocessing` as soon as the process that spawned it has gone, however it went
(kill -9, the kernel's OOM killer): the batch child of each server process, and each worker of `golfflight serve
--workers N` (uvicorn spawns them), which would otherwise live on with their models, ignoring SIGTERM or holding the
port.

The pipe a spawned process was started through reads end of file when its parent dies, even before the watching
thread begins. Not PR_SET_PDEATHSIG: that fires when the parent's *thread* that spawned the child ends, and a
process pool spawns from whichever of its parent's threads submitted first.
"""

from __future__ import annotations

import multiprocessing
import os
import threading

ORPHANED = 70
"""The exit code of a process that ended because the process that spawned it had gone."""


def _exit_when_parent_goes() -> None:
    multiprocessing.parent_process().join()
    os._exit(ORPHANED)


def exit_with_parent() -> bool:
    """In a process spawned by `multiprocessing`, start a daemon thread that ends it (exit code ORPHANED) once its
    parent has gone, and return True; elsewhere (a process started otherwise) do nothing and return False."""
    if multiprocessing.parent_process() is None:
        return False
    threading.Thread(target=_exit_when_parent_goes, name="exit with the parent", daemon=True).start()
    return True
