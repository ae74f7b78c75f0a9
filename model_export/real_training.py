"""`golfflight train-real` end to end: build the merged real-flight file, train jointly from a starting bundle over
several seeds, keep the run with the lowest validation felt error (`joint.selection_loss`), and export it as a
bundle whose card names every source with its SHA-256 and rows, the latent conditions and the held-out errors.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.constants import YARD_M
from golfflight.flight.devices import DEFAULT_DEVICE, resolve_device
from golfflight.model_export.export import export_bundle
from golfflight.model_export.joint import JointConfig, JointResult, soup_runs, train_joint, train_joint_runs
from golfflight.model_export.observations import NOISE, OBSERVABLES, PATH_OBSERVATIONS, PATH_SIGMA_M
from golfflight.model_export.real_data import SourceData, build
from golfflight.model_export.real_variants import NN_NOT_SERVED, Start
from golfflight.model_export.training import TrainConfig, load_checkpoint
from golfflight.shots.progress import progress_bar, progress_step
from golfflight.shots.records import read_shots
from golfflight.weights_schema.bundle import sha256_of
from golfflight.weights_schema.model_card import ModelCard

if TYPE_CHECKING:
    from torch import nn

DATA_FILE = "real_flights.csv"
CONDITIONS_FILE = "training_conditions.json"
"""The fitted latent conditions of the exported run, beside the bundle's card (read by `golfflight accuracy`)."""
MEASURED_SOURCES = ("trackman-outdoor", "sentry-2022", "players-2020", "tour-championship-2020")
SOUP = "soup"
"""The run name (and WORK folder) of the seeds' weight average."""


@dataclass
class RealRun:
    """What a `train_real` call leaves: the merged data, each run by name (seed-S, and the soup of the seeds when
    there are several), the chosen run and the card."""

    data_file: Path
    sources: list[SourceData]
    runs: dict[str, JointResult]
    chosen: str
    card: ModelCard | None
    seconds: float


def loss_description(config: JointConfig) -> str:
    """The card's account of the loss, with the noise figures."""
    return (
        f"sum over each recorded observable of Huber_{config.huber_delta:g}(residual / sigma), sigma = the radar "
        f"noise: landing point {NOISE.carry_m:g} m + {NOISE.carry_fraction:.1%} of the carry per axis, apex "
        f"{NOISE.apex_m:g} m, flight time {NOISE.flight_time_s:g} s, landing angle {NOISE.landing_angle_deg:g} deg; "
        f"plus path positions every 0.5 s up to the radar's last point (3-D distance / {PATH_SIGMA_M:g} m, a path "
        f"counting as {PATH_OBSERVATIONS:g} observations); weighted per source {config.weights}; landing = the Euler "
        "states interpolated to r_z = 0 at the first downward crossing, apex = the vertex of the parabola through the "
        "highest state and its neighbours: measured as the runtime measures them"
    )


def latent_description(config: JointConfig, conditions: dict[str, Any]) -> str:
    return (
        f"fitted beside the network with Gaussian priors: a uniform wind per conditions group "
        f"({len(conditions['wind'])} groups, prior sd {config.wind_prior_mps:g} m/s per component), an air-density "
        f"factor per air group ({len(conditions['air'])}, prior sd {config.density_prior:g} in log), lift and drag "
        f"scales per non-Premium ball type ({len(conditions['ball'])}, prior sd {config.ball_prior:g} in log); each "
        f"source's mean log density held within {config.mean_density_prior:g} of its stated air, or within "
        f"{config.unknown_mean_density_prior:g} for the sources that recorded none ({', '.join(config.unknown_air_sources)}), "
        f"so the sources with known air set the level; served shots are flown without them (calm, the air given). "
        f"Values: {CONDITIONS_FILE}"
    )


def _data_summary(path: Path, sources: list[SourceData]) -> dict[str, Any]:
    shots = read_shots(path)
    split = shots.column("split")
    density = shots.air().density_kg_m3
    return {
        "file": path.name,
        "sha256": sha256_of(path),
        "n_rows": len(shots),
        "n_train": int(np.sum(split == "train")),
        "n_val": int(np.sum(split == "val")),
        "n_landing_targets": int(np.sum(~np.isnan(shots.column("carry_y_m")))),
        "n_apex_targets": int(np.sum(~np.isnan(shots.column("apex_m")))),
        "density_min_kg_m3": float(np.min(density)),
        "density_max_kg_m3": float(np.max(density)),
        "n_with_wind": 0,
        "min_apex_m": 0.0,
        "filters": {},
    }


