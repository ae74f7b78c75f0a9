"""A club's figures over a session, kept as running sums so that a summary costs the same for 3 shots as for 10,000
and a shot dropped by the session's cap comes off again (`ClubStats.add` with `sign=-1`).

Each shot adds its carry, total, apex and lateral and its landing and rest points; the sums are of each value less the
club's first shot's (`origin`), so that sums of squares of 200 m carries over thousands of shots lose no precision to
cancellation. The spread is the sample standard deviation (n - 1); the ellipse is the 95 % ellipse of the normal
distribution fitted to the points (`contract.session`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from golfflight.contract.results import ShotResult
from golfflight.contract.session import ClubSummary, Ellipse, Spread

ELLIPSE_PROBABILITY = 0.95
ELLIPSE_SCALE = -2.0 * math.log(1.0 - ELLIPSE_PROBABILITY)
"""chi2 with 2 degrees of freedom at 0.95 (5.991): a normal scatter's share inside the ellipse whose semi-axes are
sqrt(ELLIPSE_SCALE x eigenvalue) of its covariance is ELLIPSE_PROBABILITY."""

ELLIPSE_SHOTS = 3
"""Fewest shots an ellipse is given for (two points make a line, not a scatter)."""


class Figures(NamedTuple):
    """What a shot adds to its club's sums, metres."""

    carry: float
    total: float
    apex: float
    lateral: float
    landing_x: float
    landing_y: float
    rest_x: float
    rest_y: float


SPREADS = ("carry", "total", "apex", "lateral")
POINTS = (("landing", 4), ("rest", 6))
"""Each point's name and the index of its x in `Figures` (its y follows)."""


def figures(result: ShotResult) -> Figures:
    """A flight result's figures for the summary."""
    return Figures(result.carry_m, result.total_m, result.apex_m, result.lateral_m, result.landing.x_m,
                   result.landing.y_m, result.rest.x_m, result.rest.y_m)


def ellipse(n: int, sum_x: float, sum_y: float, sum_xx: float, sum_yy: float, sum_xy: float) -> Ellipse | None:
    """The 95 % ellipse of n points from their sums (of values less an origin; the centre is returned relative to
    that origin too), or None under ELLIPSE_SHOTS points."""
    if n < ELLIPSE_SHOTS:
        return None
    mean_x, mean_y = sum_x / n, sum_y / n
    var_x = max((sum_xx - sum_x * mean_x) / (n - 1), 0.0)
    var_y = max((sum_yy - sum_y * mean_y) / (n - 1), 0.0)
    cov = (sum_xy - sum_x * mean_y) / (n - 1)
    middle, half = (var_x + var_y) / 2.0, math.hypot((var_x - var_y) / 2.0, cov)
    major, minor = middle + half, max(middle - half, 0.0)
    theta = 0.5 * math.atan2(2.0 * cov, var_x - var_y)  # the long axis from +x (right), towards +y (down the line)
    angle = 90.0 - math.degrees(theta)  # from +y (the target line) towards +x
    angle = angle - 180.0 if angle > 90.0 else angle
    return Ellipse(center_x_m=mean_x, center_y_m=mean_y, semi_major_m=math.sqrt(ELLIPSE_SCALE * major),
                   semi_minor_m=math.sqrt(ELLIPSE_SCALE * minor), angle_deg=angle)


class ClubStats:
    """Running sums of one club's shots (or putts) in a session: count, and per figure the sum and the sum of
    squares of its value less `origin`, and for each point the sum of the products of its x and y."""

    def __init__(self, origin: Figures):
        self.origin = origin
        self.n = 0
        self.sums = [0.0] * len(origin)
        self.squares = [0.0] * len(origin)
        self.products = [0.0] * len(POINTS)

    def add(self, shot: Figures, sign: int = 1) -> None:
        """Count a shot in (`sign` 1) or out again (-1: one dropped by the cap)."""
        self.n += sign
        deltas = [value - origin for value, origin in zip(shot, self.origin, strict=True)]
        for i, delta in enumerate(deltas):
            self.sums[i] += sign * delta
            self.squares[i] += sign * delta * delta
        for k, (_, x) in enumerate(POINTS):
            self.products[k] += sign * deltas[x] * deltas[x + 1]

    def spread(self, index: int) -> Spread:
        """Mean and sample standard deviation of one figure."""
        n, total = self.n, self.sums[index]
        mean = total / n
        sd = math.sqrt(max((self.squares[index] - total * mean) / (n - 1), 0.0)) if n > 1 else None
        return Spread(mean_m=self.origin[index] + mean, sd_m=sd)

    def point(self, k: int) -> Ellipse | None:
        """One point's ellipse, its centre back in the bay's coordinates."""
        x = POINTS[k][1]
        found = ellipse(self.n, self.sums[x], self.sums[x + 1], self.squares[x], self.squares[x + 1], self.products[k])
        if found is None:
            return None
        return found.model_copy(update={"center_x_m": found.center_x_m + self.origin[x],
                                        "center_y_m": found.center_y_m + self.origin[x + 1]})

    def summary(self, club: str | None, putts: bool) -> ClubSummary:
        """The club's summary (its carry gap is the session's to fill in: it needs the next club)."""
        spreads = {name: self.spread(i) for i, name in enumerate(SPREADS)}
        return ClubSummary(club=club, putts=putts, shots=self.n, **spreads,
                           landing=None if putts else self.point(0), rest=self.point(1))
