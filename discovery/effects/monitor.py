"""Biases of the launch monitor: a launch value recorded off by an offset (angles) or a scale (speed, spin).

The true launch = recorded + offset (or recorded x scale); `prove` hides one by recording true - offset (or
true / scale) before the noise is added, and flies the true launches.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from golfflight.discovery.effects.base import Context, Effect, Hiding, Parameter, unchanged
from golfflight.discovery.effects.parts import plus_minus, scaled, signed, single
from golfflight.discovery.schema import CorrectionSettings
from golfflight.discovery.simulator import Setup
from golfflight.shots.synth import LaunchTable


def _bias(
    name: str, column: str, parameter: Parameter, plausible: tuple[float, float], words: str, setting: str
) -> Effect:
    """The bias `name` of the launch value `column`: an offset where `parameter` is `offset_deg`, else a scale;
    `plausible` (low, high) is the size `prove` hides, either sign; `setting` the launch correction's key."""
    key = parameter.name
    offset = key == "offset_deg"

    def apply(theta: np.ndarray, conditions: Setup) -> Setup:
        out = conditions.copy()
        out.launch[column] = out.launch[column] + theta[:, 0] if offset else out.launch[column] * theta[:, 0]
        return out

    def recorded(p: dict[str, float], launches: LaunchTable) -> LaunchTable:
        value = getattr(launches, column)
        return replace(launches, **{column: value - p[key] if offset else value / p[key]})

    def correction(settings: CorrectionSettings, p: dict[str, float], context: Context, wind: float | None) -> None:
        settings.launch_corrections[setting] = p[key]

    def offset_phrase(p: dict[str, float], u: dict[str, float]) -> str:
        return f"a {name.replace('_', ' ')} of {plus_minus(p[key], u[key], '°')} (true − recorded)"

    value = column.rsplit("_", 1)[0].replace("_", " ")
    return Effect(
        name,
        (parameter,),
        apply,
        single(key),
        f"the true {value} = recorded + offset" if offset else f"the true {value} = recorded x scale",
        kind="monitor",
        words=words,
        phrase=offset_phrase if offset else scaled(f"true/recorded {value} of"),
        setting=correction,
        hiding=Hiding(signed(**{key: (parameter.null, *plausible)}), recorded, unchanged, unchanged),
    )


LAUNCH_ANGLE_BIAS = _bias(
    "launch_angle_bias",
    "launch_angle_deg",
    Parameter("offset_deg", "deg", 0.0, -6.0, 6.0, 1.0, 0.1),
    (0.7, 2.0),
    "launch angle reading",
    "launch_angle_deg_add",
)
LAUNCH_DIRECTION_BIAS = _bias(
    "launch_direction_bias",
    "launch_direction_deg",
    Parameter("offset_deg", "deg", 0.0, -10.0, 10.0, 1.0, 0.1),
    (1.0, 3.0),
    "launch direction reading",
    "launch_direction_deg_add",
)
BALL_SPEED_BIAS = _bias(
    "ball_speed_bias",
    "ball_speed_mps",
    Parameter("scale", "1", 1.0, 0.85, 1.15, 0.02, 0.003),
    (0.015, 0.04),
    "ball speed reading",
    "ball_speed_scale",
)
SPIN_BIAS = _bias(
    "spin_bias",
    "spin_rpm",
    Parameter("scale", "1", 1.0, 0.6, 1.5, 0.05, 0.01),
    (0.06, 0.15),
    "spin reading",
    "spin_rpm_scale",
)
SPIN_AXIS_BIAS = _bias(
    "spin_axis_bias",
    "spin_axis_deg",
    Parameter("offset_deg", "deg", 0.0, -15.0, 15.0, 2.0, 0.2),
    (2.0, 5.0),
    "spin axis reading",
    "spin_axis_deg_add",
)
