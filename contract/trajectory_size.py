"""The bound on the trajectory points one request may get back (issue 55, item 4): samples = rate x shots x each
flight's time to rest, counted once the shots have flown and before any point is built, since a flight's length
(up to 20 s in the air and 120 s of roll) is known only then. 100 shots at 1 kHz, a 14 KB request, took the server
and its batch process to 964 MiB against the pod's 768 MiB limit."""

from __future__ import annotations

import math

from golfflight.contract.refusals import RequestRefused, input_detail
from golfflight.contract.requests import TrajectoryRequest
from golfflight.errors import InputError
from golfflight.flight.engine import EulerStates

MAX_TRAJECTORY_SAMPLES = 300_000
"""Most trajectory points one request may get back, over all its shots and their normalized replays: a single shot
at the top rate, 1,000 Hz, with its normalized replay over the longest flight and roll there can be (2 x 140 s,
280,002 points), or 100 shots at 60 Hz over 50 s each. Each point costs about 0.6 KB while its answer is built."""


def sample_count(states: EulerStates, trajectory: TrajectoryRequest) -> int:
    """How many points `contract.trajectory.resample` gives for these states at the trajectory's rate (the states
    themselves when it names none)."""
    if trajectory.rate_hz is None:
        return len(states.times_s)
    duration_s = float(states.times_s[-1])
    on_grid = math.floor(duration_s * trajectory.rate_hz + 1e-9) + 1
    ends_off_grid = (on_grid - 1) / trajectory.rate_hz < duration_s - 1e-9  # the last state's time is added
    return on_grid + int(ends_off_grid)


def refuse_long_trajectories(traced: list[tuple[TrajectoryRequest, EulerStates]]) -> None:
    """RequestRefused (422, naming trajectory.rate_hz and the allowed size) when the trajectories asked for, each a
    request's trajectory and the states of one of its flights, come to more than MAX_TRAJECTORY_SAMPLES points."""
    total = sum(sample_count(states, trajectory) for trajectory, states in traced)
    if total <= MAX_TRAJECTORY_SAMPLES:
        return
    problem = (f"the trajectories asked for come to {total:,} points (rate_hz x each flight's time to rest, its "
               "normalized replay's too): ask a lower rate_hz or fewer trajectories")
    allowed = f"at most {MAX_TRAJECTORY_SAMPLES:,} trajectory points per request"
    too_many = InputError(problem, field="trajectory.rate_hz", value=total, allowed=allowed)
    raise RequestRefused([input_detail(too_many, "too_many_points")])
