"""Each source's share of the sessions' shot memory: the shots kept per source (what came in where, from which
address), oldest first, and which source holds the most, found in constant time as shots come and go.

When the memory is full, the source holding the most lets its oldest shot go (`Sessions.add`): one connector's flood,
however many connections it opens from its address, pushes out only its own shots once it holds the most, and
never those of a source that holds fewer. A source's shots are kept in the order they came, so a session's shots
are each source's oldest until that session is forgotten (`drop_session`). Everything here runs on the service's
event loop thread.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable
from typing import Protocol


class Shot(Protocol):
    """What a share holds: a shot that knows its session."""

    session: int


class SourceShares:
    """The shots kept per source key, oldest first, and the source holding the most (the first to reach that count
    on a tie)."""

    def __init__(self) -> None:
        self._shots: dict[Hashable, deque[Shot]] = {}
        self._holding: dict[int, dict[Hashable, None]] = {}  # a count -> the sources holding it, in arrival order
        self._most = 0

    def add(self, source: Hashable, shot: Shot) -> None:
        """A new shot of `source`, its newest."""
        kept = self._shots.setdefault(source, deque())
        kept.append(shot)
        self._count(source, len(kept) - 1, len(kept))

    def largest_oldest(self) -> Shot:
        """Take the oldest shot of the source holding the most (there must be one) out of its share."""
        source = next(iter(self._holding[self._most]))
        return self._take(source)

    def drop_session(self, session: int) -> None:
        """Forget every shot of `session`, the oldest session kept (its shots are each source's oldest)."""
        for source in list(self._shots):
            kept = self._shots[source]
            while kept and kept[0].session == session:
                self._take(source)

    def _take(self, source: Hashable) -> Shot:
        kept = self._shots[source]
        shot = kept.popleft()
        if not kept:
            del self._shots[source]
        self._count(source, len(kept) + 1, len(kept))
        return shot

    def _count(self, source: Hashable, before: int, after: int) -> None:
        """Move `source` from the sources holding `before` shots to those holding `after`."""
        if before:
            holding = self._holding[before]
            del holding[source]
            if not holding:
                del self._holding[before]
        if after:
            self._holding.setdefault(after, {})[source] = None
        self._most = max(self._most, after)
        while self._most and self._most not in self._holding:
            self._most -= 1
