"""Another ball: its drag, lift and spin decay differ from the model's ball together, as one cause.

Without a baseline session a ball cannot be told from the model's own form, so it is not in the single-session
`LIBRARY`: `discovery.diagnose` offers it when new shots are diagnosed against a baseline session.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from golfflight.discovery.effects.base import Context, Effect, Hiding, Reported, World, unchanged
from golfflight.discovery.effects.coefficients import (
    DRAG_SCALE,
    LIFT_SCALE,
    SPIN_DECAY,
    scale_columns,
    scale_knobs,
    scale_settings,
)
from golfflight.discovery.effects.parts import plus_minus, signed
from golfflight.discovery.schema import CorrectionSettings

KNOBS = ("drag_scale", "lift_scale", "spin_decay_scale")
"""The ball's parameters: the reference world's knobs it turns, multipliers of C_D, C_L and C_M's spin decay."""

DRAG_AND_LIFT = KNOBS[:2]
"""The two scales the recorded outcomes measure to a few per cent against a baseline; the spin decay they do not
(docs/discovery.md, "Another ball: what these outcomes tell of it")."""

_apply = scale_columns(KNOBS)


def _describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
    sd = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    return {k: float(v) for k, v in zip(KNOBS, theta)}, {k: float(s) for k, s in zip(KNOBS, sd)}


def _phrase(p: dict[str, float], u: dict[str, float]) -> str:
    drag, lift, decay = (plus_minus(p[k], u[k]) for k in KNOBS)
    unmeasured = f"spin decay {decay}, which these outcomes do not measure"
    return f"another ball: drag scaled by {drag} and lift by {lift} ({unmeasured})"


def _scales(p: dict[str, float]) -> dict[str, float]:
    return {k: p[k] for k in KNOBS}


def _reference(p: dict[str, float], world: World) -> World:
    return scale_knobs(_scales(p), world)


def _setting(settings: CorrectionSettings, p: dict[str, float], context: Context, wind_factor: float | None) -> None:
    """No service option: the three scales as model changes, as the separate scale effects give them."""
    scale_settings(settings, _scales(p))


BALL = Effect(
    "ball",
    tuple(replace(e.parameters[0], name=k) for e, k in zip((DRAG_SCALE, LIFT_SCALE, SPIN_DECAY), KNOBS)),
    _apply,
    _describe,
    "another ball: drag, lift and spin decay scaled as one cause",
    kind="ball",
    words="another ball",
    phrase=_phrase,
    setting=_setting,
    hiding=Hiding(
        signed(drag_scale=(1.0, 0.03, 0.08), lift_scale=(1.0, 0.04, 0.10), spin_decay_scale=(1.0, 0.1, 0.3)),
        unchanged,
        _reference,
        _apply,
    ),
)
