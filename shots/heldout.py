"""The real data that is held out (NOTES section 9): never trained on, never used to select a model.

One registry, checked wherever training data is assembled (`check_training_rows`): a held-out file, or a held-out
line of a file that is split in two, refuses the whole training set with the file and the lines named.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class HeldOutSet:
    """A held-out file (relative to the shared data folder), or its lines from `first_line` on (1-based, counting
    the header) where the earlier lines may be trained on."""

    name: str
    path: Path
    first_line: int = 1
    note: str = ""

    def holds(self, line: int) -> bool:
        return line >= self.first_line


HELD_OUT: tuple[HeldOutSet, ...] = (
    HeldOutSet(
        "TrackMan outdoor drivers, second half",
        Path("real/trackman_driver_sessions/data.csv"),
        first_line=2943,
        note="lines 1-2 are the header and units rows; lines 3-2942 may be trained on",
    ),
    HeldOutSet("TOUR Championship 2020 (East Lake)", Path("real/pga_tourcast_trackman/pbp/pbp_2020_060_688.csv")),
    HeldOutSet("PGA TOUR 2023 TrackMan averages", Path("reference/trackman_tour_averages_pga_2023.csv"),
               note="a check only"),
)


class HeldOutError(ValueError):
    """Held-out rows reached a training set."""


def held_out_set(path: str | os.PathLike) -> HeldOutSet | None:
    """The registry entry for a file, matched on its last path parts (wherever the shared folder is mounted)."""
    parts = Path(path).resolve().parts if Path(path).exists() else Path(path).parts
    for held in HELD_OUT:
        if parts[-len(held.path.parts):] == held.path.parts:
            return held
    return None


def check_training_rows(path: str | os.PathLike, lines: Iterable[int]) -> None:
    """Refuse (HeldOutError) if any of these source lines of `path` is held out; silent for every other file."""
    held = held_out_set(path)
    if held is None:
        return
    leaked = sorted(line for line in lines if held.holds(line))
    if leaked:
        shown = ", ".join(str(n) for n in leaked[:10]) + (", ..." if len(leaked) > 10 else "")
        raise HeldOutError(
            f"{path}: {len(leaked)} held-out rows ({held.name}, lines {held.first_line} on) would reach training: "
            f"lines {shown}"
        )
