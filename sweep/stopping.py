"""How a sweep stops before its end. In the driver, SIGTERM, SIGINT (Ctrl-C) and SIGHUP raise `Interrupted`, so that
the way out removes the temporary output and stops the workers like any failure (`stopped_by_signals`). In a worker
of the local pool, a thread ends the process as soon as the driver is gone, however it went (SIGKILL included): a
worker waiting for its next piece would otherwise wait for ever, and hold the fork server and the resource tracker
up with it (`exit_with_driver`).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from multiprocessing.connection import wait

STOPPING_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)
"""What asks a sweep to stop: `kill`, a service manager or a container runtime; Ctrl-C; the terminal closed."""

GROUP_SIGNALS = (signal.SIGINT, signal.SIGHUP)
"""What a terminal sends its whole foreground process group, workers included: a worker ignores them and leaves
the stopping to the driver, which has a message to print and a file to remove."""


class Interrupted(BaseException):
    """A signal asked the sweep to stop. A BaseException, as KeyboardInterrupt is: no `except Exception` on the way
    out may take it for a failure of its own and carry on."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def status(self) -> int:
        """The shell's exit status for a process ended by this signal: 128 + its number (143 for SIGTERM, 130 for
        SIGINT, 129 for SIGHUP)."""
        return 128 + self.signum


@contextmanager
def stopped_by_signals() -> Iterator[None]:
    """Within the block, each of STOPPING_SIGNALS raises `Interrupted` in this (the main) thread, once: the handlers
    go back to the system's defaults as it is raised, so a second signal ends the process at once, the next run
    removing what it left. A signal this process was started ignoring (`nohup`, a background job) stays ignored, and
    one handled outside Python stays so; outside the main thread nothing changes (only it may set handlers)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {s: h for s in STOPPING_SIGNALS if (h := signal.getsignal(s)) not in (signal.SIG_IGN, None)}

    def stop(signum: int, frame) -> None:
        for s in before:
            signal.signal(s, signal.SIG_DFL)
        raise Interrupted(signum)

    for s in before:
        signal.signal(s, stop)
    try:
        yield
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)


@contextmanager
def group_signals_held() -> Iterator[None]:
    """GROUP_SIGNALS blocked in this thread within the block. Helper processes started in it, the resource tracker and
    the fork server, keep them blocked (a signal mask survives fork and exec; the tracker relies on that for SIGINT
    and SIGTERM, not SIGHUP): a terminal's hangup to the whole process group would otherwise kill them under the
    driver, which still needs them to stop its workers. The mask is this thread's: the driver still hears such a
    signal, through another thread or as the block ends."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, GROUP_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def exit_with_driver() -> None:
    """In a worker of a multiprocessing pool: ignore the terminal's GROUP_SIGNALS, and end this process as soon as
    the driver that started it is gone. The worker's parent is the fork server, not the driver, so PR_SET_PDEATHSIG
    would watch the wrong process; multiprocessing hands every child a sentinel of the process that asked for it
    instead (the read end of a pipe whose write end only the driver holds), which a thread here waits on."""
    for s in GROUP_SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    driver = multiprocessing.parent_process()
    if driver is None:
        return

    def watch() -> None:
        wait([driver.sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="sweep-driver-watch", daemon=True).start()
