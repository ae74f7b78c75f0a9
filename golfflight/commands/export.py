"""`golfflight export`: write a model bundle (model.onnx + model_card.json) from a training checkpoint."""

from __future__ import annotations

import argparse

from golfflight.commands import COMMANDS


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("export", help=COMMANDS["export"].summary)
    parser.add_argument("--checkpoint", required=True, help="checkpoint file, or a run directory (its best.pt)")
    parser.add_argument("--out", required=True, help="bundle directory to write")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.model_export.export import export_checkpoint

    card = export_checkpoint(args.checkpoint, args.out)
    print(
        f"wrote {args.out}: {card.variant}, val landing error {card.validation.landing_error_m:.3f} m, "
        f"ONNX vs torch max |diff| {card.export_check.max_abs_coefficient_difference:.2g}"
    )
    return 0
