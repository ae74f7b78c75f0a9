"""The session's shots as CSV (GET /v1/session.csv), in `golfflight simulate`'s columns: the launch in SI and the
conditions flown in as simulate reads them, then the result as simulate writes it, so a session can be flown again
(`golfflight simulate session.csv`) or opened in a spreadsheet. Who hit it, when and from where ride along in
columns simulate passes over (`session`, `club`, `timestamp`)."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from datetime import UTC, datetime

from golfflight.contract.columns import AIR_COLUMNS, GROUND_COLUMNS, WIND_COLUMNS, flat_row
from golfflight.contract.inputs import launch_of
from golfflight.contract.requests import ShotRequest
from golfflight.service.runtime.feed import SessionShot

SHOT_COLUMNS = ("shot_id", "timestamp", "session", "club", "putt", "shot_number")
"""Who, when and where from: `session` is the source (http, batch, gspro-http, open-connect), `club` the GSPro club
code of the bay's player when the shot was hit."""

LAUNCH_COLUMNS = ("ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm", "spin_axis_deg")


def request_cells(request: ShotRequest) -> dict:
    """A request's launch (SI) and conditions as simulate's input columns (`contract.columns`)."""
    cells = dict(zip(LAUNCH_COLUMNS, launch_of(request), strict=True))
    for part, columns in ((request.air, AIR_COLUMNS), (request.wind, WIND_COLUMNS), (request.ground, GROUND_COLUMNS)):
        if part is not None:
            named = {field: column for column, field in columns.items()}
            cells.update({named[k]: v for k, v in part.model_dump(exclude_none=True).items() if k in named})
    return cells


def _row(shot: SessionShot) -> dict:
    when = datetime.fromtimestamp(shot.received_unix_s, UTC).isoformat(timespec="milliseconds")
    club = "" if shot.player is None else shot.player.club
    own = {"shot_id": shot.id, "timestamp": when, "session": shot.source, "club": club, "putt": int(shot.putt),
           "shot_number": "" if shot.shot_number is None else shot.shot_number}
    return {**own, **request_cells(shot.request), **flat_row(shot.result.model_dump(exclude_none=True))}


def session_csv(shots: Iterable[SessionShot]) -> str:
    """The shots as CSV text, one row each, columns in the order they first appear."""
    rows = [_row(shot) for shot in shots]
    columns = list(dict.fromkeys(name for row in ([dict.fromkeys(SHOT_COLUMNS)] + rows) for name in row))
    out = io.StringIO()
    writer = csv.DictWriter(out, columns, restval="", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()
