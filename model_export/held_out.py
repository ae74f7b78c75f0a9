"""The held-out errors a shipped card records: each held-out set (NOTES section 9) flown through the runtime path
(the bundle's ONNX graph in the NumPy Euler loop), calm, in the card's air; mean absolute error per observable."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from flight.constants import YARD_M
from model_export.accuracy_flyers import ModelFlyer
from model_export.accuracy_sets import (
    PGA_AVERAGES_HELD_OUT,
    TOUR_CHAMPIONSHIP_HELD_OUT,
    TRACKMAN_HELD_OUT,
    compare_clubs,
    held_out_driver_shots,
    outcome_errors,
    tour_championship_shots,
)
from shots.files import write_text_atomic
from shots.heldout import HeldOutSet
from shots.reference_world import read_tour_averages
from weights_schema.bundle import CARD_FILE, load_bundle, sha256_of
from weights_schema.model_card import HeldOutResult, ModelCard

FLIGHT_ERRORS = {"landing_m": "landing_point_m", "carry_m": "carry_m", "side_m": "side_m", "apex_m": "apex_m",
                 "landing_angle_deg": "landing_angle_deg", "flight_time_s": "flight_time_s"}
"""Keys of `outcome_errors` -> the card's error names (mean absolute value; the landing point's is a distance)."""


def _mae(errors: dict[str, np.ndarray], names: dict[str, str]) -> dict[str, float]:
    out = {}
    for key, name in names.items():
        values = errors[key][np.isfinite(errors[key])]
        if len(values):
            out[name] = float(np.mean(np.abs(values)))
    return out


def _result(held: HeldOutSet, path: Path, n: int, errors: dict[str, float], note: str) -> HeldOutResult:
    rows = "all" if held.first_line == 1 else f"lines {held.first_line} on"
    return HeldOutResult(name=held.name, path=str(held.path), sha256=sha256_of(path), rows=rows, n_shots=n,
                         errors=errors, note=note)


def held_out_results(bundle: str | os.PathLike, data_dir: str | os.PathLike) -> list[HeldOutResult]:
    """The bundle's errors on every held-out set present under `data_dir` (sets that are absent are left out)."""
    flyer, data_dir, results = ModelFlyer(bundle), Path(data_dir), []
    driver = data_dir / TRACKMAN_HELD_OUT.path
    if driver.is_file():
        shots, note = held_out_driver_shots(driver)
        errors = _mae(outcome_errors(flyer.simulate(shots.launch()), shots), FLIGHT_ERRORS)
        results.append(_result(TRACKMAN_HELD_OUT, driver, len(shots), errors, f"all ball types; {note}"))
    tour = data_dir / TOUR_CHAMPIONSHIP_HELD_OUT.path
    if tour.is_file():
        shots, note = tour_championship_shots(tour)
        errors = _mae(outcome_errors(flyer.simulate(shots.launch()), shots), {"apex_m": "apex_m"})
        results.append(_result(TOUR_CHAMPIONSHIP_HELD_OUT, tour, len(shots), errors, note))
    averages = data_dir / PGA_AVERAGES_HELD_OUT.path
    if averages.is_file():
        clubs = read_tour_averages(averages)
        mae = compare_clubs(flyer, clubs).mean_absolute_error
        results.append(_result(PGA_AVERAGES_HELD_OUT, averages, len(clubs),
                               {"carry_m": float(mae[0]) * YARD_M, "max_height_m": float(mae[1]) * YARD_M,
                                "landing_angle_deg": float(mae[2])},
                               "each club's average launch against TrackMan's average outcome (a check only)"))
    return results


def record_held_out(bundle: str | os.PathLike, data_dir: str | os.PathLike) -> ModelCard:
    """Measure the held-out errors and write them into the bundle's card (the graph is not touched)."""
    card, _ = load_bundle(bundle)
    updated = ModelCard.model_validate({**card.model_dump(mode="json"), "schema_version": "1.2",
                                        "held_out": [r.model_dump() for r in held_out_results(bundle, data_dir)]})
    write_text_atomic(Path(bundle) / CARD_FILE, json.dumps(updated.model_dump(mode="json"), indent=2) + "\n")
    return updated
