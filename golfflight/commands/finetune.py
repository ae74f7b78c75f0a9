"""`golfflight finetune`: adapt a trained model to your own canonical recordings and export a new bundle."""

from __future__ import annotations

import argparse

from golfflight.commands import COMMANDS
from golfflight.commands.train import COMPILE_HELP


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "finetune",
        help=COMMANDS["finetune"].summary,
        description="Start from the trained weights, train on the file's 'train' rows (or, without a split column, "
        "all but the most recent --val-fraction of the shots), keep the epoch with the lowest validation landing "
        "error, and export it to OUT if it beats the starting model there. The training run stays in a subdirectory "
        "of OUT.",
    )
    parser.add_argument("--model", required=True, help="model bundle directory, run directory or checkpoint file")
    parser.add_argument("--data", required=True, help="your canonical shot CSV")
    parser.add_argument("--epochs", type=int, default=30)
    parser.add_argument("--out", required=True, help="bundle directory to write")
    parser.add_argument(
        "--lr", type=float, default=3e-4, help="Adam learning rate (a third of training's: few shots overfit fast)"
    )
    parser.add_argument("--batch-size", type=int, default=64)
    parser.add_argument(
        "--val-fraction",
        type=float,
        default=0.2,
        help="share of the most recent shots (whole sessions) held out when the file has no split",
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--device", default="cpu", help="where to train: cpu (default) or cuda[:N]")
    parser.add_argument("--compile", action="store_true", help=COMPILE_HELP)
    parser.add_argument(
        "--quiet", action="store_true", help="no progress on standard error and no line per epoch on standard output"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import torch

    from golfflight.model_export.finetune import RUN_DIR, finetune

    torch.set_num_threads(1)  # fine-tuning batches are small: a second thread only adds synchronisation
    result = finetune(
        args.model,
        args.data,
        args.out,
        args.epochs,
        args.lr,
        args.batch_size,
        args.val_fraction,
        args.seed,
        progress=not args.quiet,
        device=args.device,
        compile_step=args.compile,
    )
    data, base = result.run.data, result.base_metrics
    print(f"data: {data.n_train} train, {data.n_val} val shots; left out {data.filters}")
    print(f"before: val landing error {base['landing_error_m']:.3f} m ({base['landing_error_yd']:.3f} yd)")
    best = result.run.best
    if best is not None:
        print(
            f"best epoch {best['epoch']}: val landing error {best['landing_error_m']:.3f} m "
            f"({best['landing_error_yd']:.3f} yd)"
        )
    if not result.improved:
        print(
            f"no epoch beat the starting model on the validation shots: {args.out} not written "
            f"(the run is in {args.out}/{RUN_DIR})"
        )
        return 1
    print(f"wrote {args.out}")
    return 0
