"""The validation felt error of every run of `golfflight train-real --variant` (the number the served-variant rule
of docs/training_real.md compares): per run its felt error over the six real sources (`joint.selection_loss`), over
the five with a carry (what NN can be scored on, `real_nn.nn_selection_loss`) and per source; then each variant's mean
over its seeds and their spread. Reads only the runs' history.json; no held-out set.

    python3 scripts/variant_validation.py LABEL=WORK[,WORK...] [LABEL=WORK...]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.model_export.joint import JointConfig, felt_error_m
from golfflight.model_export.real_nn import nn_selection_loss
from golfflight.shots.markdown import table

SOURCES = ("trackman-outdoor", "sentry-2022", "players-2020", "tour-championship-2020", "trackman-model",
           "pga-2023-table")


def run_row(label: str, run: Path) -> tuple[list[str], float | None, float]:
    """A table row of one run, its six-source felt error (None for NN) and its five-source one."""
    final = json.loads((run / "history.json").read_text())["final"]
    metrics = {"sources": final["val"]}
    five = nn_selection_loss(metrics, JointConfig())
    has_all = all(s in final["val"] and ("carry_y_m_mae" in final["val"][s] or "apex_m_mae" in final["val"][s])
                  for s in SOURCES)
    six = sum(felt_error_m(final["val"][s]) for s in SOURCES) / len(SOURCES) if has_all else None
    per_source = [f"{felt_error_m(final['val'][s]):.2f}" if s in final["val"] and (
        "carry_y_m_mae" in final["val"][s] or "apex_m_mae" in final["val"][s]) else "—" for s in SOURCES]
    return [f"{label} {run.name}", "—" if six is None else f"{six:.2f}", f"{five:.2f}", *per_source], six, five


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("variants", nargs="+", help="LABEL=WORK[,WORK...]: a variant's train-real work folders")
    args = parser.parse_args()
    rows, summary = [], []
    for spec in args.variants:
        label, _, works = spec.partition("=")
        runs = sorted(run for work in works.split(",") for run in Path(work).glob("seed-*")
                      if (run / "history.json").is_file())
        results = [run_row(label, run) for run in runs]
        rows += [row for row, _, _ in results]
        for index, name in ((1, "six sources"), (2, "five with a carry")):
            values = [r[index] for r in results if r[index] is not None]
            if values:
                summary.append([label, name, str(len(values)), f"{sum(values) / len(values):.2f}",
                                f"{min(values):.2f}–{max(values):.2f}", f"{max(values) - min(values):.2f}"])
    print("\n".join(table(["run", "felt, six sources", "felt, five with a carry", *SOURCES], rows)))
    print()
    print("\n".join(table(["variant", "felt error over", "seeds", "mean", "range", "spread"], summary)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
