"""The model's coefficients scaled: C_L, C_D or C_M's spin decay this many times the model's (the model's form).

Each scale is one of the reference world's knobs (`flight.reference_aero.ReferenceParameters`) and one column of a
`Setup`'s coefficient scales; `discovery.effects.ball` scales all three at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
from golfflight.discovery.effects.base import Context, Draw, Effect, Hiding, Parameter, World, unchanged
from golfflight.discovery.effects.parts import scaled, signed, single
from golfflight.discovery.schema import CorrectionSettings
from golfflight.discovery.simulator import Setup

COLUMNS = {"lift_scale": 0, "drag_scale": 1, "spin_decay_scale": 2}
"""Each reference-world knob's column in a `Setup`'s coefficient scales (C_L, C_D, C_M)."""

ALIASES: tuple[str, ...] = ("lift_scale", "drag_scale", "spin_decay")
"""The coefficient scales air density is made of: air `ratio` x as dense scales drag, lift and the spin torque by
`ratio` together (exactly so for density alone; real air also moves the Reynolds number). A combination of two or
more of them that agree is air, stated with one parameter (`discovery.physical`)."""


def scale_columns(knobs: tuple[str, ...]) -> Callable[[np.ndarray, Setup], Setup]:
    """Multiplies the coefficient scales of these knobs by theta's columns, in that order."""

    def apply(theta: np.ndarray, conditions: Setup) -> Setup:
        out = conditions.copy()
        out.coefficient_scale = out.coefficient_scale.copy()
        for i, knob in enumerate(knobs):
            out.coefficient_scale[:, COLUMNS[knob]] *= theta[:, i]
        return out

    return apply


def scale_knobs(scales: dict[str, float], world: World) -> World:
    """The reference world with these knobs multiplied by these scales."""
    return replace(world, params=replace(world.params, **{k: getattr(world.params, k) * v for k, v in scales.items()}))


def scale_settings(settings: CorrectionSettings, scales: dict[str, float]) -> None:
    """These knobs' scales as model changes (no service option), multiplied into any already there."""
    for knob, value in scales.items():
        settings.coefficient_scales[knob] = settings.coefficient_scales.get(knob, 1.0) * value


def _coefficient(name: str, knob: str, parameter: Parameter, summary: str, words: str, draw: Draw) -> Effect:
    """The effect `name` that scales the coefficient of `knob` by its one parameter, reported as `scale`."""

    def reference(p: dict[str, float], world: World) -> World:
        return scale_knobs({knob: p["scale"]}, world)

    def setting(settings: CorrectionSettings, p: dict[str, float], context: Context, wind: float | None) -> None:
        scale_settings(settings, {knob: p["scale"]})

    apply = scale_columns((knob,))
    return Effect(
        name,
        (parameter,),
        apply,
        single("scale"),
        summary,
        kind="form",
        words=words,
        phrase=scaled(f"{words} scaled by"),
        setting=setting,
        hiding=Hiding(draw, unchanged, reference, apply),
    )


def _faster_or_slower(rng: np.random.Generator) -> dict[str, float]:
    """Spin decaying 1.6-2.5 x as fast, or 0.35-0.6 x, evenly."""
    return {"scale": float(rng.uniform(1.6, 2.5) if rng.random() < 0.5 else rng.uniform(0.35, 0.6))}


SPIN_DECAY = _coefficient(
    "spin_decay",
    "spin_decay_scale",
    Parameter("scale", "1", 1.0, 0.2, 4.0, 0.3, 0.05),
    "spin decays this many times as fast as the model's C_M says",
    "spin decay",
    _faster_or_slower,
)
DRAG_SCALE = _coefficient(
    "drag_scale",
    "drag_scale",
    Parameter("scale", "1", 1.0, 0.7, 1.4, 0.05, 0.005),
    "the drag coefficient is this many times the model's",
    "drag",
    signed(scale=(1.0, 0.04, 0.10)),
)
LIFT_SCALE = _coefficient(
    "lift_scale",
    "lift_scale",
    Parameter("scale", "1", 1.0, 0.6, 1.5, 0.05, 0.005),
    "the lift coefficient is this many times the model's",
    "lift",
    signed(scale=(1.0, 0.05, 0.12)),
)
