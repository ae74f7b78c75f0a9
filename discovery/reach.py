"""How far a baseline session reaches over a new one: which new shots lie outside the baseline's launches (where the
learned form is extrapolated), which baseline shots would cover them, and what the baseline cannot teach at all.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from golfflight.discovery.discrepancy import INPUTS
from golfflight.discovery.form import LearnedForm
from golfflight.discovery.recordings import LABELS, OBSERVABLES, UNKNOWN_CLUB, Recordings
from golfflight.discovery.schema import BaselineInfo
from golfflight.errors import InputError
from scipy.spatial import cKDTree

OUTSIDE_DISTANCE = 1.0
"""A new shot lies outside the baseline's launches where no baseline shot is nearer than this, in standard deviations
of the baseline's launch values (the discrepancy's middle length scale; 300 shots of a bag of clubs lie within about
0.3 of each other)."""

AIR_SPAN = 1.10
"""A baseline whose densest air is less than this many times its thinnest cannot teach how the flight responds to
air: thinner or denser air is then flown as the model's own physics says."""

WORDS = {
    "ball_speed_mps": ("ball speed", "m/s", 0),
    "launch_angle_deg": ("launch angle", "deg", 1),
    "spin_rpm": ("spin", "rpm", -2),
    "spin_axis_deg": ("spin axis", "deg", 1),
}


def _span(values: np.ndarray, low: float = 0.0, high: float = 100.0) -> list[float]:
    finite = values[np.isfinite(values)]
    return [float(np.percentile(finite, low)), float(np.percentile(finite, high))] if len(finite) else []


def _range_words(name: str, span: list[float]) -> str:
    label, unit, digits = WORDS[name]
    low, high = (round(v, digits) for v in span)
    number = "{:,.0f}" if digits <= 0 else f"{{:,.{digits}f}}"
    return f"{label} {number.format(low)}–{number.format(high)} {unit}"


def needed_words(outside_launch: dict[str, list[float]], clubs: list[str]) -> str:
    """The baseline shots that would cover the new session's outside shots, in words."""
    if not outside_launch:
        return ""
    ranges = ", ".join(_range_words(name, span) for name, span in outside_launch.items() if span)
    which = f" (the new session's {', '.join(clubs)})" if clubs else ""
    return f"Record baseline shots at {ranges}{which}, with the same launch monitor and ball."


def _outcome_words(names: list[str]) -> str:
    return ", ".join(LABELS[name].split(" (")[0] for name in names)


def comparable(recordings: Recordings, form: LearnedForm) -> Recordings:
    """The new recordings with only the outcomes the baseline recorded: the others have no baseline to differ from
    (a form and discrepancy never learned for them would read the model's own form error as a change)."""
    shared = [name for name in recordings.observed_names if name in form.informs]
    if not shared:
        new, old = _outcome_words(list(recordings.observed_names)), _outcome_words(list(form.informs)) or "nothing"
        raise InputError(f"the baseline records none of the new session's outcomes ({new}; it records {old})")
    keep = np.array([name in form.informs for name in OBSERVABLES])
    return replace(recordings, observed=np.where(keep, recordings.observed, np.nan))


def cannot_inform(form: LearnedForm, new_density: list[float]) -> list[str]:
    """What the baseline cannot teach about the new shots."""
    thinnest, densest = float(np.min(form.density_kg_m3)), float(np.max(form.density_kg_m3))
    notes = []
    unrecorded = [name for name in OBSERVABLES if name not in form.informs]
    if unrecorded:
        notes.append(
            f"the new shots' {_outcome_words(unrecorded)}: it records none of them (or on fewer than 10 shots), so "
            "they are not compared"
        )
    if densest < AIR_SPAN * thinnest:
        notes.append(
            f"how this ball and monitor respond to other air: the baseline flew at {thinnest:.3f}–{densest:.3f} kg/m³ "
            "only, so thinner or denser air is flown as the model's own physics says (its two air variants differ "
            "there)"
        )
    if new_density and (new_density[0] < thinnest / AIR_SPAN or new_density[1] > densest * AIR_SPAN):
        notes.append(
            f"the new shots' assumed air ({new_density[0]:.3f}–{new_density[1]:.3f} kg/m³) lies outside the "
            "baseline's: the learned form is carried there by the dynamic pressure alone"
        )
    return notes


def outside_baseline(form: LearnedForm, launch: dict[str, np.ndarray]) -> np.ndarray:
    """True [N] where a new shot's launch lies further than OUTSIDE_DISTANCE from every baseline shot's."""
    scale = form.discrepancy.standardized
    distance, _ = cKDTree(scale(form.launches)).query(scale(launch))
    return distance > OUTSIDE_DISTANCE


def baseline_info(form: LearnedForm, recordings: Recordings, new_density_kg_m3: np.ndarray) -> BaselineInfo:
    """The report's account of the baseline against the new recordings."""
    outside = outside_baseline(form, recordings.launch)
    outside_launch = {name: _span(recordings.launch[name][outside]) for name in INPUTS} if outside.any() else {}
    clubs = sorted({str(c) for c in recordings.club[outside]} - {UNKNOWN_CLUB})
    new_density = _span(np.asarray(new_density_kg_m3, dtype=float))
    return BaselineInfo(
        source=form.source,
        n_shots=form.n_shots,
        heldout_error_before=form.error_before,
        heldout_error_after=form.error_after,
        form=form.weights(),
        discrepancy_sd={name: p.amplitude for name, p in zip(OBSERVABLES, form.discrepancy.processes, strict=True)},
        baseline_density_kg_m3=_span(form.density_kg_m3),
        new_density_kg_m3=new_density,
        baseline_launch={name: _span(form.launches[name], 1.0, 99.0) for name in INPUTS},
        outside_shots=int(outside.sum()),
        outside_launch=outside_launch,
        outside_clubs=clubs,
        needed=needed_words(outside_launch, clubs),
        cannot_inform=cannot_inform(form, new_density),
    )


def baseline_sentence(info: BaselineInfo, n_shots: int) -> str:
    """The statement's opening on the baseline: what it taught and how far it reaches over the new shots."""
    text = (
        f"Against the baseline session {info.source} ({info.n_shots:,} shots): the model's form learned from it "
        f"takes its held-out error from {info.heldout_error_before:.2f} to {info.heldout_error_after:.2f} (1 = noise "
        "alone), and what differs below is what changed since. "
    )
    if info.outside_shots:
        text += (
            f"{info.outside_shots:,} of the {n_shots:,} new shots lie outside the baseline's launches, where the "
            f"learned form is extrapolated and each shot is expected to miss by more. {info.needed} "
        )
    for note in info.cannot_inform:
        text += f"The baseline cannot teach {note}. "
    return text
