"""What the reference world's calibration does when each source recorded in unknown air gets its own air-density
factor (a prior of PRIOR_SD in log density, mean 1) instead of `CALIBRATION_AIR` for all: the factors, the nine
parameters and the calibration cells, next to the committed fit. Only the calibration cells (training splits) and
the spin-loss figures are used; the held-out PGA table is not flown. docs/training_real.md ("What limits it")
quotes the table.

    python3 scripts/source_air.py [--data DIR] [--prior-sd 0.03]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from flight.air import Air
from flight.constants import YARD_M
from flight.reference_aero import CALIBRATED, ReferenceParameters
from model_export.reference_targets import calibration_cells
from shots.calibrate_reference import FREE_PARAMETERS, CalibrationCell, FitScaling, evaluate, residuals
from shots.markdown import table
from shots.paths import shared_data_dir
from shots.reference_world import CALIBRATION_AIR

PRIOR_SD = 0.03
"""Prior sd of a source's log air density around CALIBRATION_AIR's: a few per cent, the spread of sea-level venues
between cool and hot days."""
LOG_BOUND = 0.15
"""The search box of each log factor."""


def source_of(cell: CalibrationCell) -> str:
    """The source a cell belongs to (its name's first word)."""
    return cell.name.split(" ")[0]


def unrecorded_sources(cells: list[CalibrationCell]) -> list[str]:
    """The sources flown in CALIBRATION_AIR because they recorded no air (the others were recorded in known air)."""
    return sorted({source_of(c) for c in cells if c.air == CALIBRATION_AIR})


def in_denser_air(cell: CalibrationCell, factor: float) -> CalibrationCell:
    """The cell flown in air `factor` times as dense at the same temperature (so the viscosity μ is unchanged and the
    kinematic viscosity ν = μ/ρ divides by the factor)."""
    air = Air(cell.air.density_kg_m3 * factor, cell.air.kinematic_viscosity_m2_s / factor)
    return dataclasses.replace(cell, air=air)


def with_factors(cells: list[CalibrationCell], factors: dict[str, float]) -> list[CalibrationCell]:
    """Every cell of a factored source in its source's air."""
    return [in_denser_air(c, factors[source_of(c)]) if source_of(c) in factors else c for c in cells]


def fit_with_source_air(cells: list[CalibrationCell], prior_sd: float = PRIOR_SD,
                        start: ReferenceParameters = CALIBRATED) -> tuple[ReferenceParameters, dict[str, float], float]:
    """The nine parameters and one density factor per unrecorded-air source, fitted together; and the cost."""
    sources = unrecorded_sources(cells)
    scaling = FitScaling(start)
    low, high = scaling.bounds()
    low, high = np.append(low, np.full(len(sources), -LOG_BOUND)), np.append(high, np.full(len(sources), LOG_BOUND))
    n = len(FREE_PARAMETERS)

    def unpack(x: np.ndarray) -> tuple[ReferenceParameters, dict[str, float]]:
        return scaling.parameters(x[:n]), dict(zip(sources, np.exp(x[n:]).tolist()))

    def misfit(x: np.ndarray) -> np.ndarray:
        params, factors = unpack(x)
        return np.concatenate([residuals(params, with_factors(cells, factors)), x[n:] / prior_sd])

    x0 = np.append(scaling.start_values(), np.zeros(len(sources)))
    solution = least_squares(misfit, x0, bounds=(low, high), diff_step=1e-3, max_nfev=200)
    params, factors = unpack(solution.x)
    return params, factors, float(solution.cost)


def cell_rows(cells: list[CalibrationCell], before: ReferenceParameters, after: ReferenceParameters,
              factors: dict[str, float]) -> list[list[str]]:
    """Per cell: carry, max height and land angle errors of the committed world, and of the refit in its sources' air."""
    old = evaluate(cells, before)
    new = evaluate(with_factors(cells, factors), after)
    units = np.array([YARD_M, YARD_M, 1.0])
    rows = []
    for i, cell in enumerate(cells):
        cells_old = (old.model_mean[i] - old.recorded_mean[i]) / units
        cells_new = (new.model_mean[i] - new.recorded_mean[i]) / units
        rows.append([cell.name, str(cell.n_shots),
                     *(("—" if np.isnan(a) else f"{a:+.1f} → {b:+.1f}") for a, b in zip(cells_old, cells_new))])
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=shared_data_dir(), help="the shared data folder")
    parser.add_argument("--prior-sd", type=float, default=PRIOR_SD, help="prior sd of a source's log density")
    args = parser.parse_args()
    cells = calibration_cells(args.data)
    committed_cost = 0.5 * float(np.sum(residuals(CALIBRATED, cells) ** 2))
    params, factors, cost = fit_with_source_air(cells, args.prior_sd)
    print(f"Cost {committed_cost:.1f} (committed world, every unrecorded source in CALIBRATION_AIR) -> {cost:.1f} "
          f"(own density factor per source, prior sd {args.prior_sd:g} in log density, prior included)\n")
    print("\n".join(table(["source", "density factor"], [[s, f"{f:.3f}"] for s, f in factors.items()])))
    print()
    print("\n".join(table(["parameter", "committed", "with source air"],
                          [[n, f"{getattr(CALIBRATED, n):.5g}", f"{getattr(params, n):.5g}"] for n in FREE_PARAMETERS])))
    print()
    print("\n".join(table(["cell", "shots", "carry err (yd)", "max height err (yd)", "land angle err (°)"],
                          cell_rows(cells, CALIBRATED, params, factors))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
