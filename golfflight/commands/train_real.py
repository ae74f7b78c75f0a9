"""`golfflight train-real`: Phys-NN+ (or the paper's baselines, Phys-Q and NN) trained on real flights with the
unrecorded conditions as latent parameters (thin layer over model_export.real_training)."""

from __future__ import annotations

import argparse

from golfflight.commands import COMMANDS
from golfflight.commands.train import COMPILE_HELP
from golfflight.model_export.real_sources import DEFAULT_SOURCES, SOURCES


def _seeds(text: str) -> tuple[int, ...]:
    try:
        seeds = tuple(int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"seeds must be comma-separated integers like 0,1,2, not {text!r}") from None
    return seeds


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "train-real",
        help=COMMANDS["train-real"].summary,
        description="Build WORK/real_flights.csv from every usable real source (docs/training_real.md), fine-tune "
        "the --init bundle on it jointly with a wind per conditions group, an air factor per air group and a scale "
        "per ball type, once per seed, average the seeds' weights into a soup, and export the run (a seed or the "
        "soup) with the lowest validation felt error (per source the carry MAE plus its absolute bias, averaged) to --out.",
    )
    parser.add_argument("--work", required=True, help="directory for the merged data and each seed's run")
    parser.add_argument("--out", help="bundle directory to export the chosen run to")
    parser.add_argument("--variant", default="phys-nn+", choices=("phys-nn+", "phys-q", "nn"),
                        help="what to train (docs/training_real.md): phys-nn+ (default, the served model), "
                        "phys-q (C_L, C_D quadratic in the spin ratio, C_M = p*S, refitted from Ferguson 2022's "
                        "coefficients) or nn (launch -> landing point, evaluated only: never exported or served)")
    parser.add_argument("--init", default=None, help="bundle to start from (default: models/synthetic for phys-nn+; "
                        "Ferguson 2022's coefficients for phys-q; nn starts fresh and takes none)")
    parser.add_argument("--data-root", default=None, help="shared data folder (default ../shared/data)")
    parser.add_argument("--sources", default=",".join(DEFAULT_SOURCES),
                        help=f"comma-separated subset of {list(SOURCES)} (default: {','.join(DEFAULT_SOURCES)})")
    parser.add_argument("--epochs", type=int, default=14)
    parser.add_argument("--seeds", type=_seeds, default=(0, 1, 2))
    parser.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate of the network")
    parser.add_argument("--threads", type=int, default=2, help="torch CPU threads per seed")
    parser.add_argument("--jobs", type=int, default=1, help="processes training seeds at once: a seed each, or with "
                        "--stack-seeds a share of the seeds each")
    parser.add_argument("--device", default="cpu", help="where to train: cpu (default) or cuda[:N] (with --jobs 1)")
    parser.add_argument("--stack-seeds", action="store_true",
                        help="train the seeds side by side in one rollout (each with its own minibatches, moments and "
                        "clipping: the same runs up to float rounding), for about one seed's kernel launches on a GPU; "
                        "with --jobs N, the seeds shared out over N processes, each stacking its share")
    parser.add_argument("--compile", action="store_true", help=COMPILE_HELP)
    parser.add_argument("--train-fraction", type=float, default=1.0,
                        help="train on this fraction (above 0, at most 1) of each source's training shots, the same "
                        "shots for every variant and seed; validation unchanged (the learning curve, docs/accuracy.md)")
    parser.add_argument(
        "--quiet", action="store_true", help="no progress on standard error and no line per epoch on standard output"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.model_export.real_variants import NN_NOT_SERVED, start_of

    if args.variant == "nn" and args.out:
        raise SystemExit(f"golfflight train-real: {NN_NOT_SERVED}")
    from golfflight.model_export.joint import JointConfig
    from golfflight.model_export.real_data import BUILDERS
    from golfflight.model_export.real_training import SeedPlan, train_real
    from golfflight.shots.paths import shared_data_dir

    names = tuple(n.strip() for n in args.sources.split(","))
    unknown = [n for n in names if n not in BUILDERS]
    if unknown:
        raise SystemExit(f"golfflight train-real: --sources: unknown {unknown}; choose from {list(BUILDERS)}")
    if args.epochs < 1:
        raise SystemExit(f"golfflight train-real: --epochs must be at least 1, got {args.epochs}")
    start = start_of(args.variant, args.init)
    result = train_real(args.data_root or shared_data_dir(), args.work, start,
                        JointConfig(epochs=args.epochs, lr=args.lr), args.seeds, args.out, names,
                        progress=not args.quiet, plan=SeedPlan(args.device, args.jobs, args.threads,
                                                               args.stack_seeds, args.compile),
                        train_fraction=args.train_fraction)
    for data in result.sources:
        print(f"{data.name}: {len(data.records)} shots ({data.kind})")
    for name, run_result in result.runs.items():
        final = run_result.final
        print(f"{name}: epoch {final['epoch']}, validation felt error {final['val_loss']:.2f} m" if final
              else f"{name}: no epoch finished")
    print(f"chosen {result.chosen}; {result.seconds / 60:.1f} min")
    if result.card is not None:
        print(f"exported {args.out} (validation landing error {result.card.validation.landing_error_yd:.2f} yd)")
    return 0
