"""The shots the viewer shows: the last HISTORY shots, and one bounded queue per open viewer.

Publishing never waits and costs a few appends: a slow or dead viewer only loses the oldest shots it has not been
sent yet (its queue drops them), it never holds up a shot's reply. A shot's event is rendered once, by the first
viewer stream that sends it, not on the shot's path: a result without a trajectory is flown again with one on the
engine's single-shot path (about a millisecond on an idle machine); a batch's results come back from the batch process
as bytes that the worker does not parse, so its last HISTORY shots (the most a viewer keeps) are flown again whole.
Everything here runs on the service's event loop.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections import deque
from dataclasses import dataclass

from golfflight.contract.flying import fly_shot
from golfflight.contract.gspro import GSProMessage, GSProReply, launch_from_ball_data
from golfflight.contract.inputs import launch_of
from golfflight.contract.requests import ShotRequest, TrajectoryRequest
from golfflight.contract.results import ShotResult, TrajectoryPoint
from golfflight.flight.engine import FlightEngine, FlightError
from golfflight.service.viewer.event import LaunchNumbers, ShotEvent, Source

HISTORY = 50
"""Shots kept for viewers that open (or reconnect) later, and the length of each viewer's queue."""

MAX_VIEWERS = 16
"""Event streams open at once; one more is refused with 503 (a bay has a screen or two)."""

MAX_POINTS = 600
"""Most trajectory points an event carries (a trajectory asked for at 1 kHz is thinned to this)."""

VIEW_RATE_HZ = 30.0
"""Rate of the trajectory flown for a shot whose result has none: smooth on screen; a driver's event is about 23 kB."""


class TooManyViewers(Exception):
    """MAX_VIEWERS streams are open already."""


Point = tuple[float, float, float, float]
"""A trajectory point kept as (t_s, x_m, y_m, z_m): about a third of a TrajectoryPoint object's memory."""


@dataclass(eq=False)
class Entry:
    """One published shot: its request (a GSPro message's is made from the message when first rendered, not on the
    shot's path), its result without the trajectory and the trajectory it came with (None: fly it again), until
    `frame`, its server-sent event, is rendered; only the frame is kept after that."""

    id: int
    source: Source
    received_unix_s: float
    shot: ShotRequest | GSProMessage | None
    result: ShotResult | None
    path: list[Point] | None
    shot_number: int | None = None
    frame: str | None = None


class Viewer:
    """One open stream's queue of shots to send: bounded, the oldest dropped when full."""

    def __init__(self, capacity: int):
        self.pending: deque[Entry] = deque(maxlen=capacity)
        self.dropped = 0
        self._wake = asyncio.Event()

    def offer(self, entry: Entry) -> None:
        if len(self.pending) == self.pending.maxlen:
            self.dropped += 1
        self.pending.append(entry)
        self._wake.set()

    async def next(self, timeout_s: float) -> Entry | None:
        """The next shot to send, or None when none came within `timeout_s`."""
        if not self.pending:
            self._wake.clear()
            try:
                async with asyncio.timeout(timeout_s):
                    await self._wake.wait()
            except TimeoutError:
                return None
        return self.pending.popleft() if self.pending else None


def thin(points: list[TrajectoryPoint], most: int = MAX_POINTS) -> list[TrajectoryPoint]:
    """At most `most` of `points`, evenly taken, the first and the last always kept."""
    if len(points) <= most:
        return points
    step = math.ceil((len(points) - 1) / (most - 1))
    kept = points[::step]
    return kept if kept[-1] is points[-1] else [*kept, points[-1]]


def gspro_request(message: GSProMessage) -> ShotRequest:
    """The /v1/shots request that flies a GSPro message's ball as `fly_message` does (standard air)."""
    launch = launch_from_ball_data(message.BallData)
    return ShotRequest.model_construct(
        ball_speed_mps=launch.ball_speed_mps,
        launch_angle_deg=launch.launch_angle_deg,
        launch_direction_deg=launch.launch_direction_deg,
        spin_rpm=launch.spin_rpm,
        spin_axis_deg=launch.spin_axis_deg,
    )


