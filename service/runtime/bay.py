"""The server's simulator bay: one set of bay conditions (`contract.bay.BayConditions`) per server, set at start
(`golfflight serve --bay FILE`) and changed live (GET/PUT/PATCH /v1/bay), kept across restarts in FILE (written whole
or not at all, `shots.files.write_text_atomic`).

A file broken or removed while serving never stops a shot: the last good bay stays in force and `problem` says what
is wrong with the file (GET /healthz shows it as "degraded") until a PUT or PATCH writes it again. Only at start does
a broken file stop the server (`BayFileError`): there is no good bay to keep yet. The file is read on the shots'
path, so only a regular file of at most MAX_BAY_FILE_BYTES is read, opened without blocking: a FIFO in its place
would hang every shot waiting for a writer, a link to /dev/zero would be read for ever, a 1 GB file for seconds.

An edit of the file is also looked for every WATCH_S while the service runs (`watch`), not only at the next shot: a
change of player made there reaches connectors as Code 201 at once, apart from any shot's reply (noticed at the
next shot instead, the 201 went out 3.5 ms ahead of that shot's Code 200, and a connector that reads once per
shot took it for its reply). The file breaking and healing is logged, once each.
"""

from __future__ import annotations

import asyncio
import logging
import os
import stat
import threading
from collections.abc import Callable
from pathlib import Path

from golfflight.contract.bay import BayConditions, Player
from golfflight.errors import InputError
from golfflight.shots.files import write_text_atomic
from pydantic import ValidationError

log = logging.getLogger(__name__)

WATCH_S = 0.25
"""How often the bay file is looked at for an edit (one `stat`): a club changed there reaches connectors well
within a second."""

MAX_BAY_FILE_BYTES = 64 * 1024
"""Largest bay file read: bay conditions written by PUT /v1/bay take well under a kilobyte."""

KINDS = {stat.S_IFDIR: "a directory", stat.S_IFIFO: "a FIFO (named pipe)", stat.S_IFCHR: "a character device",
         stat.S_IFBLK: "a block device", stat.S_IFSOCK: "a socket"}
"""What a bay file that is not a regular file is, as the refusal says it."""

PlayerListener = Callable[[Player], None]
"""Told of the new player whenever the bay's player changes (Open Connect sends connectors Code 201)."""


class BayFileError(InputError):
    """A bay file that cannot be read as bay conditions: the message names the file and the field."""


