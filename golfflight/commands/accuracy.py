"""`golfflight accuracy`: a model bundle on the real data sets (PGA averages, outdoor driver shots, PGA TOUR
trajectories) and a fine-tuning study, written into a docs page's generated section."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "accuracy",
        help="evaluate a model bundle on the real data sets and write docs/accuracy.md",
        description="Fly a bundle through the runtime path on the shared real data (read by path, never copied): "
        "TrackMan's PGA 2023 averages per club, the outdoor TrackMan driver shots and the PGA TOUR trajectories; "
        "then fine-tune it on the first half of the driver shots and measure the second half. Sets that are not "
        "found are skipped and said so.",
    )
    parser.add_argument("--model", default="models/default", help="model bundle directory (default models/default)")
    parser.add_argument("--out", default="docs/accuracy.md", help="markdown file whose generated section is replaced")
    parser.add_argument("--figures", help="directory for the path-error PNG (default: figures/ beside --out)")
    parser.add_argument("--data-dir", help="shared data folder (default: $GOLFFLIGHT_SHARED_DATA or ../shared/data)")
    parser.add_argument("--finetune-epochs", type=int, default=30, help="epochs of the fine-tuning study (0 skips it)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from model_export.accuracy import run_accuracy

    if args.finetune_epochs < 0:
        raise ValueError(f"--finetune-epochs must be 0 or more, got {args.finetune_epochs}")
    if args.finetune_epochs:
        import torch

        torch.set_num_threads(1)  # batches of 64 shots: a second thread only adds synchronisation
    figures = args.figures or Path(args.out).parent / "figures"
    report = run_accuracy(args.model, args.out, figures, args.data_dir, args.finetune_epochs)
    print(report.markdown, end="")
    print(f"wrote {args.out}" + "".join(f", {path}" for path in report.figures))
    return 0
