"""Choose the real-data training's loss weights on the validation split: one joint run per (weights, seed) from the
same start on the same merged file, all in parallel, and a table of each run's validation error per source (carry or
apex MAE and bias, and the felt error the runs are compared on, `model_export.joint.selection_loss`). Held-out data
is never read: the merged file comes from `model_export.real_data.build`, which refuses held-out rows.

    python3 scripts/train_real_weights.py --work build/weights --init models/synthetic --jobs 12 \\
        --grid 'pga-2023-table=5,20,80' --grid 'trackman-model=0.1,0.5' --seeds 0

Writes WORK/weights.json (every run's final validation metrics) and prints the table; the best weights (lowest
felt error, mean over seeds) come first. With `--stack-seeds` each weight set's seeds train side by side in one
process (`model_export.stacked_runs`: the same runs up to float rounding), a process a weight set.
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from golfflight.model_export.joint import JointConfig, felt_error_m
from golfflight.model_export.real_data import DEFAULT_SOURCES, build
from golfflight.model_export.real_training import DATA_FILE, train_seed, train_stacked
from golfflight.shots.markdown import table
from golfflight.shots.paths import shared_data_dir


def parse_grid(items: list[str]) -> dict[str, list[float]]:
    """'source=1,2,3' items -> {source: [1, 2, 3]}."""
    grid = {}
    for item in items:
        source, _, values = item.partition("=")
        grid[source.strip()] = [float(v) for v in values.split(",")]
    return grid


def weight_sets(base: dict[str, float], grid: dict[str, list[float]]) -> list[dict[str, float]]:
    """Every combination of the grid's values over the base weights."""
    names = list(grid)
    return [{**base, **dict(zip(names, values))} for values in itertools.product(*(grid[n] for n in names))]


def label(weights: dict[str, float], grid: dict[str, list[float]]) -> str:
    return ", ".join(f"{name} {weights[name]:g}" for name in grid)


def run_one(data_file: Path, run_dir: Path, init: str, config: JointConfig) -> dict:
    result = train_seed(data_file, run_dir, init, config, threads=1, progress=False)
    return {"dir": str(run_dir), "weights": config.weights, "seed": config.seed, **(result.final or {})}


def run_stacked(data_file: Path, work: Path, init: str, configs: dict[str, JointConfig]) -> list[dict]:
    """One weight set's seeds (WORK/NAME) side by side in this process (one torch thread)."""
    results = train_stacked(data_file, work, init, configs, threads=1, progress=False)
    return [{"dir": str(r.out_dir), "weights": configs[name].weights, "seed": configs[name].seed, **(r.final or {})}
            for name, r in results.items()]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--init", default="models/synthetic")
    parser.add_argument("--data", type=Path, default=shared_data_dir())
    parser.add_argument("--merged", type=Path, default=None,
                        help="an already built merged file (`golfflight train-real` writes WORK/real_flights.csv) "
                             "instead of building one from --data")
    parser.add_argument("--grid", action="append", default=[], help="SOURCE=W1,W2,... (repeatable)")
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--epochs", type=int, default=20)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--stack-seeds", action="store_true",
                        help="each weight set's seeds side by side, a process each")
    args = parser.parse_args()
    started = time.perf_counter()
    args.work.mkdir(parents=True, exist_ok=True)
    data_file = args.merged or args.work / DATA_FILE
    if args.merged is None:
        build(args.data, data_file, DEFAULT_SOURCES)
    grid = parse_grid(args.grid)
    base = JointConfig(epochs=args.epochs, lr=1e-3)
    configs = [replace(base, weights=w, seed=int(s)) for w in weight_sets(base.weights, grid)
               for s in args.seeds.split(",")]
    dirs = [args.work / f"run-{i}" for i in range(len(configs))]
    with ProcessPoolExecutor(args.jobs) as pool:
        if args.stack_seeds:
            sets: dict[str, list[int]] = {}
            for i, c in enumerate(configs):
                sets.setdefault(label(c.weights, grid), []).append(i)
            futures = [pool.submit(run_stacked, data_file, args.work, args.init,
                                   {dirs[i].name: configs[i] for i in runs}) for runs in sets.values()]
            runs = [run for f in futures for run in f.result()]
        else:
            futures = [pool.submit(run_one, data_file, d, args.init, c) for d, c in zip(dirs, configs)]
            runs = [f.result() for f in futures]
    (args.work / "weights.json").write_text(json.dumps({"grid": grid, "runs": runs}, indent=2) + "\n")
    sources = [s for s in base.select_on if any(s in r.get("val", {}) for r in runs)]
    by_weights: dict[str, list[dict]] = {}
    for r in runs:
        by_weights.setdefault(label(r["weights"], grid), []).append(r)
    rows = []
    for name, group in sorted(by_weights.items(), key=lambda kv: sum(r["val_loss"] for r in kv[1]) / len(kv[1])):
        felt = sum(r["val_loss"] for r in group) / len(group)
        cells = []
        for s in sources:
            values = [felt_error_m(r["val"][s]) for r in group if s in r["val"]]
            cells.append(f"{sum(values) / len(values):.2f}")
        rows.append([name, ",".join(str(r["seed"]) for r in group), f"{felt:.2f}", *cells])
    print("\n".join(table(["weights", "seeds", "felt error (m), mean of sources", *sources], rows)))
    print("\nPer run: carry (apex where a source has no carry) MAE / bias, m\n")
    detail = []
    for r in sorted(runs, key=lambda r: r["val_loss"]):
        cells = []
        for s in sources:
            row = r["val"].get(s, {})
            key = "carry_y_m" if "carry_y_m_mae" in row else "apex_m"
            cells.append(f"{row[key + '_mae']:.2f} / {row[key + '_bias']:+.2f}" if row else "—")
        detail.append([label(r["weights"], grid), str(r["seed"]), f"{r['val_loss']:.2f}", *cells])
    print("\n".join(table(["weights", "seed", "felt error (m)", *sources], detail)))
    print(f"\n{len(runs)} runs, {(time.perf_counter() - started) / 60:.1f} min")
    return 0


if __name__ == "__main__":
    sys.exit(main())