def source_cards(sources: list[SourceData], weights: dict[str, float], paths: dict[str, int]) -> list[dict]:
    """The card's `training_data.sources` entries."""
    cards = []
    for data in sources:
        observed = [o for o in OBSERVABLES if any(getattr(r, o) is not None for r in data.records)]
        if paths.get(data.name):
            observed.append("path positions")
        cards.append({
            "name": data.name, "kind": data.kind,
            "files": [{"path": p, "sha256": h} for p, h in data.files.items()],
            "n_rows": len(data.records),
            "n_train": sum(r.split == "train" for r in data.records),
            "n_val": sum(r.split == "val" for r in data.records),
            "weight": weights[data.name], "observables": observed,
            "note": data.report.splitlines()[0].split(": ", 1)[-1] if data.report else "",
        })
    return cards


def _validation_metrics(final: dict[str, Any]) -> dict[str, Any]:
    """Landing and max-height error over the measured sources' validation shots (shot-weighted)."""
    rows = [final["val"][s] for s in MEASURED_SOURCES if s in final["val"]]
    landing = [(r["landing_error_m"], r["n_shots"]) for r in rows if "landing_error_m" in r]
    apex = [(r["apex_m_mae"], r["n_shots"]) for r in rows if "apex_m_mae" in r]

    def mean(pairs: list[tuple[float, int]]) -> float:
        return sum(v * n for v, n in pairs) / sum(n for _, n in pairs)

    landing_m, apex_m = mean(landing), mean(apex)
    return {"epoch": final["epoch"], "landing_error_m": landing_m, "landing_error_yd": landing_m / YARD_M,
            "max_height_error_m": apex_m, "max_height_error_yd": apex_m / YARD_M,
            "n_shots": sum(r["n_shots"] for r in rows)}


def export_real(run_dir: Path, data_file: Path, sources: list[SourceData], out: Path, variant: str,
                hidden: tuple[int, ...]) -> ModelCard:
    """Export a joint run's final epoch with a card that records its sources and latent conditions."""
    from golfflight.model_export.variants import build_model

    payload = load_checkpoint(run_dir / "last.pt")
    config = JointConfig(**payload["config"])
    model = build_model(variant, hidden)
    model.load_state_dict(payload["model"])
    model.eval()
    history = json.loads((run_dir / "history.json").read_text())
    metrics = _validation_metrics(history["final"])
    soup_of = history["epochs"][-1].get("soup_of")
    which = f"the weight average (soup) of {len(soup_of)} seeds' last epochs" if soup_of else \
        "the last epoch of the chosen seed"
    conditions = json.loads((run_dir / "conditions.json").read_text())
    data = _data_summary(data_file, sources)
    data["n_val"] = metrics.pop("n_shots")
    paths = {s.name: len(s.trajectories) for s in sources}
    train_config = TrainConfig(variant=variant, hidden=hidden, epochs=payload["epoch"], batch_size=config.batch_size,
                               lr=config.lr, loss="observables", seed=config.seed,
                               grad_clip_norm=config.grad_clip_norm, min_apex_m=0.0, dt_s=config.dt_s,
                               t_sim_s=config.t_sim_s)
    card = export_bundle(model, {
        "config": train_config.as_dict(), "epoch": payload["epoch"], "metrics": metrics,
        "data": {**data, "sources": source_cards(sources, config.weights, paths)},
        "split": "validation by conditions group, never a random shuffle: every 4th driver-range block in file "
                 "order, the Sentry's last round, every 4th hole of THE PLAYERS (one round) and of the TOUR "
                 "Championship's rounds 1-2, every 10th modelled indoor row, the 3-wood, 3-iron, 6-iron and 9-iron of "
                 "the tour-averages table, the last synthetic sessions; the validation landing and max-height errors "
                 "are over the measured sources' validation shots, flown calm in their air (a range session's in its "
                 f"source's fitted air) ({which})",
        "loss_description": loss_description(config),
        "latent_conditions": latent_description(config, conditions),
    }, out)
    shutil.copyfile(run_dir / "conditions.json", out / CONDITIONS_FILE)
    return card


def _network(init: str | os.PathLike | Start) -> nn.Module:
    """A fresh copy of the starting network (a seed's start, or the module the soup's weights go into): the bundle
    INIT's, or a variant's start."""
    from golfflight.model_export.bundle_model import model_from_bundle

    return init.network() if isinstance(init, Start) else model_from_bundle(init)[0]


