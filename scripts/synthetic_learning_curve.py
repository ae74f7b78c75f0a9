"""Issue 57's learning curve on the synthetic world: each variant's validation landing error against the recorded
(noisy) outcomes and its model-form error against the reference world on the same launches, against n training shots.

The world that made the data is known, so the model-form error (model against the nominal reference world, calm, the
training sessions' mean air, both fed the same recorded launches) is read apart from the weather and measurement noise
that the validation error also holds. Bias is the mean signed length error (prediction minus recorded, or minus the
world, along the target line). Each error and bias has a 95 % interval that resamples whole sessions (one player
or robot, one day, one hidden weather: `evaluation.variant_comparison.block_bootstrap`), never single shots. Runs come
from `scripts/train_synthetic_learning_curve.sh`.

    python3 scripts/synthetic_learning_curve.py subset --data SYNTH.csv --train-shots 1000 --out SUBSET.csv
    python3 scripts/synthetic_learning_curve.py report --data SYNTH.csv [--png PNG] [--results FILE] RUN...
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.evaluation.figures import learning_curves
from golfflight.evaluation.noise_floor import nominal_conditions, reference_prediction
from golfflight.evaluation.validation import Prediction, errors_of
from golfflight.evaluation.variant_comparison import block_bootstrap
from golfflight.model_export.evaluate import DISPLAY, evaluate_run
from golfflight.model_export.real_training import thin_training_rows
from golfflight.model_export.validation import ValidationSet, load_validation
from golfflight.shots.markdown import table
from golfflight.shots.records import read_shots

HEADERS = ["variant", "training shots", "epochs × batch (best epoch)", "seeds",
           "validation landing error m [95 %] (bias [95 %])", "model-form error m [95 %] (bias [95 %])",
           "seed range, validation / form m", "train time min"]
ORDER = ("phys-nn+", "phys-q", "nn")
"""The table's and the figure's order of the issue's three variants (any other variant after them)."""
PER_SHOT = ("val_landing_m", "val_length_bias_m", "form_landing_m", "form_length_bias_m")
"""The statistics that are means over the validation shots, so each gets a session-bootstrap interval."""


def subset(data: Path, train_shots: int, out: Path) -> int:
    """Copy `data` to `out` keeping `train_shots` of its training rows (drawn as `thin_training_rows` draws them, so
    a smaller subset lies inside a larger one) and every validation row; returns the training rows kept."""
    n_train = int(np.sum(read_shots(data).column("split") == "train"))
    if not 0 < train_shots <= n_train:
        raise SystemExit(f"--train-shots must be from 1 to the file's {n_train} training rows, not {train_shots}")
    shutil.copyfile(data, out)
    thin_training_rows(out, train_shots / n_train)
    return int(np.sum(read_shots(out).column("split") == "train"))


def run_point(run: Path, val: ValidationSet, world: Prediction) -> dict:
    """One run's best checkpoint on the validation shots: error against the records and against the world, as
    means and (under "per_shot", for the intervals) per validation shot."""
    evaluation = evaluate_run(run, val)
    errors = evaluation.errors
    against_world = evaluation.prediction.landing_m - world.landing_m
    per_shot = {"val_landing_m": errors.landing_m, "val_length_bias_m": errors.length_m,
                "form_landing_m": np.linalg.norm(against_world, axis=-1), "form_length_bias_m": against_world[:, 1]}
    return {
        "run": str(run), "variant": evaluation.variant, "seed": evaluation.config.seed,
        "n_train": json.loads((run / "history.json").read_text())["data"]["n_train"],
        "epochs": evaluation.epochs_trained, "batch_size": evaluation.config.batch_size,
        "best_epoch": evaluation.best_epoch, "train_seconds": evaluation.train_seconds,
        "val_side_bias_m": float(np.nanmean(errors.side_m)),
        **{key: float(np.nanmean(values)) for key, values in per_shot.items()}, "per_shot": per_shot,
    }


def _rank(variant: str) -> int:
    return ORDER.index(variant) if variant in ORDER else len(ORDER)


def session_interval(per_seed: list[np.ndarray], sessions: np.ndarray) -> list[float]:
    """The 95 % interval of the seeds' mean of a per-shot statistic, drawing whole sessions (shots of one session
    share their hidden weather and player, so they are not independent)."""
    return list(block_bootstrap(np.mean(np.stack(per_seed), axis=0), sessions))


def summarise(points: list[dict], sessions: np.ndarray) -> list[dict]:
    """Mean over seeds of each (variant, training shots), with the seeds' range and, for each per-shot statistic,
    its session-bootstrap interval (`sessions`: each validation shot's); in ORDER, then n order."""
    groups = defaultdict(list)
    for point in points:
        groups[point["variant"], point["n_train"]].append(point)
    rows = []
    for (variant, n_train), group in sorted(groups.items(), key=lambda item: (_rank(item[0][0]), item[0][1])):
        row = {"variant": variant, "n_train": n_train, "seeds": len(group), "epochs": group[0]["epochs"],
               "batch_size": group[0]["batch_size"], "best_epochs": [p["best_epoch"] for p in group]}
        for key in ("val_landing_m", "val_length_bias_m", "form_landing_m", "form_length_bias_m", "train_seconds"):
            values = [p[key] for p in group]
            row[key], row[f"{key}_range"] = float(np.mean(values)), [min(values), max(values)]
        for key in PER_SHOT:
            row[f"{key}_interval"] = session_interval([p["per_shot"][key] for p in group], sessions)
        rows.append(row)
    return rows