class ShotFeed:
    """The last `history` shots and the open viewers' queues."""

    def __init__(self, history: int = HISTORY, max_viewers: int = MAX_VIEWERS):
        self._history: deque[Entry] = deque(maxlen=history)
        self._viewers: set[Viewer] = set()
        self._max_viewers = max_viewers
        self._next_id = 1

    @property
    def viewers(self) -> tuple[Viewer, ...]:
        """The open streams' queues."""
        return tuple(self._viewers)

    def publish(
        self,
        source: Source,
        shot: ShotRequest | GSProMessage,
        result: ShotResult | None,
        shot_number: int | None = None,
    ) -> None:
        """A shot flown (`result` None: flown in a batch, its result not at hand). A trajectory the client asked for
        is kept thinned to MAX_POINTS plain tuples, so the history holds little more than its rendered events."""
        path = None
        if result is not None and (result.trajectory is not None or result.normalized is not None):
            if result.trajectory is not None:
                path = [(p.t_s, p.x_m, p.y_m, p.z_m) for p in thin(result.trajectory)]
            result = result.model_copy(update={"trajectory": None, "normalized": None})
        entry = Entry(self._next_id, source, time.time(), shot, result, path, shot_number)
        self._next_id += 1
        self._history.append(entry)
        for viewer in self._viewers:
            viewer.offer(entry)

    def publish_batch(self, shots: list[ShotRequest]) -> None:
        """A batch's shots: only the last HISTORY of them, the most any viewer keeps."""
        for shot in shots[-self._history.maxlen :]:
            self.publish("batch", shot, None)

    def publish_gspro(self, source: Source, message: GSProMessage, reply: GSProReply) -> None:
        """A GSPro message's shot, if it flew (Code 200)."""
        if reply.Code == 200 and reply.Flight is not None:
            self.publish(source, message, reply.Flight, message.ShotNumber)

    def subscribe(self, after_id: int | None = None) -> Viewer:
        """A new viewer's queue, holding the kept shots after `after_id` (all of them without one, or when the id
        is from before a restart); TooManyViewers when MAX_VIEWERS are open."""
        if len(self._viewers) >= self._max_viewers:
            raise TooManyViewers(f"{self._max_viewers} viewers are open already")
        viewer = Viewer(self._history.maxlen)
        resume = after_id is not None and after_id < self._next_id
        for entry in self._history:
            if not resume or entry.id > after_id:
                viewer.offer(entry)
        self._viewers.add(viewer)
        return viewer

    def unsubscribe(self, viewer: Viewer) -> None:
        self._viewers.discard(viewer)

    def frame(self, entry: Entry, engine: FlightEngine) -> str | None:
        """The shot's server-sent event, rendered on first use; None for a batch shot that could not land."""
        if entry.frame is None and entry.shot is not None:
            try:
                entry.frame = _encode(entry, engine)
            except FlightError:
                pass  # a batch shot the batch itself reported as failed: nothing to show
            entry.shot = entry.result = entry.path = None
        return entry.frame


def _encode(entry: Entry, engine: FlightEngine) -> str:
    shot = entry.shot if isinstance(entry.shot, ShotRequest) else gspro_request(entry.shot)
    if entry.path is not None:
        trajectory = [TrajectoryPoint.model_construct(t_s=t, x_m=x, y_m=y, z_m=z) for t, x, y, z in entry.path]
        result = entry.result
    else:
        traced_shot = shot.model_copy(
            update={"trajectory": TrajectoryRequest(rate_hz=VIEW_RATE_HZ), "normalized": False}
        )
        traced = fly_shot(engine, traced_shot)
        trajectory = thin(traced.trajectory)
        result = traced if entry.result is None else entry.result
    event = ShotEvent(
        id=entry.id,
        source=entry.source,
        received_unix_s=entry.received_unix_s,
        shot_number=entry.shot_number,
        launch=LaunchNumbers(**launch_of(shot)._asdict()),
        flight=result.model_copy(update={"trajectory": trajectory, "normalized": None}),
    )
    return f"id: {entry.id}\nevent: shot\ndata: {event.model_dump_json(exclude_none=True)}\n\n"
