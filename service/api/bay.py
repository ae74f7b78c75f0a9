"""The simulator bay's conditions: the air, wind and ground a shot flies in when it brings none of its own, and the
units the bay's screen shows. A launch monitor's connector sends ball data only (GSPro Open Connect has no field for
the weather or the green): in a simulator the course's conditions come from the simulator, here from the bay.

One `BayConditions` per server, set at start (`golfflight serve --bay FILE`) and changed live (GET/PUT /v1/bay),
validated by the same request models and limits as a shot's conditions, and kept across restarts in FILE (written
whole or not at all, `shots.files.write_text_atomic`). A shot's own conditions win, field by field (`in_bay`).
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Literal

from golfflight.service.api.models import AirRequest, GroundRequest, ShotRequest, Strict, WindRequest
from golfflight.shots.files import write_text_atomic
from pydantic import Field, ValidationError

CONDITION_FIELDS = ("air", "wind", "ground")
BAY_FILE_ENV = "GOLFFLIGHT_BAY_FILE"
"""Where `golfflight serve --bay FILE` tells its worker processes the bay file is."""


class BayConditions(Strict):
    """What a shot without conditions of its own flies in, and the units the bay's screen shows; the same `air`,
    `wind` and `ground` objects as a shot request (omitted: ICAO standard air, calm, a level fairway)."""

    air: AirRequest | None = None
    wind: WindRequest | None = None
    ground: GroundRequest | None = None
    units: Literal["imperial", "metric"] = Field(
        "imperial", description="what the bay's screen shows: yards, mph and feet, or metres and m/s"
    )


def in_bay(shot: ShotRequest, bay: BayConditions) -> ShotRequest:
    """The shot with the bay's air, wind and ground wherever it gives none of its own."""
    updates = {name: getattr(bay, name) for name in CONDITION_FIELDS
               if getattr(shot, name) is None and getattr(bay, name) is not None}
    return shot.model_copy(update=updates) if updates else shot


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
