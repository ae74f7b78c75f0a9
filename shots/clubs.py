"""Typical launch conditions of each club for a tour-level player, in SI (rounded from TrackMan's published
tour averages, extended to the three wedges below PW): the centres the synthetic sessions scatter around.

Launches only: the table's carries, heights and land angles are targets elsewhere (`model_export.reference_targets`,
`model_export.real_data`), never centres here."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple, Protocol

if TYPE_CHECKING:
    import numpy as np


class HasLaunch(Protocol):
    """Anything with a mean launch in SI: a club of CLUBS, a row of a tour-averages table."""

    @property
    def ball_speed_mps(self) -> float: ...
    @property
    def launch_angle_deg(self) -> float: ...
    @property
    def spin_rpm(self) -> float: ...


def straight_launches(clubs: Sequence[HasLaunch]) -> dict[str, np.ndarray]:
    """The canonical launch columns of each club's mean launch, straight: launch direction and spin axis 0 (the
    tables publish neither). NumPy is imported here, not with the table: `golfflight fly --help` lists the clubs."""
    import numpy as np

    n = len(clubs)
    return {
        "ball_speed_mps": np.array([c.ball_speed_mps for c in clubs], dtype=float),
        "launch_angle_deg": np.array([c.launch_angle_deg for c in clubs], dtype=float),
        "launch_direction_deg": np.zeros(n),
        "spin_rpm": np.array([c.spin_rpm for c in clubs], dtype=float),
        "spin_axis_deg": np.zeros(n),
    }


class ClubLaunch(NamedTuple):
    """Mean launch of one club for a tour-level player."""

    name: str
    ball_speed_mps: float
    launch_angle_deg: float
    spin_rpm: float


CLUBS: tuple[ClubLaunch, ...] = (
    ClubLaunch("Driver", 76.5, 10.5, 2550.0),
    ClubLaunch("3-wood", 72.5, 9.5, 3650.0),
    ClubLaunch("5-wood", 69.5, 9.5, 4300.0),
    ClubLaunch("Hybrid", 66.5, 10.0, 4600.0),
    ClubLaunch("3-iron", 65.0, 10.5, 4400.0),
    ClubLaunch("4-iron", 62.5, 11.0, 4800.0),
    ClubLaunch("5-iron", 60.5, 12.0, 5300.0),
    ClubLaunch("6-iron", 58.0, 14.0, 6200.0),
    ClubLaunch("7-iron", 55.0, 16.0, 7100.0),
    ClubLaunch("8-iron", 52.5, 18.0, 8100.0),
    ClubLaunch("9-iron", 50.0, 20.0, 8800.0),
    ClubLaunch("PW", 46.5, 24.0, 9300.0),
    ClubLaunch("GW", 43.0, 27.0, 9600.0),
    ClubLaunch("SW", 39.0, 30.0, 9800.0),
    ClubLaunch("LW", 34.0, 33.0, 9500.0),
)

CLUB_SHARE = {"Driver": 0.2, "7-iron": 0.12, "LW": 0.08, "PW": 0.07, "SW": 0.06}
"""How often a club is picked, relative to 0.04 for the others: drivers, mid irons and wedges dominate testing."""


def club_weights() -> list[float]:
    """Probability of each entry of CLUBS in a session's bag draw."""
    raw = [CLUB_SHARE.get(club.name, 0.04) for club in CLUBS]
    total = sum(raw)
    return [w / total for w in raw]


CLUB_NAMES: tuple[str, ...] = tuple(club.name for club in CLUBS)
"""The launch table's club names, longest to shortest club (`contract.clubs.FLIES_AS` names a GSPro code's)."""


def club_launch(name: str) -> ClubLaunch:
    """The club of CLUBS with this canonical name (`CLUB_NAMES`); which club a golfer's name means is
    `contract.clubs`' to say."""
    return next(club for club in CLUBS if club.name == name)
