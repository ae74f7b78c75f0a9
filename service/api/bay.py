"""The server's simulator bay: one set of bay conditions (`contract.bay.BayConditions`) per server, set at start
(`golfflight serve --bay FILE`) and changed live (GET/PUT /v1/bay), kept across restarts in FILE (written whole or
not at all, `shots.files.write_text_atomic`).
"""

from __future__ import annotations

import threading
from pathlib import Path

from golfflight.contract.bay import BayConditions
from golfflight.shots.files import write_text_atomic
from pydantic import ValidationError

BAY_FILE_ENV = "GOLFFLIGHT_BAY_FILE"
"""Where `golfflight serve --bay FILE` tells its worker processes the bay file is."""


class BayFileError(ValueError):
    """A bay file that cannot be read as bay conditions: the message names the file and the field."""


class Bay:
    """The server's current bay conditions, and the file they are kept in (if any). Thread-safe: the HTTP routes
    and the Open Connect listener read it, PUT /v1/bay replaces it. With a file, a change another worker process
    wrote there (`golfflight serve --workers N`) is read at the next use (one stat per read)."""

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = None if path is None else Path(path)
        self._lock = threading.Lock()
        self._conditions, self._stamp = BayConditions(), None
        self._refresh()

    def _file_stamp(self) -> int | None:
        try:
            return self.path.stat().st_mtime_ns
        except OSError:
            return None

    def _refresh(self) -> None:
        """Re-read the bay file if it changed since it was last read or written."""
        if self.path is None:
            return
        stamp = self._file_stamp()
        if stamp is not None and stamp != self._stamp:
            self._conditions, self._stamp = self._read(), stamp

    def _read(self) -> BayConditions:
        try:
            return BayConditions.model_validate_json(self.path.read_text())
        except ValidationError as error:
            problems = "; ".join(
                f"{'.'.join(str(p) for p in e['loc']) or 'body'}: {e['msg']}" for e in error.errors(include_url=False))
            raise BayFileError(f"{self.path}: not bay conditions ({problems})") from None

    @property
    def conditions(self) -> BayConditions:
        with self._lock:
            self._refresh()
            return self._conditions

    def set(self, conditions: BayConditions) -> BayConditions:
        """Replace the bay's conditions, writing them to the bay file first (whole or not at all): a failed write
        leaves the bay as it was."""
        with self._lock:
            if self.path is not None:
                write_text_atomic(self.path, conditions.model_dump_json(indent=2, exclude_none=True) + "\n")
                self._stamp = self._file_stamp()
            self._conditions = conditions
            return conditions
