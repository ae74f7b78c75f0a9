"""`golfflight accuracy`: the real-data model, the synthetic model and Ferguson 2022 side by side on the held-out
real sets (and the context around them), written into a docs page's generated section."""

from __future__ import annotations

import argparse
from pathlib import Path

from golfflight.commands import COMMANDS
from golfflight.errors import InputError
from golfflight.flight.bundle_location import CHECKOUT_MODEL

DEFAULT_SYNTHETIC = CHECKOUT_MODEL.parent / "synthetic"
"""The synthetic-data model of a source checkout (not shipped in the wheel)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "accuracy",
        help=COMMANDS["accuracy"].summary,
        description="Fly three models through the runtime path on the shared real data (read by path, never copied): "
        "the held-out TrackMan drivers (lines 2943 on), the TOUR Championship 2020 and the PGA 2023 averages; the "
        "paper's figures and slow shots for context; the Sentry 2022 trajectories with each shot's fitted wind; "
        "and a fine-tuning study on the Sony Open 2022 (rounds 1-2 tuned, 3-4 measured). Sets that are not found are "
        "skipped and said so.",
    )
    parser.add_argument("--model", help="the real-data model bundle (default: the served default, `golfflight serve`'s "
                        "lookup)")
    parser.add_argument("--synthetic", help="the synthetic-data model bundle (default: a source checkout's "
                        "models/synthetic where it exists, else the --model bundle again)")
    parser.add_argument("--out", default="docs/accuracy.md", help="markdown file whose generated section is replaced")
    parser.add_argument("--figures", help="directory for the path-error PNG (default: figures/ beside --out)")
    parser.add_argument("--data-dir", help="shared data folder (default: $GOLFFLIGHT_SHARED_DATA or ../shared/data)")
    parser.add_argument("--finetune-epochs", type=int, default=30, help="epochs of the fine-tuning study (0 skips it)")
    parser.add_argument("--variant", action="append", default=[], metavar="LABEL=RUN[,RUN...]",
                        help="compare trained variants instead (repeatable; docs/accuracy.md): a bundle or a "
                        "`train-real --variant nn` run folder a seed, the first the exported one; beside them "
                        "Ferguson 2022 published and --synthetic, on every held-out set and --validation's split, "
                        "written into --out's own generated section")
    parser.add_argument("--validation", help="with --variant: the merged training file (train-real's "
                        "WORK/real_flights.csv) whose validation split is compared too")
    parser.add_argument("--quiet", action="store_true", help="no progress on standard error")
    parser.set_defaults(run=run)


def _synthetic(args: argparse.Namespace) -> str | Path | None:
    """--synthetic, else a source checkout's models/synthetic where it exists, else the --model bundle again."""
    if args.synthetic is not None:
        return args.synthetic
    return DEFAULT_SYNTHETIC if (DEFAULT_SYNTHETIC / "model_card.json").is_file() else args.model


def run(args: argparse.Namespace) -> int:
    if args.variant:
        from golfflight.evaluation.variant_report import run_variant_comparison
        from golfflight.shots.paths import shared_data_dir

        print(run_variant_comparison(args.variant, _synthetic(args), args.data_dir or shared_data_dir(),
                                     args.validation, args.out), end="")
        print(f"wrote {args.out}")
        return 0
    from golfflight.evaluation.accuracy import run_accuracy

    if args.finetune_epochs < 0:
        raise InputError(f"--finetune-epochs must be 0 or more, got {args.finetune_epochs}")
    finetune = None
    if args.finetune_epochs:
        import torch

        from golfflight.model_export import finetune as training

        torch.set_num_threads(1)  # batches of 64 shots: a second thread only adds synchronisation
        finetune = training.finetune
    figures = args.figures or Path(args.out).parent / "figures"
    report = run_accuracy(args.model, args.out, figures, args.data_dir, args.finetune_epochs,
                          synthetic=_synthetic(args), finetune=finetune, progress=not args.quiet)
    print(report.markdown, end="")
    print(f"wrote {args.out}" + "".join(f", {path}" for path in report.figures))
    return 0
