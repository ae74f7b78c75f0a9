"""GSPro Open Connect v1 shot messages (NOTES.md section 4), as a launch-monitor connector sends them.

The protocol is not ours, so unknown fields are ignored (connectors add their own); the values we use are
type- and range-checked like every other launch (GSPRO_RANGES, quoted in the error message).
Speeds are mph, angles degrees (HLA + = right), spins rpm. BackSpin and
SideSpin are used only when TotalSpin is absent (or zero while they are not); + SideSpin curves the ball right.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

from service import limits
from service.api.models import BALL_SPEED_MPH, SIDE_SPIN_RPM, ShotResult
from service.api.shots import spin_from_components
from service.constants import MPH_TO_MPS
from service.engine import Launch
from service.limits import Range


class _Lenient(BaseModel):
    """Ignores unknown fields; refuses non-finite numbers and values of the wrong JSON type."""

    model_config = ConfigDict(extra="ignore", allow_inf_nan=False, strict=True)


GSPRO_RANGES: dict[str, Range] = {
    "Speed": BALL_SPEED_MPH,
    "SpinAxis": limits.SPIN_AXIS_DEG,
    "TotalSpin": limits.SPIN_RPM,
    "BackSpin": limits.SPIN_RPM,
    "SideSpin": SIDE_SPIN_RPM,
    "HLA": limits.LAUNCH_DIRECTION_DEG,
    "VLA": limits.LAUNCH_ANGLE_DEG,
}
"""Allowed range of every BallData value used, by field name."""


def _in(name: str, description: str):
    bounds = GSPRO_RANGES[name]
    return Annotated[
        float | None, Field(ge=bounds.low, le=bounds.high, description=f"{description} ({bounds.describe()})")
    ]


class GSProBallData(_Lenient):
    Speed: _in("Speed", "ball speed, mph") = None
    SpinAxis: _in("SpinAxis", "spin axis, + = right") = None
    TotalSpin: _in("TotalSpin", "total spin, rpm") = None
    BackSpin: _in("BackSpin", "back spin, rpm") = None
    SideSpin: _in("SideSpin", "side spin, rpm, + = right") = None
    HLA: _in("HLA", "horizontal launch angle, + = right") = None
    VLA: _in("VLA", "vertical launch angle") = None
    CarryDistance: float | None = Field(None, description="the monitor's own carry; not used")


class GSProOptions(_Lenient):
    ContainsBallData: bool = True
    ContainsClubData: bool = False
    LaunchMonitorIsReady: bool | None = None
    LaunchMonitorBallDetected: bool | None = None
    IsHeartBeat: bool = False


class GSProMessage(_Lenient):
    """One Open Connect v1 message (ClubData is accepted and not used: the flight needs the ball only)."""

    DeviceID: str | None = None
    Units: str | None = None
    ShotNumber: int | None = Field(None, ge=0, le=2**31 - 1)
    APIversion: str | None = None
    BallData: GSProBallData | None = None
    ClubData: dict | None = None
    ShotDataOptions: GSProOptions = Field(default_factory=GSProOptions)

    @property
    def is_heartbeat(self) -> bool:
        return self.ShotDataOptions.IsHeartBeat


class GSProReply(BaseModel):
    """Open Connect's reply: Code 200 with the flight for a shot, 200 for a heartbeat, 500 with a Message on error
    (sent with HTTP 422)."""

    Code: int
    Message: str
    ShotNumber: int | None = None
    Flight: ShotResult | None = None


def launch_from_ball_data(ball: GSProBallData) -> Launch:
    """The SI launch of a message's BallData; ValueError naming the field when one it needs is missing."""
    missing = [name for name in ("Speed", "VLA") if getattr(ball, name) is None]
    uses_components = not ball.TotalSpin and (ball.BackSpin or ball.SideSpin)
    if ball.TotalSpin is None and ball.BackSpin is None:
        missing.append("TotalSpin (or BackSpin)")
    if missing:
        raise ValueError(f"BallData is missing {', '.join(missing)}")
    if uses_components:
        spin, axis = spin_from_components(ball.BackSpin or 0.0, ball.SideSpin or 0.0)
        if spin > limits.SPIN_RPM.high:
            raise ValueError(f"BallData: BackSpin and SideSpin make {spin:.0f} rpm, over {limits.SPIN_RPM.describe()}")
    else:
        spin, axis = ball.TotalSpin or 0.0, ball.SpinAxis or 0.0
    return Launch(ball.Speed * MPH_TO_MPS, ball.VLA, ball.HLA or 0.0, spin, axis)
