"""The bay's sessions: each a player's run of shots, the one the bay's shots go to now the last started. The service
starts with session 1; POST /v1/sessions starts the next (`ShotFeed.start_session` also empties the screens).

Memory is bounded over all sessions: at most MAX_SHOTS shots are kept, shared among their sources (`shares`: the
oldest shot of the source holding the most goes first, counted as dropped in its session), and at most MAX_SESSIONS
sessions (starting one more forgets the oldest, with its shots). Each session keeps its clubs' running sums
(`club_stats`), updated as shots come and go, so its summary never walks its shots. Everything here runs on the
service's event loop thread.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from collections.abc import ValuesView
from dataclasses import dataclass, field
from typing import Literal, NamedTuple

from golfflight.contract.bay import Player
from golfflight.contract.clubs import GSPRO_CLUBS
from golfflight.contract.requests import ShotRequest
from golfflight.contract.results import ShotResult
from golfflight.contract.session import ClubSummary, SessionInfo, SessionList, SessionSummary
from golfflight.service.runtime.club_stats import ELLIPSE_PROBABILITY, ClubStats, figures
from golfflight.service.runtime.shares import SourceShares

Source = Literal["http", "batch", "gspro-http", "open-connect"]
"""Where a shot came in: POST /v1/shots, POST /v1/shots/batch, POST /v1/gspro, GSPro Open Connect over TCP."""

MAX_SHOTS = 10_000
"""Shots kept over all sessions (their CSV and summaries): a long range session; about 4 kB each, 40 MB in all. Past
it, the source holding the most shots (`SessionShot.share`: where they came in and from which address) lets its
oldest go, so no source's flood can push out the shots of one that holds fewer: before (issue 55) the oldest shot
of all went first, and 8 connections at 600 shots a second emptied an older session of 300 shots in 18 s."""

MAX_SESSIONS = 100
"""Sessions kept: starting one more forgets the oldest, and its shots."""

class SessionShot(NamedTuple):
    """One shot of a session as its download lists it: when, where from, who hit it, what flew, what came out."""

    id: int
    received_unix_s: float
    source: Source
    shot_number: int | None
    player: Player | None
    putt: bool
    request: ShotRequest
    result: ShotResult
    session: int = 0
    client: str = ""

    @property
    def share(self) -> tuple[str, str]:
        """The share of the session memory it counts in: where it came in and the address it came from (a connector's
        connections from one machine share one; a proxy's clients share its address)."""
        return self.source, self.client


ClubKey = tuple[str | None, bool]
"""A club's summary key: its GSPro code (None for shots without a player) and whether these are putts."""

BAG_ORDER = {code: i for i, code in enumerate(GSPRO_CLUBS)}


def _club_of(shot: SessionShot) -> ClubKey:
    return (None if shot.player is None else shot.player.club, shot.putt)


def _bag_place(key: ClubKey) -> tuple[int, int]:
    """Where a club's summary stands: full shots in the bag's order, then putts, then shots without a club."""
    club, putts = key
    return (2 if club is None else int(putts), BAG_ORDER.get(club, len(BAG_ORDER)))


@dataclass(eq=False)
class Session:
    """One session: who and since when, its shots kept (by id, oldest first), how many were dropped by the cap, and
    its clubs' running sums."""

    id: int
    player: str | None
    started_unix_s: float
    kept: dict[int, SessionShot] = field(default_factory=dict)
    dropped: int = 0
    clubs: dict[ClubKey, ClubStats] = field(default_factory=dict)

    @property
    def shots(self) -> ValuesView[SessionShot]:
        """Its shots kept, oldest first."""
        return self.kept.values()

    def add(self, shot: SessionShot) -> None:
        self.kept[shot.id] = shot
        key, numbers = _club_of(shot), figures(shot.result)
        self.clubs.setdefault(key, ClubStats(numbers)).add(numbers)

    def drop(self, shot: SessionShot) -> None:
        """Let a shot go (the cap): out of the shots and out of its club's sums."""
        del self.kept[shot.id]
        self.dropped += 1
        key = _club_of(shot)
        stats = self.clubs[key]
        stats.add(figures(shot.result), sign=-1)
        if stats.n == 0:
            del self.clubs[key]

    def info(self, current: bool) -> SessionInfo:
        return SessionInfo(id=self.id, player=self.player, started_unix_s=self.started_unix_s, shots=len(self.shots),
                           dropped_shots=self.dropped, current=current)

    def club_summaries(self) -> list[ClubSummary]:
        """Each club's summary in the bag's order, each full-shot club's carry gap to the next shorter one."""
        keys = sorted(self.clubs, key=_bag_place)
        rows = [self.clubs[key].summary(*key) for key in keys]
        gapped = [row for row in rows if row.club is not None and not row.putts]
        for longer, shorter in zip(gapped, gapped[1:]):
            longer.carry_gap_m = longer.carry.mean_m - shorter.carry.mean_m
        return rows


class Sessions:
    """The sessions kept, oldest first; the last is the current one."""

    def __init__(self, max_shots: int = MAX_SHOTS, max_sessions: int = MAX_SESSIONS):
        self.max_shots, self.max_sessions = max_shots, max_sessions
        self._kept: OrderedDict[int, Session] = OrderedDict()
        self._next_id = 1
        self._shots = 0
        self._shares = SourceShares()
        self.start(None)

    @property
    def current(self) -> Session:
        return next(reversed(self._kept.values()))

    def start(self, player: str | None) -> Session:
        """A new current session (the oldest forgotten, with its shots, past `max_sessions`)."""
        session = Session(self._next_id, player, time.time())
        self._next_id += 1
        self._kept[session.id] = session
        while len(self._kept) > self.max_sessions:
            _, forgotten = self._kept.popitem(last=False)
            self._shots -= len(forgotten.shots)
            self._shares.drop_session(forgotten.id)
        return session

    def get(self, session_id: int | None) -> Session | None:
        """A kept session by id (None: the current one), or None when it is not kept."""
        return self.current if session_id is None else self._kept.get(session_id)

    def add(self, shot: SessionShot) -> None:
        """A shot of the current session; past `max_shots`, the oldest shot of the source holding the most goes."""
        shot = shot._replace(session=self.current.id)
        self.current.add(shot)
        self._shares.add(shot.share, shot)
        self._shots += 1
        while self._shots > self.max_shots:
            dropped = self._shares.largest_oldest()
            self._kept[dropped.session].drop(dropped)
            self._shots -= 1

    def listing(self) -> SessionList:
        current = self.current
        return SessionList(current=current.id, sessions=[s.info(s is current) for s in self._kept.values()],
                           max_sessions=self.max_sessions, max_shots=self.max_shots)

    def summary(self, session: Session) -> SessionSummary:
        return SessionSummary(session=session.info(session is self.current), ellipse_probability=ELLIPSE_PROBABILITY,
                              clubs=session.club_summaries())
