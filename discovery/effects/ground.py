"""The landing ground's height: the balls land on ground above or below the tee (a condition of the venue)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from golfflight.discovery.effects.base import Context, Effect, Hiding, Parameter, World, unchanged
from golfflight.discovery.effects.parts import plus_minus, signed, single
from golfflight.discovery.schema import CorrectionSettings
from golfflight.discovery.simulator import Setup


def _apply(theta: np.ndarray, conditions: Setup) -> Setup:
    out = conditions.copy()
    out.ground_height_m = out.ground_height_m + theta[:, 0]
    return out


def _phrase(p: dict[str, float], u: dict[str, float]) -> str:
    where = "below" if p["height_m"] < 0 else "above"
    return f"landing ground {plus_minus(abs(p['height_m']), u['height_m'], ' m')} {where} the tee"


def _setting(settings: CorrectionSettings, p: dict[str, float], context: Context, wind_factor: float | None) -> None:
    settings.ground_height_m = p["height_m"]


def _reference(p: dict[str, float], world: World) -> World:
    return replace(world, ground_m=p["height_m"])


LANDING_ELEVATION = Effect(
    "landing_elevation",
    (Parameter("height_m", "m", 0.0, -40.0, 40.0, 5.0, 0.3),),
    _apply,
    single("height_m"),
    "the balls land on ground this high above the tee (negative = below)",
    kind="venue",
    words="landing ground height",
    phrase=_phrase,
    setting=_setting,
    hiding=Hiding(signed(height_m=(0.0, 3.0, 12.0)), unchanged, _reference, _apply),
)