class Bay:
    """The server's current bay conditions, and the file they are kept in (if any). Thread-safe: the HTTP routes
    and the Open Connect listener read it, PUT and PATCH /v1/bay change it. With a file, a change another worker
    process wrote there (`golfflight serve --workers N`) is read at the next use (one stat per read)."""

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = None if path is None else Path(path)
        self._lock = threading.Lock()
        self._conditions, self._stamp = BayConditions(), None
        self._problem: str | None = None
        self._listeners: list[PlayerListener] = []
        if self.path is not None and self._file_stamp() is not None:
            self._conditions, self._stamp = self._read(), self._file_stamp()
        elif self.path is not None:  # created now, as `serve --bay FILE` says: the file to edit is there at once
            try:
                self._set(self._conditions)
            except OSError as error:
                raise BayFileError(f"{self.path}: cannot be created ({error.strerror or error})") from None

    async def watch(self, every_s: float = WATCH_S) -> None:
        """Look at the bay file every `every_s` until cancelled, reading it when it changed (a player changed there is
        told to the listeners at once); nothing to do without a file."""
        if self.path is None:
            return
        while True:
            await asyncio.sleep(every_s)
            with self._lock:
                self._refresh()

    def on_player_change(self, listener: PlayerListener) -> None:
        """Call `listener` with the new player after each change of the bay's player (from any source)."""
        self._listeners.append(listener)

    @property
    def problem(self) -> str | None:
        """What is wrong with the bay file now (None: nothing): the last good bay is in force meanwhile."""
        with self._lock:
            self._refresh()
            return self._problem

    def _file_stamp(self) -> tuple[int, int, int, int] | None:
        """When its content and when its inode last changed, how long and which file (a replaced file is another
        inode): a change of any is read again. The inode's change time (ctime) moves with a chmod or chown too, so
        a file made unreadable (`chmod 000`) is reported at once, and one made readable again heals; with the
        content's time alone, neither was noticed (issue 55)."""
        try:
            info = self.path.stat()
        except OSError:
            return None
        return info.st_mtime_ns, info.st_ctime_ns, info.st_size, info.st_ino

    def _refresh(self) -> None:
        """Re-read the bay file if it changed since it was last read or written; a file that is gone or broken
        keeps the last good bay and says why in `problem`."""
        if self.path is None:
            return
        stamp = self._file_stamp()
        if stamp is None:
            if self._stamp is not None:
                self._broken(f"{self.path}: the bay file is gone; the last good bay stays in force until PUT /v1/bay "
                             "writes it again")
            return
        if stamp == self._stamp:
            return
        self._stamp = stamp
        try:
            conditions = self._read()
        except (BayFileError, OSError) as error:
            self._broken(f"{error}; the last good bay stays in force until PUT /v1/bay writes the file again")
            return
        self._broken(None)
        self._replace(conditions)

    def _broken(self, problem: str | None) -> None:
        """Set the file's problem (None: none), logging the moment it breaks and the moment it heals."""
        if problem and problem != self._problem:
            log.warning("bay file: %s", problem)
        elif problem is None and self._problem is not None:
            log.info("bay file: %s is bay conditions again; in force now", self.path)
        self._problem = problem

    def _bytes(self) -> bytes:
        """The bay file's bytes: a regular file of at most MAX_BAY_FILE_BYTES, opened without blocking (a FIFO
        would wait for a writer); BayFileError for anything else, OSError when it cannot be read."""
        descriptor = os.open(self.path, os.O_RDONLY | os.O_NONBLOCK)
        with open(descriptor, "rb") as file:
            info = os.fstat(descriptor)
            if not stat.S_ISREG(info.st_mode):
                kind = KINDS.get(stat.S_IFMT(info.st_mode), "not a file")
                raise BayFileError(f"{self.path}: is {kind}, not a regular file: a bay file is JSON text")
            data = file.read(MAX_BAY_FILE_BYTES + 1)
        if len(data) > MAX_BAY_FILE_BYTES:
            raise BayFileError(f"{self.path}: {info.st_size:,} bytes, over the {MAX_BAY_FILE_BYTES:,} a bay file may "
                               "have (bay conditions take under a kilobyte)")
        return data

    def _read(self) -> BayConditions:
        try:
            return BayConditions.model_validate_json(self._bytes())
        except ValidationError as error:
            problems = "; ".join(
                f"{'.'.join(str(p) for p in e['loc']) or 'body'}: {e['msg']}" for e in error.errors(include_url=False))
            raise BayFileError(f"{self.path}: not bay conditions ({problems})") from None
        except OSError as error:
            raise BayFileError(f"{self.path}: cannot be read ({error.strerror or error})") from None

    def _replace(self, conditions: BayConditions) -> None:
        changed = conditions.player != self._conditions.player
        self._conditions = conditions
        if changed:
            for listener in self._listeners:
                listener(conditions.player)

    @property
    def conditions(self) -> BayConditions:
        with self._lock:
            self._refresh()
            return self._conditions

    def update(self, change: Callable[[BayConditions], BayConditions]) -> BayConditions:
        """Apply `change` to the bay in force and keep the result (as `set`), with no other change in between: a
        PATCH changes only what it names even while another request changes the rest."""
        with self._lock:
            self._refresh()
            return self._set(change(self._conditions))

    def set(self, conditions: BayConditions) -> BayConditions:
        """Replace the bay's conditions, writing them to the bay file first (whole or not at all): a failed write
        leaves the bay as it was. A successful write clears the file's problem."""
        with self._lock:
            return self._set(conditions)

    def _set(self, conditions: BayConditions) -> BayConditions:
        if self.path is not None:
            write_text_atomic(self.path, conditions.model_dump_json(indent=2, exclude_none=True) + "\n")
            self._stamp = self._file_stamp()
            self._broken(None)
        self._replace(conditions)
        return conditions
