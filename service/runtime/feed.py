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
import itertools
import time
from collections import Counter, deque
from collections.abc import ValuesView
from dataclasses import dataclass

from golfflight.contract.bay import Player
from golfflight.contract.requests import ShotRequest
from golfflight.contract.results import ShotResult
from golfflight.flight.engine import EulerStates
from golfflight.service.runtime.sessions import MAX_SESSIONS, MAX_SHOTS, Session, Sessions, SessionShot, Source

HISTORY = 50
"""Shots kept for viewers that open (or reconnect) later, and the length of each viewer's queue."""

SESSION_SHOTS = MAX_SHOTS
"""Shots kept over all sessions for their downloads (GET /v1/session.csv) and summaries; past it, the source holding
the most lets its oldest go (`sessions`)."""

MAX_VIEWERS = 16
"""Event streams open at once (a bay has a screen or two; 16 leaves room for a venue's screens and a page's reconnect
overlapping its old stream). One more is never refused: it takes the place of the oldest stream of the client
address that holds the most (`ShotFeed.subscribe`, the new one counted with its own), which ends with a comment
saying so. A stream says nothing back, so open streams held by a program that never shows them cannot be told from
screens; what can be told is who holds them: sixteen streams held from one address give way to a screen anywhere
else, and their own new ones push out only their own. A screen's page opens its stream again at once with
Last-Event-ID, so one pushed out misses no kept shot."""

VIEWER_GAVE_WAY = ("closed to make room for a new stream: {places} were open (the most this golfflight serves at "
                   "once) and this address held the most of them; open it again to go on")
"""The comment that ends a stream giving its place to a new one."""

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


_OPENED = itertools.count()


class Viewer:
    """One open stream's queue of shots to send: bounded, the oldest dropped when full; and the session to announce
    before any of them (the stream's first event, and the event that empties a screen)."""

    def __init__(self, capacity: int, session: Session, client: str = ""):
        self.pending: deque[Entry] = deque(maxlen=capacity)
        self.dropped = 0
        self.session: Session | None = session
        self.client = client
        self.opened = next(_OPENED)  # the order streams opened in
        self.ended: str | None = None  # why the stream ends: it gave its place to a new one
        self._wake = asyncio.Event()

    def end(self, reason: str) -> None:
        """Have the stream end (its next wait returns at once), saying `reason`."""
        self.ended = reason
        self._wake.set()

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
        if self.session is None and not self.pending and self.ended is None:
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
    def session(self) -> ValuesView[SessionShot]:
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
                flight_time_s: float, client: str = "", **details) -> Entry:
        """A shot flown: its request as flown, its result (trajectory and normalized flight left out: the states
        are the path) and the states it was read from, from address `client` (its share of the session memory);
        `details` are Entry's shot_number, player, putt, club_data."""
        result = result.model_copy(update={"trajectory": None, "normalized": None})
        session = self.sessions.current
        entry = Entry(self._next_id, source, time.time(), request, result, states, flight_time_s, **details,
                      session_shot=session.dropped + len(session.shots) + 1)
        self._next_id += 1
        self._history.append(entry)
        self.sessions.add(SessionShot(entry.id, entry.received_unix_s, source, entry.shot_number, entry.player,
                                      entry.putt, request, result, client=client))
        for viewer in self._viewers:
            viewer.offer(entry)
        return entry

    def subscribe(self, after_id: int | None = None, client: str = "") -> Viewer:
        """A new viewer's queue for a stream from `client` (its address), announcing the current session, then holding
        its kept shots after `after_id` (all of them without one, or when the id is from before a restart); with
        `max_viewers` open already, one gives its place (`_make_room`)."""
        if len(self._viewers) >= self._max_viewers:
            self._make_room(client)
        viewer = Viewer(self._history.maxlen, self.sessions.current, client)
        resume = after_id is not None and after_id < self._next_id
        for entry in self._history:
            if not resume or entry.id > after_id:
                viewer.offer(entry)
        self._viewers.add(viewer)
        return viewer

    def unsubscribe(self, viewer: Viewer) -> None:
        self._viewers.discard(viewer)

    def _make_room(self, client: str) -> None:
        """End the oldest stream of the address holding the most streams, a new one from `client` counted with its
        own (`client`'s own first on a tie), and let it go."""
        held = Counter(viewer.client for viewer in self._viewers)
        most = max(held.values())
        mine = held[client] > 0 and held[client] + 1 >= most
        address = (lambda viewer: viewer.client == client) if mine else (lambda viewer: held[viewer.client] == most)
        giving = [viewer for viewer in self._viewers if address(viewer)]
        oldest = min(giving, key=lambda viewer: viewer.opened)
        oldest.end(VIEWER_GAVE_WAY.format(places=self._max_viewers))
        self._viewers.discard(oldest)