@dataclass(frozen=True)
class SeedPlan:
    """How `train_real` trains its seeds: on `device`, in `jobs` processes of their own at a time, each with
    `threads` torch threads; one seed a process, or (`stacked`) the seeds shared out over the processes and each
    process's side by side in one rollout; `compile_step` fuses each Euler step's kernels with torch.compile. On a
    GPU one process: the seeds one after another, or all stacked."""

    device: str = DEFAULT_DEVICE
    jobs: int = 1
    threads: int = 2
    stacked: bool = False
    compile_step: bool = False

    def check(self) -> None:
        """InputError, in the command line's words, for a plan that cannot run here."""
        if resolve_device(self.device).type != "cpu" and self.jobs > 1:
            raise InputError(f"--jobs {self.jobs} goes with --device cpu: on {self.device} the seeds run one after "
                             "another, or side by side with --stack-seeds")


def train_seed(data_file: Path, run_dir: Path, init: str | os.PathLike | Start, config: JointConfig, threads: int,
               progress: bool, device: str = DEFAULT_DEVICE, compile_step: bool = False) -> JointResult:
    """One seed's joint run from the bundle `init` on `device` (a process of its own when seeds run in parallel)."""
    return train_joint(data_file, run_dir, config, _start(init, threads), progress, device, compile_step)


def train_stacked(data_file: Path, work: Path, init: str | os.PathLike | Start, configs: dict[str, JointConfig],
                  threads: int, progress: bool, device: str = DEFAULT_DEVICE, compile_step: bool = False
                  ) -> dict[str, JointResult]:
    """Seeds side by side in one rollout from the bundle `init` (`joint.train_joint_runs`), each in WORK/NAME."""
    results = train_joint_runs(data_file, [work / name for name in configs], list(configs.values()),
                               _start(init, threads), progress, device, compile_step)
    return dict(zip(configs, results))


def _start(init: str | os.PathLike | Start, threads: int) -> nn.Module:
    """The network of the bundle `init` in training mode, with torch on `threads` CPU threads in this process."""
    import torch

    torch.set_num_threads(threads)
    model = _network(init)
    model.train()
    return model


def train_seeds(data_file: Path, work: Path, init: str | os.PathLike | Start, configs: dict[str, JointConfig],
                 plan: SeedPlan, progress: bool) -> dict[str, JointResult]:
    """Each seed's joint run (WORK/NAME), by name, as `plan` says. In this process: stacked, or one after the other,
    with their epoch bars. In several (`plan.jobs`, silent there): a seed or a stack of seeds each, with a bar over
    those finished."""
    from concurrent.futures import ProcessPoolExecutor, as_completed

    names = list(configs)
    if plan.jobs <= 1:
        if plan.stacked:
            progress_step(f"{', '.join(names)} side by side", progress)
            return train_stacked(data_file, work, init, configs, plan.threads, progress, plan.device,
                                 plan.compile_step)
        runs = {}
        for index, (name, c) in enumerate(configs.items(), start=1):
            progress_step(f"{name} ({index} of {len(configs)})", progress)
            runs[name] = train_seed(data_file, work / name, init, c, plan.threads, progress, plan.device,
                                    plan.compile_step)
        return runs
    done: dict[str, JointResult] = {}
    with ProcessPoolExecutor(plan.jobs) as pool:
        if plan.stacked:
            stacks = [{name: configs[name] for name in names[i::plan.jobs]} for i in range(min(plan.jobs, len(names)))]
            futures = [pool.submit(train_stacked, data_file, work, init, stack, plan.threads, False, plan.device,
                                   plan.compile_step) for stack in stacks]
            unit = "stack"
        else:
            futures = {pool.submit(train_seed, data_file, work / name, init, c, plan.threads, False, plan.device,
                                   plan.compile_step): name for name, c in configs.items()}
            unit = "seed"
        for future in progress_bar(as_completed(futures), f"{unit}s", total=len(futures), unit=unit, shown=progress):
            done |= future.result() if plan.stacked else {futures[future]: future.result()}
    return {name: done[name] for name in names}


