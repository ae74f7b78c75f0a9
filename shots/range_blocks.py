"""The range blocks of the TrackMan driver file, which has no date or session column: runs of nearby measured lines
of one ball type. Training's conditions groups and the bootstrap's resampled blocks (`evaluation`) are the same."""

from __future__ import annotations

from golfflight.shots.records import ShotRecord

GAP_LINES = 3
"""A new block where more than 3 lines separate two measured shots (rows recorded indoors or dropped between)."""
BLOCK_SHOTS = 40
"""A new block after 40 shots: a range session is rarely longer, and one block never outweighs the rest."""


def driver_groups(records: list[ShotRecord]) -> list[str]:
    """A conditions group per record of the driver file (ids = file lines): runs of nearby lines of one ball type."""
    groups: list[str] = []
    previous: tuple[int, str | None] | None = None
    size = 0
    for record in records:
        line = int(record.shot_id)
        same = previous is not None and line - previous[0] <= GAP_LINES and record.ball == previous[1]
        if not same or size >= BLOCK_SHOTS:
            groups.append(f"L{line}")
            size = 0
        else:
            groups.append(groups[-1])
        size += 1
        previous = (line, record.ball)
    return groups
