"""`golfflight diagnose` and `golfflight prove`: find what the simulation leaves out, and prove the method works."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from golfflight.commands import COMMANDS
from golfflight.discovery.choices import CAMPAIGNS, CLEAN_SETS, REFERENCE, SHOTS, TRUTHS
from golfflight.errors import InputError
from golfflight.shots.progress import print_line, progress_step

QUIET_HELP = "no progress on standard error"
MIN_BASELINE_SHOTS = 30
"""A baseline session needs at least this many shots: the form has 19 weights and the discrepancy a process each."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("diagnose", help=COMMANDS["diagnose"].summary)
    parser.add_argument("recordings", help="canonical shot CSV (a NAME.trajectories.csv beside it is used)")
    parser.add_argument(
        "--model",
        help=f"model bundle directory, or '{REFERENCE}' for the reference world (default: the served default, "
        "`golfflight serve`'s lookup)",
    )
    parser.add_argument(
        "--baseline",
        metavar="BASELINE.csv",
        help="a session in known conditions (air recorded, or standard when blank; wind calm unless recorded) with the "
        "same launch monitor and ball: the model's form is learned from it and the recordings are explained as what "
        "changed since",
    )
    parser.add_argument("--out", required=True, help="folder for report.json, report.html, service_settings.json")
    parser.add_argument("--seed", type=int, default=0, help="seed of the fitting subsample and the bootstraps")
    parser.add_argument(
        "--reference-control",
        action="store_true",
        help="add the bundle's difference from the reference world on the recorded launches to every prediction: "
        "this measures how the recordings differ from the reference world (as seen through the bundle), not from "
        "the model the service flies (the default)",
    )
    parser.add_argument(
        "--assumed-noise",
        action="store_true",
        help="expect only the assumed launch-monitor noise, even where the recordings scatter more than that from "
        "shot to shot (by default their own scatter replaces it there)",
    )
    parser.add_argument("--quiet", action="store_true", help=QUIET_HELP)
    parser.set_defaults(run=run_diagnose)

    prove = subparsers.add_parser("prove", help=COMMANDS["prove"].summary)
    prove.add_argument(
        "--model", help=f"a bundle (default: the served default) or '{REFERENCE}' (the method alone)"
    )
    prove.add_argument(
        "--truth",
        choices=TRUTHS,
        default="model",
        help="hide the effects in the diagnosed model's own flights (default) or in a world whose form differs (the "
        "model-form campaign): the reference world's, Ferguson 2022's coefficients', or the model's own in recorded "
        "venue air that scales density only, flown as the service flies it or by RK4 at 0.01 s (density-only-rk4)",
    )
    prove.add_argument(
        "--campaign",
        choices=CAMPAIGNS,
        default="library",
        help="every library effect, the pair and the effects outside the library (default), two effects at once "
        "(pairs) or three (triples)",
    )
    prove.add_argument(
        "--baseline",
        action="store_true",
        help="the same as --campaign baseline: every set diagnosed against a clean baseline session of the same "
        "players and clubs",
    )
    prove.add_argument("--seeds", type=int, default=4, help="concealed sets per case")
    prove.add_argument("--clean-sets", type=int, default=CLEAN_SETS, help="clean sets (false-alarm count)")
    prove.add_argument("--shots", type=int, default=SHOTS, help="shots per concealed set")
    prove.add_argument("--out", default="docs/discovery.md", help="markdown file whose generated section is replaced")
    prove.add_argument("--json", help="also write every run's truth and findings to this JSON file")
    prove.add_argument(
        "--cases", help="only the cases whose name matches this regular expression (e.g. '^clean$' for false alarms)"
    )
    prove.add_argument("--tables-from", help="write the tables of the runs in this --json dump instead of flying")
    prove.add_argument("--quiet", action="store_true", help=QUIET_HELP)
    prove.set_defaults(run=run_prove)

    own = subparsers.add_parser(
        "own-error", help=COMMANDS["own-error"].summary
    )
    own.add_argument("bundle", help="model bundle directory")
    own.add_argument("--shots", type=int, default=2000, help="clean calm launches to fly")
    own.add_argument("--write", action="store_true", help="write it into the bundle's card (schema 1.3)")
    own.set_defaults(run=run_own_error)


def run_diagnose(args: argparse.Namespace) -> int:
    from golfflight.discovery.diagnose import diagnose
    from golfflight.discovery.form import learn_form
    from golfflight.discovery.html import PLOTS_MISSING, plots_available
    from golfflight.discovery.model import load_model
    from golfflight.discovery.outputs import write_diagnosis
    from golfflight.discovery.recordings import read_recordings

    recordings = read_recordings(args.recordings)
    if len(recordings) < 3:
        raise InputError(f"{args.recordings}: {len(recordings)} shots with an observed outcome; at least 3 are needed")
    model = load_model(args.model, control=args.reference_control)
    baseline = None
    if args.baseline is not None:
        session = read_recordings(args.baseline)
        if len(session) < MIN_BASELINE_SHOTS:
            raise InputError(
                f"--baseline {args.baseline}: {len(session)} shots with an observed outcome; at least "
                f"{MIN_BASELINE_SHOTS} are needed to learn the model's form from it"
            )
        baseline = learn_form(session, model, seed=args.seed, progress=not args.quiet)
    diagnosis = diagnose(
        recordings,
        model,
        seed=args.seed,
        estimate_scatter=not args.assumed_noise,
        progress=not args.quiet,
        baseline=baseline,
    )
    progress_step(f"writing the report to {args.out}...", not args.quiet)
    paths = write_diagnosis(diagnosis, args.out)
    print("\n".join(diagnosis.report.headline), end="\n\n")
    print(diagnosis.report.statement)
    print(f"wrote {', '.join(str(p) for p in paths)} ({diagnosis.report.seconds:.1f} s)")
    if not plots_available():
        print(f"report.html has no figures: {PLOTS_MISSING}")
    return 0


def run_prove(args: argparse.Namespace) -> int:
    from golfflight.discovery.model import load_model
    from golfflight.discovery.prove import cases, command, prove, read_runs, write_tables

    if args.cases is not None:
        try:
            re.compile(args.cases)
        except re.error as error:
            raise InputError(f"--cases {args.cases!r} is not a regular expression: {error}") from None
    model = load_model(args.model)
    if args.baseline:
        args.campaign = "baseline"
    if args.tables_from:
        results = read_runs(Path(args.tables_from))
    else:
        results = prove(
            model,
            args.seeds,
            args.shots,
            print_line,
            only=args.cases,
            truth=args.truth,
            clean_sets=args.clean_sets,
            progress=not args.quiet,
            campaign=args.campaign,
        )
    if not results:
        names = ", ".join(name for name, _ in cases(args.truth, args.campaign))
        raise InputError(f"--cases {args.cases!r} matches none of: {names}")
    spec = args.model or "models/default"
    section = command(spec, args.truth, args.cases, args.seeds, args.campaign, args.shots)
    json_path = Path(args.json) if args.json else None
    write_tables(results, Path(args.out), json_path, model.name, section, args.truth, args.campaign)
    print(f"wrote the tables to {args.out}")
    return 0


def run_own_error(args: argparse.Namespace) -> int:
    from golfflight.discovery.own_error import measure_own_error, write_own_error

    own = measure_own_error(args.bundle, args.shots)
    print(own.model_dump_json(indent=2))
    if args.write:
        print(f"wrote {write_own_error(args.bundle, own)}")
    return 0
