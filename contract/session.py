"""The bay's sessions: a player's run of shots on the bay's screens, started afresh on request (POST /v1/sessions),
listed with their shots kept, downloaded as CSV and summed up per club (GET /v1/session/summary).

Every length is SI, metres, with the unit in the field's name; a screen shows yards by dividing by 0.9144. The spread
is the sample standard deviation (n - 1), so it is absent with one shot; the dispersion ellipse is the 95 % ellipse
of a two-dimensional normal distribution fitted to the points (mean and sample covariance): the semi-axes are
sqrt(chi2(2 dof, 0.95) x eigenvalue) = sqrt(5.991 x eigenvalue) of the covariance, absent under three shots.
"""

from __future__ import annotations

import unicodedata
from typing import Annotated

from golfflight.contract.requests import Strict
from golfflight.errors import InputError
from pydantic import AfterValidator, BaseModel, Field

PLAYER_CHARS = 40
"""Longest player name: a name on a screen, not a note."""

FORMULA_STARTS = ("=", "+", "-", "@")
"""Characters a spreadsheet reads as the start of a formula: a name opening with one would run as one when the
session's CSV is opened in a spreadsheet, so such a name is refused."""


def _plain_name(name: str) -> str:
    """A player's name as it may be shown and written to the CSV: printable characters only (no control characters,
    no lone surrogates that no UTF-8 text can carry), not opening like a spreadsheet formula, not blank."""
    stripped = name.strip()
    if not stripped:
        raise InputError("a player's name needs a letter or a digit (leave `player` out for none)")
    if stripped.startswith(FORMULA_STARTS):
        raise InputError(f"a player's name may not start with {' '.join(FORMULA_STARTS)} (a spreadsheet formula)")
    if any(not char.isprintable() or unicodedata.category(char) == "Cs" for char in stripped):
        raise InputError("a player's name takes printable characters only")
    return stripped


PlayerName = Annotated[str, Field(min_length=1, max_length=PLAYER_CHARS), AfterValidator(_plain_name)]


class NewSession(Strict):
    """POST /v1/sessions: who plays the session that starts now (optional)."""

    player: PlayerName | None = Field(None, description=f"the player's name, at most {PLAYER_CHARS} characters")


class SessionInfo(BaseModel):
    """One session: when it started, who plays, how many of its shots are kept. Also the viewer's `session` event,
    sent first on every stream and whenever a new session starts (the screens then empty)."""

    id: int = Field(ge=1, description="rising from 1 per service process; the first session starts with the service")
    player: str | None = Field(None, description="the player's name, when the session was started with one")
    started_unix_s: float = Field(description="when the session started, seconds since 1970 (UTC)")
    shots: int = Field(ge=0, description="its shots kept: in its CSV and its summary")
    dropped_shots: int = Field(0, ge=0, description="its oldest shots dropped to keep the service's shot cap")
    current: bool = Field(description="the session the bay's shots go to now")


class SessionList(BaseModel):
    """GET /v1/sessions: the sessions kept, oldest first, and the caps that bound them."""

    current: int = Field(ge=1, description="the id of the session the bay's shots go to now")
    sessions: list[SessionInfo]
    max_sessions: int = Field(description="sessions kept; starting one more forgets the oldest with its shots")
    max_shots: int = Field(description="shots kept over all sessions; the oldest go first")


class Spread(BaseModel):
    """A figure's mean and sample standard deviation over a club's shots."""

    mean_m: float
    sd_m: float | None = Field(None, description="sample standard deviation (n - 1); absent with one shot")


class Ellipse(BaseModel):
    """Where a club's balls came down (or stopped): the 95 % ellipse of the normal distribution fitted to the
    points, its centre (the mean), semi-axes and the direction of its long axis."""

    center_x_m: float = Field(description="+ = right of the target line")
    center_y_m: float = Field(description="down the target line")
    semi_major_m: float = Field(ge=0)
    semi_minor_m: float = Field(ge=0)
    angle_deg: float = Field(description="the long axis from the target line, + = turned to the right, "
                             "in (-90, 90]: 0 is long down the line (a carry spread), 90 across it")


class ClubSummary(BaseModel):
    """One club's shots in the session (its putts apart): how far, how high, how straight, and how scattered."""

    club: str | None = Field(None, description="GSPro club code of the bay's player; absent for shots without one "
                             "(a batch)")
    putts: bool = Field(False, description="these are putts (the putter over a connector): no flight, rest only")
    shots: int = Field(ge=1)
    carry: Spread
    total: Spread
    apex: Spread
    lateral: Spread = Field(description="at landing, + = right")
    carry_gap_m: float | None = Field(
        None, description="mean carry less that of the next shorter club with shots in the session (the next one "
        "down the bag); absent for the shortest and for putts")
    landing: Ellipse | None = Field(None, description="landing points' 95 % ellipse; absent under three shots and "
                                    "for putts")
    rest: Ellipse | None = Field(None, description="rest points' 95 % ellipse; absent under three shots")


class SessionSummary(BaseModel):
    """GET /v1/session/summary: the session and its clubs in the bag's order (GSPro's codes, the putter last, shots
    without a club after it)."""

    session: SessionInfo
    ellipse_probability: float = Field(0.95, description="the share of a normal scatter inside each ellipse")
    clubs: list[ClubSummary]