def train_real(data_root: str | os.PathLike, work: str | os.PathLike, init: str | os.PathLike | Start,
               config: JointConfig, seeds: tuple[int, ...], out: str | os.PathLike | None,
               source_names: tuple[str, ...] | None = None, progress: bool = True,
               plan: SeedPlan = SeedPlan(), train_fraction: float = 1.0) -> RealRun:
    """Build WORK/real_flights.csv from DATA_ROOT (`train_fraction` of each source's training shots, for a learning
    curve: `thin_training_rows`), train one run per seed from INIT (a bundle, or a variant's
    `Start`: WORK/seed-S, as `plan` says), average several physics seeds' weights into a soup (WORK/soup, scored on
    the CPU), and export the run with the lowest validation felt error to OUT (if given; never for NN, refused
    before anything runs). With `progress`, each step, and the epochs (one seed at a time or all stacked) or the
    seeds (several processes), go to standard error."""
    landing_nn = isinstance(init, Start) and init.variant == "nn"
    if landing_nn and out is not None:
        raise InputError(NN_NOT_SERVED)
    if not 0.0 < train_fraction <= 1.0:
        raise InputError(f"--train-fraction must be above 0 and at most 1, got {train_fraction}")
    plan.check()
    started = time.perf_counter()
    work = Path(work)
    work.mkdir(parents=True, exist_ok=True)
    data_file = work / DATA_FILE
    progress_step(f"building {data_file} from the real sources...", progress)
    sources = build(data_root, data_file, *(() if source_names is None else (source_names,)))
    if train_fraction < 1.0:
        thin_training_rows(data_file, train_fraction)
    configs = {f"seed-{seed}": replace(config, seed=seed) for seed in seeds}
    if landing_nn:
        runs = _train_landing_nn_seeds(data_file, work, configs, plan.threads, progress)
    else:
        runs = train_seeds(data_file, work, init, configs, plan, progress)
        finished = [run.out_dir for run in runs.values() if run.final]
        if len(finished) > 1:
            progress_step(f"averaging {len(finished)} seeds' weights (the soup)...", progress)
            runs[SOUP] = soup_runs(data_file, finished, work / SOUP, _network(init))
    chosen = min(runs, key=lambda s: runs[s].final["val_loss"] if runs[s].final else float("inf"))
    exported = None
    if out is not None:
        exported = _export_chosen(runs[chosen], data_file, sources, Path(out), init, data_root, progress)
    return RealRun(data_file, sources, runs, chosen, exported, time.perf_counter() - started)


LEARNING_CURVE_SEED = 0
"""Every variant and seed of a learning-curve point trains on the same subset of shots."""


def thin_training_rows(data_file: Path, fraction: float, seed: int = LEARNING_CURVE_SEED) -> None:
    """Rewrite the merged file with `fraction` of each source's training shots (at least one, drawn with `seed`, in
    file order) and every validation shot: a smaller set of the same sources for the learning curve."""
    from golfflight.shots.records import write_shots

    records = read_shots(data_file).records
    rng = np.random.default_rng(seed)
    keep = np.array([r.split != "train" for r in records])
    for source in dict.fromkeys(r.source for r in records):
        train = np.flatnonzero([r.source == source and r.split == "train" for r in records])
        if len(train):
            keep[rng.permutation(train)[:max(1, round(fraction * len(train)))]] = True
    write_shots(data_file, [r for r, kept in zip(records, keep) if kept])


def _train_landing_nn_seeds(data_file: Path, work: Path, configs: dict[str, JointConfig], threads: int,
                            progress: bool) -> dict[str, JointResult]:
    """NN's seeds one after another in this process (a fresh network each, `real_nn.train_landing_nn`)."""
    import torch
    from golfflight.model_export import DEFAULT_HIDDEN
    from golfflight.model_export.real_nn import train_landing_nn

    torch.set_num_threads(threads)
    runs = {}
    for index, (name, c) in enumerate(configs.items(), start=1):
        progress_step(f"{name} ({index} of {len(configs)})", progress)
        runs[name] = train_landing_nn(data_file, work / name, c, DEFAULT_HIDDEN, progress)
    return runs


def _export_chosen(run: JointResult, data_file: Path, sources: list[SourceData], out: Path,
                   init: str | os.PathLike | Start, data_root: str | os.PathLike, progress: bool) -> ModelCard:
    """Export the chosen physics run to OUT as its variant's bundle and measure its held-out errors into the card."""
    from golfflight.evaluation.held_out import record_held_out
    from golfflight.weights_schema.bundle import load_bundle

    progress_step(f"exporting {run.out_dir.name} to {out} and measuring its held-out errors...", progress)
    if isinstance(init, Start):
        variant, hidden = init.variant, tuple(getattr(init.network(), "hidden", ()))
    else:
        card, _ = load_bundle(init)
        variant, hidden = card.variant, tuple(card.architecture.hidden_units)
    export_real(run.out_dir, data_file, sources, out, variant, hidden)
    return record_held_out(out, data_root)
