"""The report's vocabulary for a reader: each observable, launch value and effect in plain words with its unit, and
numbers written with their units, so report.html never shows a field name where a quantity is meant."""

from __future__ import annotations

import numpy as np
from golfflight.discovery.effects import EFFECTS

OBSERVABLE_WORDS = {
    "carry_y_m": "carry",
    "carry_x_m": "carry across the line",
    "apex_m": "apex",
    "flight_time_s": "flight time",
    "landing_angle_deg": "landing angle",
}
"""Each observable as a reader names it."""

UNITS = {"carry_y_m": "m", "carry_x_m": "m", "apex_m": "m", "flight_time_s": "s", "landing_angle_deg": "°"}
"""Each observable's unit."""

DIRECTIONS = {
    "carry_y_m": ("longer", "shorter"),
    "carry_x_m": ("further right", "further left"),
    "apex_m": ("higher", "lower"),
    "flight_time_s": ("longer", "shorter"),
    "landing_angle_deg": ("steeper", "shallower"),
}
"""How a positive and a negative residual (recorded − model) of each observable reads: the recordings are …"""

COVARIATE_WORDS = {
    "ball_speed_mps": ("ball speed", "m/s"),
    "launch_angle_deg": ("launch angle", "°"),
    "spin_rpm": ("spin", "rpm"),
    "spin_axis_deg": ("spin axis", "°"),
    "launch_direction_deg": ("launch direction", "°"),
    "shot_order": ("shot order", "shot number"),
}
"""Each launch value the residuals are tested against, in words, with its unit."""

EFFECT_WORDS = {name: effect.words for name, effect in EFFECTS.items() if effect.words} | {
    "unlisted": "learned extra acceleration"
}
"""Each effect in words (`Effect.words`), and the learned correction (an effect not listed reads as its name with
spaces)."""

PARAMETER_UNITS = (
    ("_kg_m3", "kg/m³"),
    ("_mps", "m/s"),
    ("_deg", "°"),
    ("_rpm", "rpm"),
    ("_m", "m"),
    ("_s", "s"),
    ("_c", "°C"),
)
"""A field name's suffix and the unit it stands for, longest first where two share an ending."""


def covariate_label(name: str) -> str:
    """'ball speed (m/s)': a launch value with its unit, for an axis or a header."""
    words, unit = COVARIATE_WORDS.get(name, (name.replace("_", " "), ""))
    return f"{words} ({unit})" if unit else words


def effect_words(name: str) -> str:
    """A candidate's name in words: 'wind + air density' for 'wind+air_density'."""
    return " + ".join(EFFECT_WORDS.get(part, part.replace("_", " ")) for part in name.split("+"))


def unit_of(key: str) -> str:
    """The unit a field name ends in ('' for a ratio, scale or count)."""
    for suffix, unit in PARAMETER_UNITS:
        if key.endswith(suffix):
            return unit
    return ""


def key_words(key: str) -> str:
    """A field name without its unit suffix, in words: 'equivalent altitude' for 'equivalent_altitude_m'."""
    for suffix, _ in PARAMETER_UNITS:
        if key.endswith(suffix):
            key = key[: -len(suffix)]
            break
    return key.replace("_", " ")


def decimals(sd: float) -> int:
    """Decimals that show an uncertainty to two significant digits where it starts with 1 or 2, else to one (the
    usual convention: 0.177 ± 0.007, 8.44 ± 0.23)."""
    if not (sd > 0 and np.isfinite(sd)):
        return 2
    exponent = int(np.floor(np.log10(sd)))
    digits = 2 if sd / 10.0**exponent < 3 else 1
    return int(np.clip(digits - 1 - exponent, 0, 6))


def with_unit(text: str, unit: str) -> str:
    """'4.2 m', '60°', '0.91' (no space before a degree sign)."""
    if not unit:
        return text
    return f"{text}{unit}" if unit == "°" else f"{text} {unit}"


def quantity(value: float, sd: float | None = None, unit: str = "") -> str:
    """'0.99 ± 0.03 m' with as many decimals as the uncertainty needs; '0.99 m' without one."""
    if sd is None or not np.isfinite(sd):
        return with_unit(f"{value:.3g}", unit)
    places = decimals(sd)
    return with_unit(f"{value:.{places}f} ± {sd:.{places}f}", unit)


SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def p_value(p: float) -> str:
    """'p = 0.003', 'p = 3.2 × 10⁻⁵', or 'p < 10⁻⁶' where the number itself says nothing more."""
    if p < 1e-6:
        return "p < 10⁻⁶"
    if p < 1e-3:
        exponent = int(np.floor(np.log10(p)))
        return f"p = {p / 10.0**exponent:.2g} × 10{str(exponent).translate(SUPERSCRIPT)}"
    return f"p = {p:.2g}"


def signed(value: float, unit: str = "") -> str:
    """'−0.38 m', '+1.2 m': two significant digits, a true minus sign."""
    return with_unit(f"{value:+.2g}".replace("-", "−"), unit)
