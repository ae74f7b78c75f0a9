"""A session's shots as CSV (GET /v1/session.csv), in `golfflight simulate`'s columns: the launch in SI and the
conditions flown in as simulate reads them, `putt` for a putt (simulate rolls it as the bay did), then the result as
simulate writes it, so a session can be flown again (`golfflight simulate session.csv`: the same carries) or opened
in a spreadsheet. Who hit it, when and from where ride along in columns simulate passes over and echoes (`session`,
`player`, `source`, `club`, `timestamp`, `shot_number`); simulate passes over the result columns too.

The download is built on the event loop in slices of at most SLICE_S, each followed by a turn of the loop, over a
snapshot of the session taken when it is asked for: 10,000 shots take 1 to 3 s of pure Python, which in one piece
held every shot (HTTP and Open Connect) for that long. A thread would not help: it holds the GIL for the
interpreter's switch interval (5 ms) each time the loop's flight lets go of it for an ONNX Runtime call, hundreds of
times per shot. Every download in progress takes its slices from one `LoopTurns`, one slice per turn of the loop
over them all: 50 at once had taken 50 slices per turn, and single shots waited 376 ms (issue 55). Its rows are
made twice, once for the columns and once for the text, which is handed on piece by piece: a download whose client
reads nothing holds one piece and the snapshot's references, where the whole session's rows (13 MiB for 10,000
shots) stayed in memory until the client left."""

from __future__ import annotations

import csv
import io
import time
from collections.abc import AsyncIterator, Callable, Sequence
from datetime import UTC, datetime

from golfflight.contract.columns import PUTT, condition_cells, flat_row, result_columns
from golfflight.contract.inputs import launch_of
from golfflight.contract.requests import ShotRequest
from golfflight.service.runtime.sessions import SessionShot
from golfflight.service.viewer.loop_turns import LoopTurns

SHOT_COLUMNS = ("shot_id", "timestamp", "session", "player", "source", "club", "shot_number", PUTT)
"""Who, when and where from: `session` is the session's id, `player` its player's name, `source` where the shot came
in (http, batch, gspro-http, open-connect), `club` the GSPro club code of the bay's player when the shot was hit,
`putt` 1 for a putt."""

SLICE_S = 0.002
"""Longest the downloads work at once before they let the loop answer shots: a shot waits about this much per turn
of the loop it needs, however many downloads are in progress (`LoopTurns`)."""

LAUNCH_COLUMNS = ("ball_speed_mps", "launch_angle_deg", "launch_direction_deg", "spin_rpm", "spin_axis_deg")


EMPTY_SESSION_COLUMNS = (*SHOT_COLUMNS, *LAUNCH_COLUMNS,
                         *(c for c in result_columns(normalized=False, flat=False) if c != "error"))
"""An empty session's header: the columns every shot's row has (who, its launch, its flight; 38), so that its CSV
opens with the columns a session of shots in the default bay has (it had the first 8 only). A row adds the
conditions it flew in and a flat flight where the ground lies off the tee's height."""


def request_cells(request: ShotRequest) -> dict:
    """A request's launch (SI), its conditions and its `normalized` flag as simulate's input columns
    (`contract.columns`)."""
    cells = dict(zip(LAUNCH_COLUMNS, launch_of(request), strict=True))
    if request.normalized:
        cells["normalized"] = 1
    return {**cells, **condition_cells(request)}


def _row(shot: SessionShot, player: str | None) -> dict:
    when = datetime.fromtimestamp(shot.received_unix_s, UTC).isoformat(timespec="milliseconds")
    club = "" if shot.player is None else shot.player.club
    own = {"shot_id": shot.id, "timestamp": when, "session": shot.session, "player": player or "",
           "source": shot.source, "club": club, "shot_number": "" if shot.shot_number is None else shot.shot_number,
           PUTT: int(shot.putt)}
    return {**own, **request_cells(shot.request), **flat_row(shot.result.model_dump(exclude_none=True))}


async def session_csv_slices(shots: Sequence[SessionShot], slice_s: float = SLICE_S, player: str | None = None,
                             turns: LoopTurns | None = None) -> AsyncIterator[str]:
    """The shots (of a session played by `player`) as CSV text, one row each, in pieces, each made in at most about
    `slice_s` at a turn of the event loop that `turns` (shared by every download of the service) gives: the columns
    first (in the order they first appear, known only once every row was made; an empty piece after each turn), then
    the text, each piece handed on as it is made, so a download holds one piece, never the whole session."""
    turns = turns if turns is not None else LoopTurns()
    columns = dict.fromkeys(SHOT_COLUMNS if shots else EMPTY_SESSION_COLUMNS)
    async for _ in _in_turns(shots, lambda shot: columns.update(dict.fromkeys(_row(shot, player))), slice_s, turns):
        yield ""  # no text yet: a turn at which the caller may stop, its client gone
    out = io.StringIO()
    writer = csv.DictWriter(out, list(columns), restval="", lineterminator="\n")
    writer.writeheader()
    async for _ in _in_turns(shots, lambda shot: writer.writerow(_row(shot, player)), slice_s, turns):
        yield _taken(out)
    rest = _taken(out)
    if rest:
        yield rest


async def _in_turns(shots: Sequence[SessionShot], each: Callable[[SessionShot], object], slice_s: float,
                    turns: LoopTurns) -> AsyncIterator[None]:
    """`each` of the shots, at most about `slice_s` of them at each turn `turns` gives; yields after each."""
    position = 0
    while position < len(shots):
        await turns.turn()
        deadline = time.perf_counter() + slice_s
        while position < len(shots):
            each(shots[position])
            position += 1
            if time.perf_counter() >= deadline:
                break
        yield


def _taken(out: io.StringIO) -> str:
    """The text written to `out` so far, `out` emptied."""
    text = out.getvalue()
    out.seek(0)
    out.truncate()
    return text
