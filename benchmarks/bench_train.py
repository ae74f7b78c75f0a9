"""An epoch of `golfflight train-real`'s joint run (`model_export.joint.train_joint_runs`) on a device, for 1 or
more seeds side by side (`--runs`, as `train-real --stack-seeds` trains them), eager and with the Euler step compiled
(`--compile`, as `train-real --compile`): its wall time (the second of two epochs; the first compiles), and the ATen
operations one eager epoch dispatches (forward rollouts, backward, optimizer steps, the epoch's validation). Each is
at least one kernel launch on a GPU, so their count times an operation's fixed cost on the device (timed here on tiny
tensors) bounds an eager epoch there from below, however fast the device computes: what issue 33's target (an epoch
10x faster than on 16 CPU cores) is up against, and what stacking seeds shares out. On a CPU `--jobs N` trains the
seeds in N processes at once, each stacking its share (`train-real --stack-seeds --jobs N`): a many-core machine's
way, and the baseline a GPU is to beat. With --results FILE, writes the section `train_epoch_<cpu|cuda>` there (a row
a device, process count, thread count, number of seeds and step; a rerun replaces its own) and prints them as a table
for docs/benchmarks.md.

The training file is built from the shared data (`model_export.real_data.build`, the held-out sets never read), or
given (`--data`: a lent machine has no shared data; carry the file there):
    python benchmarks/bench_train.py --device cpu --threads 1 --runs 1,4 --compile
    python benchmarks/bench_train.py --device cuda --data real_flights.csv --runs 1,16 --compile  # then, there,
    python benchmarks/bench_train.py --device cpu --data real_flights.csv --runs 16 --jobs 16 --threads 1  # baseline
"""

from __future__ import annotations

import argparse
import contextlib
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import torch
from common import REPO, add_results_flag, read_results, write_results
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.devices import resolve_device
from golfflight.model_export.joint import JointConfig, JointResult
from golfflight.model_export.real_data import build
from golfflight.model_export.real_training import DATA_FILE, SeedPlan, train_seeds
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


def train(data: Path, device: str, folder: Path, runs: int, epochs: int, compile_step: bool = False,
          jobs: int = 1, counter: OpCounter | None = None) -> list[JointResult]:
    """`epochs` epochs of `runs` seeds from the shipped bundle's network (under `counter` if given), as `train-real
    --stack-seeds --jobs JOBS` trains them (`real_training.train_seeds`): side by side in this process, or shared
    out over `jobs` processes, each stacking its share on this process's torch threads."""
    configs = {f"seed-{seed}": replace(JointConfig(), epochs=epochs, seed=seed) for seed in range(runs)}
    plan = SeedPlan(device, jobs, torch.get_num_threads(), stacked=True, compile_step=compile_step)
    plan.check()
    with counter or contextlib.nullcontext():
        return list(train_seeds(data, folder, model_dir(None), configs, plan, progress=False).values())


def measure(data: Path, device: str, folder: Path, runs: int, compile_step: bool, jobs: int = 1,
            count_ops: bool = True) -> dict:
    """An epoch's seconds: the second of two (the first compiles where `compile_step`; with `jobs` processes, the
    slowest process's second epoch, all of them training at once), and, eager in one process where `count_ops`, the
    operations one epoch dispatches (a third epoch, slower for the counting). Compiled runs start from an empty
    compile cache: torch.compile keeps its versions of the Euler step (`flight.rollout.step_rule`) by the function,
    so the runs' counts before would add up to its limit of eight (then it runs eager)."""
    if compile_step:
        torch._dynamo.reset()
    results = train(data, device, folder / "timed", runs, 2, compile_step, jobs)
    epoch_s = max(result.history[1]["seconds"] for result in results)
    row = {"runs": runs, "jobs": jobs, "compiled": compile_step, "epoch_s": epoch_s,
           "first_epoch_s": max(result.history[0]["seconds"] for result in results), "seed_share_s": epoch_s / runs,
           "selection_loss": results[0].history[1]["selection_loss"], "ops": None}
    if count_ops and not compile_step and jobs == 1:
        counter = OpCounter()
        train(data, device, folder / "counted", runs, 1, counter=counter)
        row["ops"] = counter.count
    return row


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
    parser.add_argument("--compile", action="store_true", help="each count eager and then compiled")
    parser.add_argument("--jobs", type=int, default=1,
                        help="processes training at once on a CPU, the seeds shared out over them (as train-real "
                        "--stack-seeds --jobs N; each with --threads torch threads; default 1)")
    parser.add_argument("--count-ops", action=argparse.BooleanOptionalAction, default=True,
                        help="count an eager epoch's operations in a third epoch (default; --no-count-ops saves its "
                        "time: the counts do not depend on the device)")
    add_results_flag(parser)
    args = parser.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    device = resolve_device(args.device)
    cost = op_cost_us(device)
    rows = []
    print("\n| device | processes | torch threads | seeds | step | epoch | a seed's share | first epoch | "
          "operations dispatched (an epoch) | their floor | felt error after epoch 2 (seed 0) |\n"
          "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as folder:
        data = args.data
        if data is None:
            if not DATA_ROOT.is_dir():
                raise SystemExit(f"no shared data at {DATA_ROOT}: give --data FILE")
            data = Path(folder) / DATA_FILE
            build(DATA_ROOT, data)
        for runs in (int(part) for part in args.runs.split(",")):
            for compiled in (False, True) if args.compile else (False,):
                row = {"device": str(device), "torch": torch.__version__, "torch_threads": torch.get_num_threads(),
                       "op_cost_us": cost, **measure(data, args.device, Path(folder) / f"{runs}-{compiled}", runs,
                                                    compiled, args.jobs, args.count_ops)}
                row["ops_floor_s"] = None if row["ops"] is None else row["ops"] * cost * 1e-6
                rows.append(row)
                ops = "—" if row["ops"] is None else f"{row['ops']:,}"
                floor = "—" if row["ops_floor_s"] is None else f"{row['ops_floor_s']:.1f} s"
                print(f"| {row['device']} | {args.jobs} | {row['torch_threads']} | {runs} | "
                      f"{'compiled' if compiled else 'eager'} | "
                      f"{row['epoch_s']:.1f} s | {row['seed_share_s']:.1f} s | {row['first_epoch_s']:.1f} s | {ops} | "
                      f"{floor} | {row['selection_loss']:.3f} m |", flush=True)
                write_rows(f"train_epoch_{device.type}", rows, args.results)
    print(f"\nan operation's fixed cost on {device}: {cost:.2f} µs")


def write_rows(section: str, rows: list[dict], path: Path | None) -> None:
    """The section of the results file with `rows` in it, in place of the rows that measured the same (written
    after each measurement: a run cut short keeps what it measured)."""
    kept = read_results(path).get(section, {}).get("rows", [])
    fresh = {_key(r) for r in rows}
    write_results(section, [*(r for r in kept if "compiled" in r and _key(r) not in fresh), *rows], path)


def _key(row: dict) -> tuple:
    """What a row measured: a rerun of the same replaces it in the results file."""
    return row["device"], row.get("jobs", 1), row["torch_threads"], row["runs"], row["compiled"]


if __name__ == "__main__":
    main()
