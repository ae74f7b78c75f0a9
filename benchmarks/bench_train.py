"""One epoch of `golfflight train-real`'s joint run (`model_export.joint.train_joint_runs`) on a device, for 1 or
more seeds side by side (`--runs`, as `train-real --stack-seeds` trains them): its wall time, and the ATen operations
it dispatches (forward rollouts, backward, optimizer steps, the epoch's validation). Each is at least one kernel
launch on a GPU, so their count times an operation's fixed cost on the device (timed here on tiny tensors) bounds an
eager epoch there from below, however fast the device computes: what issue 33's target (an epoch 10x faster than on
16 CPU cores) is up against, and what stacking seeds shares out. Writes a row of the section `train_epoch_<cpu|cuda>`
of benchmarks/results.json (one a device, thread count and number of runs) and prints it as a table row for
docs/benchmarks.md.

The training file is built from the shared data (`model_export.real_data.build`, the held-out sets never read), or
given (`--data`: a lent machine has no shared data; carry the file there):
    python benchmarks/bench_train.py --device cpu --threads 1 --runs 1,4
    python benchmarks/bench_train.py --device cuda --data real_flights.csv --runs 1,16  # then --device cpu
                                                                  # --threads 16 there: the baseline, same machine
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import torch
from common import REPO, RESULTS, write_results
from golfflight.flight.bundle_location import model_dir
from golfflight.model_export.bundle_model import model_from_bundle
from golfflight.model_export.devices import resolve_device
from golfflight.model_export.joint import JointConfig, JointResult, train_joint_runs
from golfflight.model_export.real_data import build
from golfflight.model_export.real_training import DATA_FILE
from torch.utils._python_dispatch import TorchDispatchMode

DATA_ROOT = REPO.parent / "shared" / "data"
UNCOUNTED = ("view", "detach", "alias", "empty", "as_strided")
"""Operations that move no data and launch no kernel (metadata only)."""
OP_LOOP = 20_000
"""Tiny additions timed for an operation's fixed cost on the device."""


class OpCounter(TorchDispatchMode):
    """Counts the ATen operations dispatched while it is active (those of UNCOUNTED aside)."""

    def __init__(self) -> None:
        super().__init__()
        self.count = 0

    def __torch_dispatch__(self, func, types, args=(), kwargs=None):
        if not any(word in func.__name__ for word in UNCOUNTED):
            self.count += 1
        return func(*args, **(kwargs or {}))


def epoch(data: Path, device: str, folder: Path, runs: int, counter: OpCounter | None = None
          ) -> tuple[float, list[JointResult]]:
    """Wall seconds of one epoch of `runs` seeds side by side from the shipped bundle's network (under `counter` if
    given), and their results."""
    model, _ = model_from_bundle(model_dir(None))
    model.train()
    configs = [replace(JointConfig(), epochs=1, seed=seed) for seed in range(runs)]
    folders = [folder / f"seed-{seed}" for seed in range(runs)]
    started = time.perf_counter()
    if counter is None:
        results = train_joint_runs(data, folders, configs, model, False, device)
    else:
        with counter:
            results = train_joint_runs(data, folders, configs, model, False, device)
    return time.perf_counter() - started, results


def op_cost_us(device: torch.device) -> float:
    """Microseconds an operation costs on `device` whatever it computes: OP_LOOP additions of 64 numbers."""
    x = torch.zeros(64, device=device)
    for _ in range(100):
        x = x + 1.0
    if device.type == "cuda":
        torch.cuda.synchronize(device)
    started = time.perf_counter()
    for _ in range(OP_LOOP):
        x = x + 1.0
    if device.type == "cuda":
        torch.cuda.synchronize(device)
    return (time.perf_counter() - started) / OP_LOOP * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    parser.add_argument("--data", type=Path, help=f"the training file (default: built from {DATA_ROOT})")
    parser.add_argument("--threads", type=int, help="torch CPU threads (default: torch's)")
    parser.add_argument("--runs", default="1", help="seeds side by side, comma-separated counts (default 1)")
    args = parser.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    device = resolve_device(args.device)
    cost = op_cost_us(device)
    rows = []
    print("\n| device | torch threads | seeds side by side | epoch | a seed's share | operations dispatched | "
          "an operation's fixed cost | their floor | felt error after it (seed 0) |\n"
          "|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as folder:
        data = args.data
        if data is None:
            if not DATA_ROOT.is_dir():
                raise SystemExit(f"no shared data at {DATA_ROOT}: give --data FILE")
            data = Path(folder) / DATA_FILE
            build(DATA_ROOT, data)
        for runs in (int(part) for part in args.runs.split(",")):
            seconds, results = epoch(data, args.device, Path(folder) / f"timed-{runs}", runs)
            counter = OpCounter()
            epoch(data, args.device, Path(folder) / f"counted-{runs}", runs, counter)
            first = results[0].history[0]
            row = {"device": str(device), "torch": torch.__version__, "torch_threads": torch.get_num_threads(),
                   "runs": runs, "epoch_s": seconds, "seed_share_s": seconds / runs,
                   "epoch_history_s": first["seconds"], "ops": counter.count, "op_cost_us": cost,
                   "ops_floor_s": counter.count * cost * 1e-6, "val_loss": first["val_loss"],
                   "selection_loss": first["selection_loss"],
                   "selection_losses": [r.history[0]["selection_loss"] for r in results]}
            rows.append(row)
            print(f"| {row['device']} | {row['torch_threads']} | {runs} | {seconds:.1f} s | {seconds / runs:.1f} s | "
                  f"{counter.count:,} | {cost:.2f} µs | {row['ops_floor_s']:.1f} s | {row['selection_loss']:.2f} m |",
                  flush=True)
    section = f"train_epoch_{device.type}"
    kept = json.loads(RESULTS.read_text()).get(section, {}).get("rows", []) if RESULTS.is_file() else []
    key = lambda r: (r["device"], r["torch_threads"], r.get("runs", 1))
    fresh = {key(r) for r in rows}
    write_results(section, [*(r for r in kept if key(r) not in fresh), *rows])


if __name__ == "__main__":
    main()
