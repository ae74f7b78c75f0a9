"""The learning curve of issue 57 on the real flights: each variant's validation felt error over the five sources
with a carry (the error NN can be scored on too, `real_nn.nn_selection_loss`) against the number of training shots,
from `golfflight train-real --train-fraction` runs; mean over seeds with their range, as a markdown table and a PNG.
Reads only the runs' history.json and merged file; no held-out set.

    python3 scripts/learning_curve.py --png docs/figures/learning_curve_real.png LABEL=WORK[,WORK...] ...
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.evaluation.figures import learning_curve
from golfflight.model_export.joint import JointConfig
from golfflight.model_export.real_nn import nn_selection_loss
from golfflight.model_export.real_training import DATA_FILE
from golfflight.shots.markdown import table
from golfflight.shots.records import read_shots


def point(work: Path) -> tuple[int, list[float]]:
    """(training shots, each seed's five-source felt error) of one train-real work folder."""
    split = read_shots(work / DATA_FILE).column("split")
    felt = [nn_selection_loss({"sources": json.loads((run / "history.json").read_text())["final"]["val"]},
                              JointConfig()) for run in sorted(work.glob("seed-*")) if (run / "history.json").is_file()]
    return int(np.sum(split == "train")), felt


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("curves", nargs="+", help="LABEL=WORK[,WORK...]: a variant's work folders, one a point")
    parser.add_argument("--png", type=Path, help="write the figure here")
    args = parser.parse_args()
    rows, shots, errors, spans = [], {}, {}, {}
    for spec in args.curves:
        label, _, works = spec.partition("=")
        points = sorted(point(Path(w)) for w in works.split(","))
        shots[label] = np.array([n for n, _ in points])
        errors[label] = np.array([np.mean(f) for _, f in points])
        spans[label] = np.array([[min(f), max(f)] for _, f in points])
        rows += [[label, str(n), str(len(f)), f"{np.mean(f):.2f}", f"{min(f):.2f}–{max(f):.2f}"] for n, f in points]
    print("\n".join(table(["variant", "training shots", "seeds", "felt error, five sources (m)", "seed range"], rows)))
    if args.png:
        print(f"wrote {learning_curve(shots, errors, spans, args.png, 'validation felt error, five sources (m)')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
