"""`golfflight evaluate`: Table 1 (every trained variant on the validation split), the noise floor, Figures 6 and 7."""

from __future__ import annotations

import argparse

from golfflight.commands import COMMANDS


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "evaluate",
        help=COMMANDS["evaluate"].summary,
        description="Evaluate each run's best checkpoint on the file's validation shots, compute the reference "
        "world's noise floor, write the table into OUT/training.md (generated section) and the figures into "
        "OUT/figures/.",
    )
    parser.add_argument("--data", required=True, help="canonical shot CSV with a split column (the runs' data)")
    parser.add_argument("--runs", required=True, nargs="+", help="run directories (their best.pt) or checkpoint files")
    parser.add_argument(
        "--bundle",
        help="the model bundle flown through NumPy + ONNX Runtime and compared with torch (default: the served "
        "default, `golfflight serve`'s lookup)",
    )
    parser.add_argument("--out", required=True, help="docs directory: OUT/training.md and OUT/figures/ are written")
    parser.add_argument("--quiet", action="store_true", help="no progress on standard error")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import torch

    from golfflight.flight.bundle_location import model_dir
    from golfflight.model_export.evaluate import run_evaluation

    torch.set_num_threads(2)
    report = run_evaluation(args.data, args.runs, args.out, bundle=model_dir(args.bundle), progress=not args.quiet)
    print(report.markdown, end="")
    for path in report.figures:
        print(f"wrote {path}")
    return 0
