"""`golfflight synth`: write realistic synthetic launch-monitor sessions in the canonical format."""

from __future__ import annotations

import argparse

from golfflight.commands import COMMANDS
from golfflight.errors import InputError
from golfflight.shots.progress import progress_step


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("synth", help=COMMANDS["synth"].summary)
    parser.add_argument("--shots", type=int, default=90_000, help="number of shots to draw (before the paper's filters)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", required=True, help="canonical CSV to write (the hidden truth goes beside it)")
    parser.add_argument("--robot-share", type=float, default=0.3, help="fraction of sessions hit by a robot")
    parser.add_argument("--val-fraction", type=float, default=0.1, help="share of shots, most recent sessions, marked val")
    parser.add_argument("--calm", action="store_true", help="no wind in any session")
    parser.add_argument("--quiet", action="store_true", help="no progress on standard error")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from golfflight.shots.synth import SynthConfig, generate, sessions_path, write_synthetic

    if args.shots < 1:
        raise InputError(f"--shots must be at least 1, got {args.shots}")
    config = SynthConfig(n_shots=args.shots, seed=args.seed, robot_share=args.robot_share,
                         val_fraction=args.val_fraction, calm=args.calm)
    synthetic = generate(config, progress=not args.quiet)
    progress_step(f"writing {args.out}...", not args.quiet)
    write_synthetic(args.out, synthetic)
    n_val = sum(r.split == "val" for r in synthetic.records)
    print(f"wrote {len(synthetic.records)} shots in {len(synthetic.sessions)} sessions to {args.out} "
          f"({n_val} marked val) in {synthetic.seconds:.1f} s; hidden truth in {sessions_path(args.out)}")
    for reason, count in synthetic.dropped.items():
        print(f"  dropped {count}: {reason}")
    return 0
