"""Slow shots (where users of open simulators report carries 10-15 yd off and wedges too long): a wedge at 60 mph, a
7-iron at 90 mph and a driver at 130 mph of ball speed, each with a launch angle and spin taken from a published
source on amateur golfers,
flown calm by every model. Where a source publishes the outcome of such a shot it is shown beside; where none was
found the table says so instead of inventing one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.flight.constants import MPH_TO_MPS, YARD_M
from golfflight.flight.flyer import Flyer


@dataclass(frozen=True)
class SlowShot:
    """A slow launch, where its angle and spin come from, and the published outcomes (text per outcome)."""

    name: str
    ball_speed_mph: float
    launch_angle_deg: float
    spin_rpm: float
    source: str
    published: dict[str, str]


NOT_FOUND = "not found"

SLOW_SHOTS = (
    SlowShot(
        "wedge (56 deg), 60 mph",
        60.0,
        28.0,
        6000.0,
        "launch and spin: Short Game Secrets, \"All wedges are not created equal\" "
        "(https://short-game-secrets.myshopify.com/blogs/news/11276189-all-wedges-are-not-created-equal), 56 deg "
        "wedges hit 70 yd from a tight lie on a Foresight GC2: \"Wedges spinning at 5000rpm launched at 30º, 6000rpm "
        "at 28º\" (average 7,130 rpm). The hitters' ability and their ball speed are not stated, so the 70 yd is no "
        "outcome for a 60 mph launch; no published carry, height or land angle at 60 mph was found.",
        {"carry": NOT_FOUND, "apex": NOT_FOUND, "land": NOT_FOUND},
    ),
    SlowShot(
        "7-iron, 90 mph",
        90.0,
        16.5,
        5000.0,
        "spin: PING Proving Grounds, Chris Broadie, \"Stop It Like a Tour Player\" "
        "(https://ca.ping.com/en-ca/blogs/proving-grounds/stop-it-like-a-tour-player; 3,500 7-iron shots): \"For "
        "slower swing speeds, the average spin rate is actually closer to 5,000 rpm\". Launch: the middle of 15-18 "
        "deg, the range \"7 Iron Optimal Launch Angle and Spin Rate Chart\" "
        "(https://thegolfmine.com/7-iron-optimal-launch-angle-and-spin-rate-chart/) gives for swing speeds under 70 "
        "mph (with 5,000-6,000 rpm); 90 mph of ball speed is such a swing: \"A 67 MPH club head speed should be a "
        "90.5mph ball speed on a 'perfect' strike\" (\"The Fitter's Corner: Can you hit it too good?\", "
        "https://marathonsportsagency.blog/2024/12/09/the-fitters-corner-can-you-hit-it-too-good). Land angle: PING's "
        "\"stopping power\" ranges for average-golfer speeds, \"from the mid 30s to the high 40s\" (Golf Digest, "
        "\"The most important data point when it comes to your next irons\", "
        "https://www.golfdigest.com/story/the-most-important-data-point-when-it-comes-to-your-next-irons-a). No carry "
        "or height at 90 mph was found; the nearest, from the same fitter: 67-69 mph of club speed, ball speed in the "
        "mid-to-high 90s, 4,300-4,700 rpm, carry 127-130 yd, apex 53-55 ft (17.7-18.3 yd).",
        {"carry": f"{NOT_FOUND} (127-130 at ~97 mph)", "apex": f"{NOT_FOUND} (17.7-18.3 at ~97 mph)",
         "land": "mid 30s to high 40s"},
    ),
    SlowShot(
        "driver, 130 mph",
        130.0,
        13.7,
        2430.0,
        "launch and spin: a magazine driver-fitting test (metric edition, "
        "https://online.flippingbook.com/view/942190819/83), \"Example 2\": a 5-handicap with an 86 mph driver club "
        "speed, one driver at 132.2 mph of ball speed, 13.7 deg launch, 2,430 rpm (total distance 220.1 m; carry not "
        "given). A fitter's range for 80-90 mph club speeds agrees: \"launch the ball between 13 and 15 degrees with "
        "a spin rate under 3,100 RPM\" "
        "(https://kirkpatrickgolf.blogspot.com/2018/05/why-is-launch-angle-important-in.html). No carry at 130 mph "
        "was found; the nearest: \"swings the driver at 90 MPH ... 135 MPH ball speed. That shot will carry about 215 "
        "yards\" with perfect launch conditions (\"The Fitter's Corner: Actual Driver Distances\", "
        "https://marathonsportsagency.blog/2024/12/09/the-fitters-corner-actual-driver-distances).",
        {"carry": f"{NOT_FOUND} (about 215 at 135 mph)", "apex": NOT_FOUND, "land": NOT_FOUND},
    ),
)

OUTCOMES = (("carry", "carry, yd"), ("apex", "max height, yd"), ("land", "land angle, deg"))


def launch_of(shots: Sequence[SlowShot]) -> dict[str, np.ndarray]:
    n = len(shots)
    return {
        "ball_speed_mps": np.array([s.ball_speed_mph * MPH_TO_MPS for s in shots]),
        "launch_angle_deg": np.array([s.launch_angle_deg for s in shots]),
        "launch_direction_deg": np.zeros(n),
        "spin_rpm": np.array([s.spin_rpm for s in shots]),
        "spin_axis_deg": np.zeros(n),
    }


def fly_slow(flyer: Flyer, shots: Sequence[SlowShot] = SLOW_SHOTS) -> dict[str, np.ndarray]:
    """Carry (yd), max height (yd) and land angle (deg) of each slow shot, calm, in the flyer's own air."""
    flight = flyer.flight(launch_problem(launch_of(shots)))
    return {"carry": flight.carry_m / YARD_M, "apex": flight.apex_m / YARD_M, "land": flight.landing_angle_deg}
