"""The held-out errors a shipped card records: each held-out set (`shots.heldout`) flown through the runtime path
(the bundle's ONNX graph in the NumPy Euler loop), calm, in its own air where it is known (the TOUR Championship
2020: the event's, `shots.source_air`), else in the card's air; mean absolute error per observable."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.evaluation.accuracy_flyers import model_flyer
from golfflight.evaluation.accuracy_sets import (
    TOUR_CHAMPIONSHIP_HELD_OUT,
    TRACKMAN_HELD_OUT,
    held_out_driver_shots,
    outcome_errors,
    tee_groups,
    tour_championship_shots,
)
from golfflight.flight.flyer import Flyer
from golfflight.shots.files import write_text_atomic
from golfflight.shots.heldout import HeldOutSet
from golfflight.shots.pbp import hole_pars
from golfflight.shots.source_air import TOUR_CHAMPIONSHIP_2020
from golfflight.weights_schema.bundle import CARD_FILE, load_bundle, sha256_of
from golfflight.weights_schema.model_card import HeldOutResult, ModelCard

FLIGHT_ERRORS = {"landing_m": "landing_point_m", "carry_m": "carry_m", "side_m": "side_m", "apex_m": "apex_m",
                 "landing_angle_deg": "landing_angle_deg", "flight_time_s": "flight_time_s"}
"""Keys of `outcome_errors` -> the card's error names (mean absolute value; the landing point's is a distance)."""


def _mae(errors: dict[str, np.ndarray], names: dict[str, str], mask: np.ndarray | None = None) -> dict[str, float]:
    out = {}
    for key, name in names.items():
        values = errors[key] if mask is None else errors[key][mask]
        values = values[np.isfinite(values)]
        if len(values):
            out[name] = float(np.mean(np.abs(values)))
    return out


def _result(held: HeldOutSet, path: Path, n: int, errors: dict[str, float], note: str) -> HeldOutResult:
    return HeldOutResult(name=held.name, path=str(held.path), sha256=sha256_of(path), rows=held.rows(), n_shots=n,
                         errors=errors, note=note)


def _drivers(flyer: Flyer, path: Path) -> HeldOutResult:
    """TrackMan's held-out lines, in the card's air (the range sessions recorded none)."""
    shots, note = held_out_driver_shots(path)
    errors = _mae(outcome_errors(flyer.flight(launch_problem(shots.launch())), shots), FLIGHT_ERRORS)
    return _result(TRACKMAN_HELD_OUT, path, len(shots), errors, f"all ball types; in the card's air; {note}")


def _tour_championship(flyer: Flyer, path: Path) -> HeldOutResult:
    """The TOUR Championship's held-out rounds in the event's air: apex MAE of all tee shots and of each group of
    `accuracy_sets.TEE_GROUPS` ('par3_apex_m', 'par4_5_apex_m')."""
    shots, note = tour_championship_shots(path)
    errors = outcome_errors(flyer.flight(launch_problem(shots.launch(), TOUR_CHAMPIONSHIP_2020.air())), shots)
    measured = _mae(errors, {"apex_m": "apex_m"})
    for name, mask in tee_groups(shots, hole_pars(path)).items():
        measured |= _mae(errors, {"apex_m": f"{name}_apex_m"}, mask)
    return _result(TOUR_CHAMPIONSHIP_HELD_OUT, path, len(shots), measured,
                   f"in the event's air ({TOUR_CHAMPIONSHIP_2020.basis}); {note}")


def held_out_results(bundle: str | os.PathLike, data_dir: str | os.PathLike) -> list[HeldOutResult]:
    """The bundle's errors on every held-out set present under `data_dir` (sets that are absent are left out)."""
    flyer, data_dir = model_flyer(bundle), Path(data_dir)
    sets = ((TRACKMAN_HELD_OUT, _drivers), (TOUR_CHAMPIONSHIP_HELD_OUT, _tour_championship))
    return [measure(flyer, data_dir / held.path) for held, measure in sets if (data_dir / held.path).is_file()]


def record_held_out(bundle: str | os.PathLike, data_dir: str | os.PathLike) -> ModelCard:
    """Measure the held-out errors and write them into the bundle's card (the graph is not touched)."""
    card, _ = load_bundle(bundle)
    updated = ModelCard.model_validate({**card.model_dump(mode="json"), "schema_version": "1.2",
                                        "held_out": [r.model_dump() for r in held_out_results(bundle, data_dir)]})
    write_text_atomic(Path(bundle) / CARD_FILE, json.dumps(updated.model_dump(mode="json"), indent=2) + "\n")
    return updated