def _with_interval(row: dict, error: str, bias: str) -> str:
    """"error [low, high] (bias [low, high])", the bias signed."""
    (low, high), (bias_low, bias_high) = row[f"{error}_interval"], row[f"{bias}_interval"]
    return (f"{row[error]:.2f} [{low:.2f}, {high:.2f}] "
            f"({row[bias]:+.2f} [{bias_low:+.2f}, {bias_high:+.2f}])")


def _cells(row: dict) -> list[str]:
    val, form = row["val_landing_m_range"], row["form_landing_m_range"]
    spread = "–" if row["seeds"] == 1 else f"{val[0]:.2f}–{val[1]:.2f} / {form[0]:.2f}–{form[1]:.2f}"
    best = ", ".join(map(str, row["best_epochs"]))
    return [DISPLAY[row["variant"]], f"{row['n_train']:,}", f"{row['epochs']} × {row['batch_size']} ({best})",
            str(row["seeds"]), _with_interval(row, "val_landing_m", "val_length_bias_m"),
            _with_interval(row, "form_landing_m", "form_length_bias_m"), spread,
            f"{row['train_seconds'] / 60:.1f}"]


def figure(rows: list[dict], floor_m: float, path: Path) -> Path:
    """Validation error (with the nominal world's own error as the floor) and model-form error against n."""
    panels = []
    for key, label in (("val_landing_m", "validation landing error (m)"), ("form_landing_m", "model-form error (m)")):
        shots, errors, spans = {}, {}, {}
        for variant in dict.fromkeys(row["variant"] for row in rows):
            mine = [row for row in rows if row["variant"] == variant]
            shots[DISPLAY[variant]] = np.array([row["n_train"] for row in mine])
            errors[DISPLAY[variant]] = np.array([row[key] for row in mine])
            spans[DISPLAY[variant]] = np.array([row[f"{key}_range"] for row in mine])
        panels.append((label, shots, errors, spans))
    return learning_curves(panels, path, floors={0: ("the reference world itself (nominal floor)", floor_m)})


def report(data: Path, runs: list[Path], png: Path | None, results: Path | None) -> None:
    """Evaluate the runs, print the table and the nominal floor, and write the figure and results where asked."""
    val = load_validation(data)
    air, described = nominal_conditions(val)
    world = reference_prediction(val.shots, air)
    floor = errors_of(world, val)
    sessions = val.shots.column("session")
    floor_m, floor_bias = floor.mean_landing_m, float(np.nanmean(floor.length_m))
    interval = session_interval([floor.landing_m], sessions)
    bias_interval = session_interval([floor.length_m], sessions)
    rows = summarise([run_point(run, val, world) for run in runs], sessions)
    print(f"Validation: {len(val)} shots of `{data.name}` in {len(np.unique(sessions))} sessions.\n")
    print("\n".join(table(HEADERS, [_cells(row) for row in rows])))
    print(f"\nNominal floor (the reference world, {described}, against the records): {floor_m:.2f} m "
          f"[{interval[0]:.2f}, {interval[1]:.2f}] (bias {floor_bias:+.2f} "
          f"[{bias_interval[0]:+.2f}, {bias_interval[1]:+.2f}]).")
    if png:
        print(f"wrote {figure(rows, floor_m, png)}")
    if results:
        results.write_text(json.dumps({"validation_shots": len(val), "floor_m": floor_m, "floor_interval": interval,
                                       "floor_length_bias_m": floor_bias, "floor_length_bias_interval": bias_interval,
                                       "rows": rows}, indent=1) + "\n")
        print(f"wrote {results}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    make = commands.add_parser("subset", help="a copy of the file with fewer training shots, every validation shot")
    make.add_argument("--data", type=Path, required=True)
    make.add_argument("--train-shots", type=int, required=True)
    make.add_argument("--out", type=Path, required=True)
    show = commands.add_parser("report", help="the table (and the figure, the results file where asked)")
    show.add_argument("--data", type=Path, required=True, help="the full synthetic file (its validation rows)")
    show.add_argument("--png", type=Path, help="write the figure here")
    show.add_argument("--results", type=Path, help="write the numbers here as JSON")
    show.add_argument("runs", nargs="+", type=Path, help="run folders of `golfflight train`")
    args = parser.parse_args()
    if args.command == "subset":
        print(f"wrote {args.out}: {subset(args.data, args.train_shots, args.out)} training shots")
    else:
        report(args.data, args.runs, args.png, args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
