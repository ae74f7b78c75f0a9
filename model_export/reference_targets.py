"""The recordings the reference world is calibrated on: the training split of the measured real sources and
TrackMan's normalized 7-iron set, grouped into calibration cells (`shots.calibrate_reference`).

Nothing held out (NOTES section 9) reaches the fit: the measured sources come through `model_export.real_data`'s
builders, which refuse held-out rows, and only their `train` split is used, so the validation groups that pick the
real-data model's seed stay unseen by its teacher too. The PGA TOUR 2023 averages are a check only.
"""

from __future__ import annotations

import os
from pathlib import Path

from flight.air import Air
from flight.constants import FOOT_M
from model_export.real_data import players, sentry, trackman_outdoor
from shots.calibrate_reference import CalibrationCell, cells_from_records
from shots.heldout import check_training_rows
from shots.reference_world import CALIBRATION_AIR
from shots.trackman import load_trackman

NORMALIZED_7IRON_FILE = Path("real/trackman_normalized_7iron/trackman-csv-export-20230807.Normalized.csv")
NORMALIZED_7IRON_AIR = Air.from_conditions(temperature_c=25.0, altitude_m=1135 * FOOT_M, humidity_pct=50.0)
"""The file's stated normalization (its SOURCE.txt): no wind, 1,135 ft, 77 F; humidity is not stated (50 %)."""

MEASURED_SOURCES = {"trackman-outdoor": trackman_outdoor, "sentry-2022": sentry, "players-2020": players}
"""Measured flights, flown in CALIBRATION_AIR: none of them recorded its air, and their winds average out over many
groups only in part (a choice, stated in docs/reference_world.md). Of the driver file only the Premium balls: the
reference world is a tour ball's, and the file's "Limited Distance Soft" range balls fly shorter by design."""


def calibration_cells(root: str | os.PathLike) -> list[CalibrationCell]:
    """Every calibration cell from the shared data folder `root`."""
    root = Path(root)
    cells: list[CalibrationCell] = []
    for name, build in MEASURED_SOURCES.items():
        records = [r for r in build(root).records if r.split == "train" and r.ball in (None, "Premium")]
        cells += cells_from_records(name, records, CALIBRATION_AIR)
    path = root / NORMALIZED_7IRON_FILE
    conversion = load_trackman(path, min_tracked_fraction=None, skip_bad_rows=True)
    check_training_rows(path, (int(r.shot_id) for r in conversion.records))
    cells += cells_from_records("trackman-normalized-7iron", conversion.records, NORMALIZED_7IRON_AIR,
                                bands=(0.0, 200.0))
    return cells
