"""The recordings the reference world is calibrated on: the training split of every trainable real source, each in
its own air (`shots.source_air`), grouped into calibration cells (`shots.calibrate_reference`).

Nothing held out (`shots.heldout`) reaches the fit: the sources come through `model_export.real_data`'s builders,
which refuse held-out rows, and only their `train` split is used, so the validation groups that choose the
real-data model's weights and seed stay unseen by its teacher too.
"""

from __future__ import annotations

import os
from pathlib import Path

from golfflight.model_export.real_data import (
    pga_table,
    players,
    sentry,
    tour_championship,
    trackman_model,
    trackman_outdoor,
)
from golfflight.shots.calibrate_reference import CalibrationCell, cells_from_records, table_cells
from golfflight.shots.heldout import check_training_rows
from golfflight.shots.reference_world import CALIBRATION_AIR, read_tour_averages
from golfflight.shots.source_air import KNOWN_AIR, UNKNOWN_AIR_SOURCES
from golfflight.shots.trackman import load_trackman

NORMALIZED_7IRON_FILE = Path("real/trackman_normalized_7iron/trackman-csv-export-20230807.Normalized.csv")
NORMALIZED_7IRON_AIR = KNOWN_AIR["trackman-normalized-7iron"].air()

RECORDED_SOURCES = {"trackman-outdoor": trackman_outdoor, "trackman-model": trackman_model, "sentry-2022": sentry,
                    "players-2020": players, "tour-championship-2020": tour_championship}
"""Shot-level sources. Of the driver file only the Premium balls: the reference world is a tour ball's, and the
file's "Limited Distance Soft" range balls fly shorter by design."""
FITTED_AIR_FACTORS = {"trackman-outdoor": 1.0721}
"""The density factors of the committed calibration (`golfflight calibrate-reference --fit` prints them)."""


def calibration_cells(root: str | os.PathLike) -> list[CalibrationCell]:
    """Every calibration cell from the shared data folder `root`, each in its source's stated air (an unknown-air
    source in CALIBRATION_AIR: apply its fitted factor with `shots.calibrate_reference.with_air_factors`)."""
    root = Path(root)
    cells: list[CalibrationCell] = []
    for name, build in RECORDED_SOURCES.items():
        records = [r for r in build(root).records if r.split == "train" and r.ball in (None, "Premium")]
        air = CALIBRATION_AIR if name in UNKNOWN_AIR_SOURCES else KNOWN_AIR[name].air()
        cells += cells_from_records(name, records, air)
    path = root / NORMALIZED_7IRON_FILE
    conversion = load_trackman(path, min_tracked_fraction=None, skip_bad_rows=True)
    check_training_rows(path, (int(r.shot_id) for r in conversion.records))
    cells += cells_from_records("trackman-normalized-7iron", conversion.records, NORMALIZED_7IRON_AIR,
                                bands=(0.0, 200.0))
    table = pga_table(root)
    clubs = {c.club: c for c in read_tour_averages(root / next(iter(table.files)))}
    trained = [clubs[r.club] for r in table.records if r.split == "train"]
    cells += table_cells("pga-2023-table", trained, KNOWN_AIR["pga-2023-table"].air())
    return cells
