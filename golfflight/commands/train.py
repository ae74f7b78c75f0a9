"""`golfflight train`: train a model variant on a canonical shot CSV (thin layer over model_export.training)."""

from __future__ import annotations

import argparse

from golfflight.commands import COMMANDS
from golfflight.model_export import DEFAULT_HIDDEN, VARIANTS

COMPILE_HELP = ("fuse each Euler step's kernels, forward and backward, with torch.compile (compiled once a run, in "
                "seconds to a minute; on a CPU it needs a C compiler)")
"""`--compile` of the commands that train (`train`, `train-real`, `finetune`)."""


def _hidden(text: str) -> tuple[int, ...]:
    try:
        units = tuple(int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"hidden units must be comma-separated integers like 256,128, not {text!r}"
        ) from None
    if not units or min(units) < 1:
        raise argparse.ArgumentTypeError(f"hidden units must be positive, not {text!r}")
    return units


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("train", help=COMMANDS["train"].summary)
    parser.add_argument("--data", required=True, help="canonical shot CSV with a split column (train/val)")
    parser.add_argument("--variant", default="phys-nn+", choices=VARIANTS, help="model variant (default phys-nn+)")
    parser.add_argument("--epochs", type=int, default=50, help="total epochs (with --resume: up to this many)")
    parser.add_argument(
        "--out", required=True, help="run directory for checkpoints (last.pt, best.pt) and history.json"
    )
    parser.add_argument(
        "--hidden", type=_hidden, default=DEFAULT_HIDDEN, help="hidden units per layer (default 256,128)"
    )
    parser.add_argument("--batch-size", type=int, default=1024)
    parser.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate")
    parser.add_argument(
        "--loss", choices=("lp", "lp+lh"), help="landing loss, or landing + max-height loss (default lp+lh; lp for nn)"
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--limit", type=int, help="use at most this many shots (quick runs)")
    parser.add_argument("--resume", action="store_true", help="continue from OUT/last.pt")
    parser.add_argument(
        "--skip-bad-rows",
        action="store_true",
        help="leave out malformed rows of --data (each listed) instead of refusing the file",
    )
    parser.add_argument("--threads", type=int, default=2, help="torch CPU threads (1 is faster on a busy machine)")
    parser.add_argument("--device", default="cpu", help="where to train: cpu (default) or cuda[:N]")
    parser.add_argument("--compile", action="store_true", help=COMPILE_HELP)
    parser.add_argument(
        "--quiet", action="store_true", help="no progress on standard error and no line per epoch on standard output"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import torch

    from golfflight.model_export.training import TrainConfig, train

    torch.set_num_threads(args.threads)
    config = TrainConfig(
        variant=args.variant,
        hidden=args.hidden,
        epochs=args.epochs,
        batch_size=args.batch_size,
        lr=args.lr,
        loss=args.loss or ("lp" if args.variant == "nn" else "lp+lh"),
        seed=args.seed,
        limit=args.limit,
    )
    result = train(
        args.data, args.out, config, resume=args.resume, progress=not args.quiet, skip_bad_rows=args.skip_bad_rows,
        device=args.device, compile_step=args.compile,
    )
    data = result.data
    for problem in data.bad_rows:
        print(f"skipped bad row: {problem}")
    print(f"data: {data.n_train} train, {data.n_val} val shots; left out {data.filters}")
    if result.skipped_batches:
        print(f"skipped {result.skipped_batches} batches with a non-finite loss or gradient")
    if result.best:
        best = result.best
        error_m, error_yd = best["landing_error_m"], best["landing_error_yd"]
        print(f"best epoch {best['epoch']}: val landing error {error_m:.3f} m ({error_yd:.3f} yd)")
    print(f"checkpoints in {result.out_dir}")
    return 0
