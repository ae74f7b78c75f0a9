"""The real data that is held out: never trained on, never used to select a model (lines 2943 on of the TrackMan
driver file, rounds 3-4 of the TOUR Championship 2020).

One registry, checked wherever training data is assembled (`check_training_rows`): a held-out file, a held-out line
of a file that is split by lines, or a shot of a held-out round of a file that is split by rounds refuses the whole
training set with the file and the rows named.
"""

from __future__ import annotations

import csv
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from golfflight.errors import InputError

ROUND_COLUMN = "roundNumber"
"""The pbp column that names a row's round."""
TOUR_SHOT_ID = re.compile(r"^(?:.*:)?[^:-]+-R(?P<round>\d+)-H\d+-P[^-]+-S\d+(?:-f\d+)?$")
"""A canonical tour shot id (`shots.tourcast.shot_id`: tournament-R<round>-H<hole>-P<player>-S<shot>[-f<flight>]),
optionally behind a source prefix such as 'tour-championship-2020:'."""


@dataclass(frozen=True)
class HeldOutSet:
    """A held-out file (relative to the shared data folder): the whole file, its lines from `first_line` on (1-based,
    counting the header) where the earlier lines may be trained on, or, where `rounds` is not empty, only the shots
    of those rounds, the other rounds being trainable."""

    name: str
    path: Path
    first_line: int = 1
    note: str = ""
    rounds: tuple[int, ...] = ()

    @property
    def whole(self) -> bool:
        """Every row of the file is held out."""
        return self.first_line <= 1 and not self.rounds

    def holds(self, line: int) -> bool:
        """Whether a source line is held out by the line rule (a file split by rounds has none: see `holds_round`)."""
        return not self.rounds and line >= self.first_line

    def holds_round(self, round_number: int) -> bool:
        """Whether a round's shots are held out: the listed rounds, or every round of a file held out whole."""
        return round_number in self.rounds if self.rounds else self.whole

    def rows(self) -> str:
        """Which rows are held out, in words: 'all', 'lines 2943 on' or 'rounds 3-4'."""
        if self.rounds:
            return f"round{'s' if len(self.rounds) > 1 else ''} {_span(self.rounds)}"
        return "all" if self.whole else f"lines {self.first_line} on"


HELD_OUT: tuple[HeldOutSet, ...] = (
    HeldOutSet(
        "TrackMan outdoor drivers, second half",
        Path("real/trackman_driver_sessions/data.csv"),
        first_line=2943,
        note="lines 1-2 are the header and units rows; lines 3-2942 may be trained on",
    ),
    HeldOutSet(
        "TOUR Championship 2020 (East Lake)",
        Path("real/pga_tourcast_trackman/pbp/pbp_2020_060_688.csv"),
        rounds=(3, 4),
        note="rounds 1-2 may be trained on",
    ),
)


class HeldOutError(InputError):
    """Held-out rows reached a training set."""


def _span(numbers: tuple[int, ...]) -> str:
    """'3-4' for a run of consecutive numbers, '1, 3' otherwise."""
    if len(numbers) > 1 and list(numbers) == list(range(numbers[0], numbers[0] + len(numbers))):
        return f"{numbers[0]}-{numbers[-1]}"
    return ", ".join(str(n) for n in numbers)


def held_out_set(path: str | os.PathLike) -> HeldOutSet | None:
    """The registry entry for a file, matched on its last path parts (wherever the shared folder is mounted)."""
    parts = Path(path).resolve().parts if Path(path).exists() else Path(path).parts
    for held in HELD_OUT:
        if parts[-len(held.path.parts):] == held.path.parts:
            return held
    return None


def held_out_rounds(path: str | os.PathLike) -> tuple[int, ...]:
    """The rounds of a file that are held out; empty for a file that is not split by rounds."""
    held = held_out_set(path)
    return () if held is None else held.rounds


def shot_round(shot_id: str) -> int:
    """The round of a canonical tour shot id ('060-R3-H15-P29725-S1', also behind a 'source:' prefix);
    InputError where the id is not one."""
    match = TOUR_SHOT_ID.match(shot_id.strip())
    if match is None:
        raise InputError(f"{shot_id!r} is not a tour shot id such as '060-R3-H15-P29725-S1'")
    return int(match["round"])


def _id_line(shot_id: str) -> int:
    """The file line a TrackMan shot id names (the loader's id is the line; a 'source:' prefix is allowed)."""
    return int(shot_id.rsplit(":", 1)[-1])


def _line_rounds(path: str | os.PathLike, lines: set[int]) -> dict[int, int]:
    """The round (ROUND_COLUMN) of each of these lines of a pbp file (line 1 is the header)."""
    with Path(path).open(newline="", encoding="utf-8-sig") as handle:
        return {line: int(row[ROUND_COLUMN]) for line, row in enumerate(csv.DictReader(handle), start=2)
                if line in lines}


def _refuse(path: str | os.PathLike, held: HeldOutSet, what: str, leaked: list[str]) -> None:
    if leaked:
        shown = ", ".join(leaked[:10]) + (", ..." if len(leaked) > 10 else "")
        raise HeldOutError(f"{path}: {len(leaked)} held-out {what} ({held.name}, {held.rows()}) would reach "
                           f"training: {shown}")


def _held_lines(path: str | os.PathLike, held: HeldOutSet, lines: list[int]) -> list[str]:
    """The lines that are held out; in a file split by rounds, the lines of a held-out round (or whose round cannot
    be read: held out until shown otherwise)."""
    if not held.rounds or not lines:
        return [str(line) for line in sorted(lines) if held.holds(line)]
    try:
        rounds = _line_rounds(path, set(lines))
    except (OSError, KeyError, ValueError, TypeError) as error:
        raise HeldOutError(f"{path}: the rounds of lines {sorted(lines)[:10]} cannot be read ({error}); "
                           f"{held.rows()} are held out") from None
    return [str(line) for line in sorted(lines) if line not in rounds or held.holds_round(rounds[line])]


def _held_ids(held: HeldOutSet, shot_ids: list[str]) -> list[str]:
    """The shot ids that are held out: of a held-out round, or of a held-out line where the file is split by lines
    (its ids are lines); an id that names neither is held out until shown otherwise."""
    leaked = []
    for shot_id in shot_ids:
        try:
            held_out = held.holds_round(shot_round(shot_id)) if held.rounds else held.holds(_id_line(shot_id))
        except ValueError:
            held_out = True
        if held_out:
            leaked.append(shot_id)
    return leaked


def check_training_rows(path: str | os.PathLike, lines: Iterable[int] = (), shot_ids: Iterable[str] = ()) -> None:
    """Refuse (HeldOutError) training rows of `path` that are held out: any row of a file held out whole (even with
    no lines or ids named), a held-out line, or a shot id of a held-out round. Silent for every file not held out,
    and for a file split by lines or rounds when nothing held out is named."""
    held = held_out_set(path)
    if held is None:
        return
    if held.whole:
        raise HeldOutError(f"{path}: the whole file is held out ({held.name}) and would reach training")
    _refuse(path, held, "lines", _held_lines(path, held, list(lines)))
    _refuse(path, held, "shots", _held_ids(held, list(shot_ids)))
