"""Whether a connector's shot with the putter selected is a putt: golfers forget to switch clubs, and a drive rolled
as a putt went 3,334 yd on a stimp-11 green (issue 56). A ball that leaves faster or steeper than any putt is flown as
the full shot it is, and the reply says why (docs/service.md, "A full swing with the putter selected flies", gives
the numbers' sources).
"""

from __future__ import annotations

from golfflight.flight.constants import MPH_TO_MPS
from golfflight.flight.problem import Launch

PUTT_MAX_SPEED_MPH = 30.0
"""The fastest ball rolled as a putt: on the slowest green the bay takes (stimp 4) 30 mph rolls about as far as the
longest putt holed on television, 159 ft (Phelps, 2012); on a stimp-11 green it rolls over 300 ft."""
PUTT_MAX_SPEED_MPS = PUTT_MAX_SPEED_MPH * MPH_TO_MPS

PUTT_MAX_LAUNCH_DEG = 10.0
"""The steepest launch rolled as a putt: five times a putt's ideal 2 degrees (SAM PuttLab), over any putter's loft
and upward stroke; a tour driver launches at 10.5 degrees and 171 mph, the wedges at 24-33 degrees (`shots.clubs`)."""


def not_a_putt(launch: Launch) -> str | None:
    """Why a launch with the putter selected is no putt and flies as a full shot (the reply's note), or None for a
    putt."""
    speed, angle = launch.ball_speed_mps, launch.launch_angle_deg
    if speed <= PUTT_MAX_SPEED_MPS and angle <= PUTT_MAX_LAUNCH_DEG:
        return None
    return (f"The putter is selected, but {speed / MPH_TO_MPS:.1f} mph at {angle:.1f} deg is no putt (a putt leaves "
            f"at most {PUTT_MAX_SPEED_MPH:g} mph and {PUTT_MAX_LAUNCH_DEG:g} deg): flown as a full shot")
