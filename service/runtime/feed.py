"""The shots the bay's screens show: the last HISTORY shots flown, and one bounded queue per open viewer.

Each entry holds the flight that was answered: its request as flown (the bay's conditions filled in), its result,
and the states the result was read from, through the bounces and roll to rest (`contract.flying.fly_request`), so a
screen draws the very flight whose numbers the player got; nothing is flown again. Publishing never waits and costs
a few appends: a slow or dead viewer only loses the oldest shots it has not been sent yet (its queue drops them).
An entry's event text is rendered once, by the first viewer stream that sends it (`service.viewer`), and only that
text is kept after. Everything here runs on the service's event loop thread.

The shots also go to the current session (`sessions`), whose shots the session's CSV and summary read. Starting a new
session empties the screens: the kept shots are let go and every open viewer drops the shots it had not sent yet and
announces the new session (the viewer's `session` event) before any shot of it; a viewer that opens or reconnects
announces the current session first, then gets that session's kept shots only.
"""

from __future__ import annotations

import asyncio
import time
from collections import deque
from dataclasses import dataclass
from typing import Literal

from golfflight.contract.bay import Player
from golfflight.contract.requests import ShotRequest
from golfflight.contract.results import ShotResult
from golfflight.errors import ServiceError
from golfflight.flight.engine import EulerStates
from golfflight.service.runtime.sessions import MAX_SESSIONS, MAX_SHOTS, Session, Sessions, SessionShot

HISTORY = 50
"""Shots kept for viewers that open (or reconnect) later, and the length of each viewer's queue."""

SESSION_SHOTS = MAX_SHOTS
"""Shots kept over all sessions for their downloads (GET /v1/session.csv) and summaries; the oldest go first."""

MAX_VIEWERS = 16
"""Event streams open at once; one more is refused with 503 (a bay has a screen or two)."""

Source = Literal["http", "batch", "gspro-http", "open-connect"]
"""Where a shot came in: POST /v1/shots, POST /v1/shots/batch, POST /v1/gspro, GSPro Open Connect over TCP."""


class TooManyViewers(ServiceError):
    """MAX_VIEWERS streams are open already."""


@dataclass(eq=False)
class Entry:
    """One shot flown in the bay: what was flown and answered, and the states it came from, until `frame` (its
    rendered event, `service.viewer`) replaces them."""

    id: int
    source: Source
    received_unix_s: float
    request: ShotRequest | None
    result: ShotResult | None
    states: EulerStates | None
    flight_time_s: float = 0.0
    shot_number: int | None = None
    player: Player | None = None
    putt: bool = False
    club_data: dict | None = None
    session_shot: int | None = None
    frame: str | None = None

    def rendered(self, frame: str) -> str:
        """Keep only the rendered event from now on."""
        self.frame, self.request, self.result, self.states = frame, None, None, None
        return frame


class Viewer:
    """One open stream's queue of shots to send: bounded, the oldest dropped when full; and the session to announce
    before any of them (the stream's first event, and the event that empties a screen)."""

    def __init__(self, capacity: int, session: Session):
        self.pending: deque[Entry] = deque(maxlen=capacity)
        self.dropped = 0
        self.session: Session | None = session
        self._wake = asyncio.Event()

    def offer(self, entry: Entry) -> None:
        if len(self.pending) == self.pending.maxlen:
            self.dropped += 1
        self.pending.append(entry)
        self._wake.set()

    def restart(self, session: Session) -> None:
        """A new session: the shots not sent yet are the old session's, let go; the session is announced next."""
        self.pending.clear()
        self.session = session
        self._wake.set()

    async def next(self, timeout_s: float) -> Entry | Session | None:
        """The session to announce, else the next shot to send, or None when none came within `timeout_s`."""
        if self.session is None and not self.pending:
            self._wake.clear()
            try:
                async with asyncio.timeout(timeout_s):
                    await self._wake.wait()
            except TimeoutError:
                return None
        if self.session is not None:
            session, self.session = self.session, None
            return session
        return self.pending.popleft() if self.pending else None


class ShotFeed:
    """The last `history` shots of the current session, the open viewers' queues, and the sessions (`sessions`:
    at most `max_sessions`, their shots at most `max_shots` in all)."""

    def __init__(self, history: int = HISTORY, max_viewers: int = MAX_VIEWERS, max_shots: int = SESSION_SHOTS,
                 max_sessions: int = MAX_SESSIONS):
        self._history: deque[Entry] = deque(maxlen=history)
        self.sessions = Sessions(max_shots, max_sessions)
        self._viewers: set[Viewer] = set()
        self._max_viewers = max_viewers
        self._next_id = 1

    @property
    def session(self) -> deque[SessionShot]:
        """The current session's shots kept, oldest first."""
        return self.sessions.current.shots

    def start_session(self, player: str | None = None) -> Session:
        """A new session, now the current one: the screens empty (the kept shots let go, each open viewer's unsent
        ones too) and every open viewer announces it next."""
        session = self.sessions.start(player)
        self._history.clear()
        for viewer in self._viewers:
            viewer.restart(session)
        return session

    @property
    def history(self) -> int:
        """How many shots are kept for viewers that open later."""
        return self._history.maxlen

    @property
    def viewers(self) -> tuple[Viewer, ...]:
        """The open streams' queues."""
        return tuple(self._viewers)

    def publish(self, source: Source, request: ShotRequest, result: ShotResult, states: EulerStates | None,
                flight_time_s: float, **details) -> Entry:
        """A shot flown: its request as flown, its result (trajectory and normalized flight left out: the states
        are the path) and the states it was read from; `details` are Entry's shot_number, player, putt, club_data."""
        result = result.model_copy(update={"trajectory": None, "normalized": None})
        session = self.sessions.current
        entry = Entry(self._next_id, source, time.time(), request, result, states, flight_time_s, **details,
                      session_shot=session.dropped + len(session.shots) + 1)
        self._next_id += 1
        self._history.append(entry)
        self.sessions.add(SessionShot(entry.id, entry.received_unix_s, source, entry.shot_number, entry.player,
                                      entry.putt, request, result))
        for viewer in self._viewers:
            viewer.offer(entry)
        return entry

    def subscribe(self, after_id: int | None = None) -> Viewer:
        """A new viewer's queue, announcing the current session, then holding its kept shots after `after_id` (all
        of them without one, or when the id is from before a restart); TooManyViewers when MAX_VIEWERS are open."""
        if len(self._viewers) >= self._max_viewers:
            raise TooManyViewers(f"{self._max_viewers} viewers are open already: close one and try again")
        viewer = Viewer(self._history.maxlen, self.sessions.current)
        resume = after_id is not None and after_id < self._next_id
        for entry in self._history:
            if not resume or entry.id > after_id:
                viewer.offer(entry)
        self._viewers.add(viewer)
        return viewer

    def unsubscribe(self, viewer: Viewer) -> None:
        self._viewers.discard(viewer)
