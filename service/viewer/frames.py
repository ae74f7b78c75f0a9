"""A feed entry as the viewer's server-sent event: the shot's launch, the result answered, and the path of the
flight that result was read from, resampled for drawing; and a session's announcement (`event: session`, no id: a
stream's Last-Event-ID stays a shot's). Rendered once per shot, off the shot's own path (by the
first stream that sends it). A shot whose event cannot be rendered is left out of every stream and logged: one bad
event must not cut the stream, nor, kept among the shots a reconnecting page is sent, every stream after it."""

from __future__ import annotations

import logging

import numpy as np
from golfflight.contract.inputs import launch_of
from golfflight.contract.results import TrajectoryPoint
from golfflight.contract.trajectory import resample
from golfflight.flight.engine import EulerStates
from golfflight.service.runtime.feed import Entry
from golfflight.service.runtime.sessions import Session
from golfflight.service.viewer.event import LaunchNumbers, ShotEvent

VIEW_RATE_HZ = 30.0
"""Rate of the drawn path between the states it must pass through: smooth on screen."""

log = logging.getLogger(__name__)

MAX_POINTS = 800
"""Most points an event's path carries: the rate is lowered for a long flight and roll so that it fits."""


def path(states: EulerStates, landing_time_s: float) -> list[TrajectoryPoint]:
    """The states on their Hermite curve at VIEW_RATE_HZ (less for a long shot), through the landing, every state
    of the ground phase (impacts, touchdowns, the roll) and the rest exactly."""
    knots = states.times_s[states.times_s >= landing_time_s - 1e-9]
    duration = float(states.times_s[-1])
    rate = VIEW_RATE_HZ if duration <= 0 else min(VIEW_RATE_HZ, max(1.0, (MAX_POINTS - len(knots) - 2) / duration))
    times, positions = resample(states, rate, knots) if len(states.times_s) > 1 else (states.times_s,
                                                                                        states.positions)
    return [
        TrajectoryPoint.model_construct(t_s=t, x_m=x, y_m=y, z_m=z)
        for t, (x, y, z) in zip(np.asarray(times).tolist(), np.asarray(positions).tolist(), strict=True)
    ]


def render(entry: Entry) -> str:
    """The entry's server-sent event (id, type `shot`, the ShotEvent as JSON)."""
    request = entry.request
    trajectory = [] if entry.states is None else path(entry.states, entry.flight_time_s)
    event = ShotEvent(
        id=entry.id,
        source=entry.source,
        received_unix_s=entry.received_unix_s,
        shot_number=entry.shot_number,
        session_shot=entry.session_shot,
        launch=LaunchNumbers(**launch_of(request)._asdict()),
        flight=entry.result.model_copy(update={"trajectory": trajectory, "normalized": None}),
        player=entry.player,
        putt=entry.putt,
        club_data=entry.club_data,
        air=request.air,
        wind=request.wind,
        ground=request.ground,
    )
    return f"id: {entry.id}\nevent: shot\ndata: {event.model_dump_json(exclude_none=True)}\n\n"


def session_frame(session: Session) -> str:
    """A session's server-sent event (type `session`, its SessionInfo as JSON, as the current session)."""
    return f"event: session\ndata: {session.info(current=True).model_dump_json(exclude_none=True)}\n\n"


def frame(entry: Entry | Session) -> str:
    """The entry's event, rendered on first use and kept (the entry keeps only that text after); empty, and logged
    once, when it cannot be rendered. A session is announced as it is now (its shots counted when sent)."""
    if isinstance(entry, Session):
        return session_frame(entry)
    if entry.frame is not None:
        return entry.frame
    try:
        return entry.rendered(render(entry))
    except Exception:  # noqa: BLE001 - the shot is left off the screens, the stream and the bay go on
        log.exception("viewer: shot %d cannot be shown (left out of the live stream)", entry.id)
        return entry.rendered("")
