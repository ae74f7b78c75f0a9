"""The held-out errors of every seed (and of the seeds' soup) of a `golfflight train-real` run, for the spread
between seeds that docs/training_real.md reports (the run itself picks its run on validation only and measures the
held-out sets for that one). Exports each seed's last epoch to WORK/seed-S/bundle (the soup to WORK/soup/bundle)
and prints a markdown table.

    python3 scripts/held_out_per_seed.py WORK [--data DIR] [--init models/synthetic | --variant phys-q]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.evaluation.held_out import record_held_out
from golfflight.flight.constants import FOOT_M, YARD_M
from golfflight.model_export.real_data import DEFAULT_SOURCES, build
from golfflight.model_export.real_training import DATA_FILE, SOUP, export_real
from golfflight.shots.markdown import table
from golfflight.shots.paths import shared_data_dir
from golfflight.weights_schema.bundle import load_bundle
from golfflight.weights_schema.model_card import ModelCard


def cells(card: ModelCard) -> list[str]:
    """TrackMan landing (yd), TOUR Championship rounds 3-4 apex (ft): all tee shots, par 3s, par 4s and 5s."""
    errors = {h.name.split(" ")[0]: h.errors for h in card.held_out or []}
    trackman, tour = errors["TrackMan"], errors["TOUR"]
    apex = " / ".join(f"{tour[key] / FOOT_M:.1f}" for key in ("apex_m", "par3_apex_m", "par4_5_apex_m"))
    return [f"{trackman['landing_point_m'] / YARD_M:.1f} yd", f"{apex} ft"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("work", type=Path, help="the --work directory of a train-real run")
    parser.add_argument("--data", type=Path, default=shared_data_dir(), help="the shared data folder")
    parser.add_argument("--init", default="models/synthetic", help="the run's --init bundle (its architecture)")
    parser.add_argument("--variant", choices=("phys-nn+", "phys-q"), default="phys-nn+",
                        help="the run's --variant (phys-q: no --init, Ferguson 2022's quadratic form)")
    args = parser.parse_args()
    sources = build(args.data, args.work / "sources_for_cards.csv", DEFAULT_SOURCES)
    if args.variant == "phys-q":
        variant, hidden = "phys-q", ()
    else:
        init, _ = load_bundle(args.init)
        variant, hidden = init.variant, tuple(init.architecture.hidden_units)
    rows = []
    soup = [args.work / SOUP] if (args.work / SOUP / "last.pt").is_file() else []
    for seed_dir in sorted(args.work.glob("seed-*")) + soup:
        bundle = seed_dir / "bundle"
        export_real(seed_dir, args.work / DATA_FILE, sources, bundle, variant, hidden)
        rows.append([seed_dir.name, *cells(record_held_out(bundle, args.data))])
    print("\n".join(table(["run", "TrackMan drivers, all: landing error",
                           "TOUR Championship rounds 3-4: apex MAE, all / par 3 / par 4-5"], rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
