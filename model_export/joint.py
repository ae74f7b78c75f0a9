"""Joint training on real flights: the coefficient network and, beside it, the conditions nobody recorded.

Every observable a shot has (landing point, apex, flight time, landing angle, path positions) enters the loss in
units of its measurement noise (`model_export.observations`), through a Huber function (outliers count linearly).
Each conditions group gets a latent uniform wind, each air group a latent density factor, each non-reference ball
type a latent lift and drag scale, all with Gaussian priors whose widths are the typical sizes of the matching
discovery effects (`discovery.effects`: wind, air_density, ball), so the network does not absorb
a session's weather into the aerodynamics. Each source's mean air is held at its stated air where it is known
(`shots.source_air`) and fitted where it is not (range sessions), so the sources with known air set the level of a
carry. Validation shots are flown calm in their recorded air (a range session's in its source's fitted mean air), as
the service would fly them. A run ends on its last epoch, where the cosine-decayed learning rates have settled it
(picking the lowest of noisy per-epoch validation losses picked early, barely moved epochs); runs are compared by
`selection_loss`: per validation source the carry's mean absolute error plus its absolute bias (what a simulator
player feels), averaged over the sources with each counting equally. Seeds can train side by side in one rollout
(`train_joint_runs`, `model_export.stacked_runs`): the latent conditions and noise factors then carry a run axis.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import torch
from golfflight.discovery.effects import EFFECTS
from golfflight.errors import InputError
from golfflight.flight.devices import DEFAULT_DEVICE, resolve_device
from golfflight.flight.wind import Wind
from golfflight.model_export.observations import (
    OBSERVABLES,
    PATH_OBSERVATIONS,
    PATH_SIGMA_M,
    ObservedData,
    ObservedShots,
    load_observed,
)
from golfflight.model_export.stacked_runs import StackedNetworks, clip_per_run, run_of_rows, runs_held
from golfflight.flight.integrator import FORWARD_EULER, StepRule
from golfflight.flight.rollout import (
    DT_S,
    T_SIM_S,
    Coefficients,
    euler_rollout,
    hard_landing,
    positions_at,
    step_rule,
)
from golfflight.model_export.training import CHECKPOINT_FORMAT, GRAD_CLIP_NORM, load_checkpoint, save_checkpoint
from golfflight.shots.files import write_text_atomic
from golfflight.shots.progress import print_line, progress_bar
from golfflight.shots.source_air import UNKNOWN_AIR_SOURCES
from torch import nn

HUBER_DELTA = 2.0
"""Residuals beyond 2 sigma count linearly: mishits and gusts do not dominate the fit."""

SOURCE_WEIGHTS = {
    "trackman-outdoor": 1.0,
    "sentry-2022": 1.0,
    "players-2020": 1.0,
    "tour-championship-2020": 1.0,
    "trackman-model": 0.05,
    "pga-2023-table": 5.0,
    "synthetic": 0.2,
}
"""Weight of one shot of each source in the loss: measured flights 1, TrackMan's modelled rows 0.05, the reference
world 0.2, one club of the tour-averages table 5 (an average over thousands of shots in known air). The modelled rows'
and the table's weights were chosen on the validation split (`scripts/train_real_weights.py`, docs/training_real.md)."""


def _typical(effect: str) -> float:
    return EFFECTS[effect].parameters[0].typical


@dataclass
class JointConfig:
    """Everything that decides a joint run (stored in its checkpoints)."""

    epochs: int = 40
    batch_size: int = 64
    """Small batches: 4,900 shots make 77 steps an epoch (at 256, 19 steps: 40 epochs left the drivers underfitted)."""
    lr: float = 3e-4
    latent_lr: float = 3e-2
    noise_lr: float = 3e-3
    """Slow on purpose: at 2e-2 the factors reach the recordings' scatter (5-15x the radar's) within 20 epochs,
    the clean synthetic shots then outweigh the measured ones, and every measured source's validation error
    grows (TrackMan 7.2 -> 8.8 m, Sentry 10 -> 11 m, THE PLAYERS' carry 6.3 -> 7.1 m)."""
    final_lr_fraction: float = 0.1
    """Every learning rate decays along a cosine from its value to this fraction of it over the run, so the last
    epochs settle instead of jumping between minibatch directions."""
    seed: int = 0
    huber_delta: float = HUBER_DELTA
    weights: dict[str, float] = field(default_factory=lambda: dict(SOURCE_WEIGHTS))
    wind_prior_mps: float = field(default_factory=lambda: _typical("wind"))
    density_prior: float = field(default_factory=lambda: _typical("air_density"))
    ball_prior: float = field(default_factory=lambda: _typical("ball"))
    select_on: tuple[str, ...] = ("trackman-outdoor", "sentry-2022", "players-2020", "tour-championship-2020",
                                  "trackman-model", "pga-2023-table")
    """Sources whose validation error compares runs, each counting equally (`selection_loss`)."""
    mean_wind_prior_mps: float = 0.3
    mean_density_prior: float = 0.01
    """A known-air source's mean latent density stays within 1 % of its stated air."""
    unknown_air_sources: tuple[str, ...] = UNKNOWN_AIR_SOURCES
    unknown_mean_density_prior: float = 0.1
    """An unknown-air source's mean density is free within about 10 %: its level is its air's and its balls', not the
    network's."""
    grad_clip_norm: float = GRAD_CLIP_NORM
    dt_s: float = DT_S
    t_sim_s: float = T_SIM_S

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


class PerRun(nn.Module):
    """Parameters with a leading run axis (`model_export.stacked_runs`), saved one run at a time without it."""

    def run_state(self, run: int) -> dict[str, torch.Tensor]:
        """One run's values, as its checkpoint holds them (no run axis)."""
        return {name: value[run].detach().clone() for name, value in self.state_dict().items()}

    @torch.no_grad()
    def load_run_state(self, run: int, state: dict[str, torch.Tensor]) -> None:
        """Set one run's values from a checkpoint's (`run_state`)."""
        for name, value in self.state_dict().items():
            value[run] = state[name]


class LatentConditions(PerRun):
    """Per-group winds (x, y in m/s), per-air-group log density factors, per-ball log (lift, drag) scales, each
    once a run: a leading axis of `runs`, the runs trained side by side (`model_export.stacked_runs`)."""

    def __init__(self, data: ObservedData, runs: int = 1) -> None:
        super().__init__()
        self.wind = nn.Parameter(torch.zeros(runs, len(data.wind_groups), 2))
        self.log_density = nn.Parameter(torch.zeros(runs, len(data.air_groups)))
        self.log_ball_scale = nn.Parameter(torch.zeros(runs, len(data.balls), 2))

    @staticmethod
    def _pick(values: torch.Tensor, run: torch.Tensor, index: torch.Tensor) -> torch.Tensor:
        """values[run, index] with zeros where index is -1 (no latent for this shot)."""
        if values.shape[1] == 0:
            return values.new_zeros((index.shape[0], *values.shape[2:]))
        picked = values[run, index.clamp_min(0)]
        keep = (index >= 0).reshape(-1, *([1] * (picked.dim() - 1)))
        return torch.where(keep, picked, torch.zeros_like(picked))

    def for_shots(self, shots: ObservedShots, run: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Wind [n,3], density [n] and coefficient scale [n,4] (C_L, C_D, C_M, C_Q) of these shots, each shot in
        the latent conditions of its run (`run` [n])."""
        wind_xy = self._pick(self.wind, run, shots.wind_group)
        wind = torch.cat([wind_xy, wind_xy.new_zeros(len(shots), 1)], dim=1)
        density = shots.density * self._pick(self.log_density, run, shots.air_group).exp()
        lift_drag = self._pick(self.log_ball_scale, run, shots.ball).exp()
        scale = torch.cat([lift_drag, lift_drag.new_ones(len(shots), 2)], dim=1)
        return wind, density, scale

    def prior(self, config: JointConfig, wind_source: torch.Tensor, air_source: torch.Tensor,
              sources: list[str]) -> torch.Tensor:
        """Negative log prior of each run [runs] (Gaussian, up to a constant): winds and ball scales about zero,
        each source's mean wind about calm; a known-air source's group densities about its stated air and their
        mean tightly so (`mean_density_prior`); an unknown-air source's group densities about the source's own
        mean, which is loose (`unknown_mean_density_prior`), so that only the sources with known air set the level.
        `*_source` [groups] name the source of each wind and air group."""
        total = (self.wind / config.wind_prior_mps).pow(2).sum(dim=(1, 2)) + (
            self.log_ball_scale / config.ball_prior).pow(2).sum(dim=(1, 2))
        for s in wind_source.unique():
            total = total + (self.wind[:, wind_source == s].mean(dim=1) / config.mean_wind_prior_mps).pow(2).sum(dim=1)
        for s in air_source.unique():
            values = self.log_density[:, air_source == s]
            mean = values.mean(dim=1)
            if sources[int(s)] in config.unknown_air_sources:
                total = total + ((values - mean[:, None]) / config.density_prior).pow(2).sum(dim=1)
                total = total + (mean / config.unknown_mean_density_prior).pow(2)
            else:
                total = total + (values / config.density_prior).pow(2).sum(dim=1) + (
                    mean / config.mean_density_prior).pow(2)
        return 0.5 * total

    @torch.no_grad()
    def source_density_factors(self, config: JointConfig, air_source: torch.Tensor, sources: list[str]
                               ) -> torch.Tensor:
        """Per run and source [runs, sources]: the fitted mean density factor of an unknown-air source, 1 for every
        other: the air a validation shot of a range session is flown in (its source's, not one block's)."""
        factors = torch.ones(self.log_density.shape[0], len(sources), device=self.log_density.device)
        for s in air_source.unique():
            if sources[int(s)] in config.unknown_air_sources:
                factors[:, int(s)] = self.log_density[:, air_source == s].mean(dim=1).exp()
        return factors


class NoiseScales(PerRun):
    """How much more each source scatters than the radar, per observable (and for its path): sigma = radar sigma
    x exp(softplus(s)) (never below the radar's), fitted by maximum likelihood (the loss adds log sigma), so gusts,
    mishits and TrackMan's extrapolations widen an observable's sigma instead of dominating the fit. Once a run
    (a leading axis of `runs`), like `LatentConditions`."""

    def __init__(self, n_sources: int, runs: int = 1) -> None:
        super().__init__()
        self.raw = nn.Parameter(torch.zeros(runs, n_sources, len(OBSERVABLES) + 1))

    def factors(self) -> torch.Tensor:
        """[runs, sources, observables + path]."""
        return nn.functional.softplus(self.raw).exp()


@dataclass
class Predicted:
    """Model observables [n, 5] (order OBSERVABLES), path positions [n, K, 3] and whether each shot landed."""

    observables: torch.Tensor
    path: torch.Tensor
    landed: torch.Tensor

    def rows(self, start: int, stop: int) -> Predicted:
        """The shots start to stop (one run's of a stacked flight)."""
        return Predicted(self.observables[start:stop], self.path[start:stop], self.landed[start:stop])


def fly(model: Coefficients, shots: ObservedShots, config: JointConfig, latent: LatentConditions | None,
        source_density: torch.Tensor | None = None, run: torch.Tensor | None = None,
        step: StepRule = FORWARD_EULER) -> Predicted:
    """Euler rollout of the shots: with their latent conditions, or, when `latent` is None, calm in their recorded
    air times their source's fitted density factor (`source_density` [runs, sources], where given). `run` [n] is
    each shot's run where `model` is several stacked (`stacked_runs.StackedNetworks`); None: all of run 0. `step`:
    `flight.rollout.step_rule`'s forward Euler, eager or compiled. The rollout stops once every shot has come down
    and its last path sample is flown (`euler_rollout`'s `stop_after_s`): what is read of it, the landing, apex and
    path, is the same."""
    if run is None:
        run = torch.zeros(len(shots), dtype=torch.long, device=shots.source.device)
    if latent is None:
        factor = 1.0 if source_density is None else source_density[run, shots.source]
        wind, density, scale = None, shots.density * factor, None
    else:
        wind, density, scale = latent.for_shots(shots, run)
    last_sample_s = float(shots.path_times.max()) if shots.path_times.numel() else 0.0
    trajectory = euler_rollout(shots.position, shots.velocity, shots.spin, model, density, config.dt_s,
                               config.t_sim_s, shots.reynolds_scale[:, None], wind, scale, step,
                               stop_after_s=last_sample_s)
    landing = hard_landing(trajectory)
    v = landing.velocity
    angle = torch.rad2deg(torch.atan2(-v[:, 2], torch.linalg.vector_norm(v[:, :2], dim=-1)))
    observables = torch.stack([landing.position[:, 0], landing.position[:, 1], trajectory.apex_m,
                               landing.time_s, angle], dim=1)
    path = positions_at(trajectory, shots.path_times) - trajectory.positions[0][:, None, :]
    return Predicted(observables, path, landing.landed)


def _huber(x: torch.Tensor, delta: float) -> torch.Tensor:
    return nn.functional.huber_loss(x, torch.zeros_like(x), reduction="none", delta=delta)


def shot_losses(predicted: Predicted, shots: ObservedShots, delta: float, factors: torch.Tensor | None = None
                ) -> torch.Tensor:
    """Per-shot loss [n]: Huber of the noise-scaled residual of each recorded observable, plus the path's samples
    (3-D distance over the path noise) scaled to count as PATH_OBSERVATIONS observations in all. With `factors`
    (each shot's row of `NoiseScales.factors()`, [n, 6]) each sigma is widened by its factor and log sigma is added
    (the negative log likelihood, so the factors are fitted too)."""
    factor = torch.ones(len(shots), len(OBSERVABLES) + 1, device=shots.sigma.device) if factors is None else factors
    mask = shots.target_mask & predicted.landed[:, None]
    sigma = shots.sigma * factor[:, :-1]
    residual = torch.where(mask, (predicted.observables - shots.targets) / sigma, 0.0)
    outcome = torch.where(mask, _huber(residual, delta) + sigma.log(), 0.0).sum(dim=1)
    path_sigma = PATH_SIGMA_M * factor[:, -1:]
    distance = torch.linalg.vector_norm(predicted.path - shots.path_positions, dim=-1) / path_sigma
    path_terms = torch.where(shots.path_mask, _huber(distance, delta) + path_sigma.log(), 0.0)
    n_samples = shots.path_mask.sum(dim=1).clamp_min(1)
    return outcome + PATH_OBSERVATIONS * path_terms.sum(dim=1) / n_samples


def spread_heavy_rows(shots: ObservedShots) -> ObservedShots:
    """Each shot of weight w > 1 repeated ceil(w) times at weight w / ceil(w): the same total weight, but spread
    over that many minibatches. A few heavy shots (one tour-averages club stands for thousands of shots) would
    otherwise each land in one batch an epoch, where gradient clipping and Adam's normalisation cap their pull
    whatever their weight (measured: table weights 5 and 150 trained the same network)."""
    copies = torch.ceil(shots.weight.clamp_min(1.0)).long()
    spread = shots.take(torch.repeat_interleave(torch.arange(len(shots), device=copies.device), copies))
    spread.weight = spread.weight / torch.repeat_interleave(copies, copies).float()
    return spread


def cosine_factor(step: int, total_steps: int, final_fraction: float) -> float:
    """Learning-rate multiplier: 1 at the first step, `final_fraction` at the last, along half a cosine."""
    progress = min(step / max(total_steps - 1, 1), 1.0)
    return final_fraction + (1.0 - final_fraction) * 0.5 * (1.0 + math.cos(math.pi * progress))


def weighted_mean(values: torch.Tensor, weight: torch.Tensor) -> torch.Tensor:
    return (values * weight).sum() / weight.sum().clamp_min(1e-12)


@torch.no_grad()
def evaluate(model: Coefficients, shots: ObservedShots, config: JointConfig, sources: list[str],
             source_density: torch.Tensor | None = None, runs: int = 1, step: StepRule = FORWARD_EULER
             ) -> list[dict[str, Any]]:
    """Each run's (of `runs` stacked in `model`) loss and per-source errors in physical units on `shots`, flown calm
    in their air times `source_density` [runs, sources] (`fly`, with `step`): landing error (m), mean absolute error
    and mean signed error (bias) of every observable, path error (m), over the shots that have each."""
    n = len(shots)
    every = shots if runs == 1 else shots.take(torch.arange(n, device=shots.source.device).repeat(runs))
    predicted = fly(model, every, config, None, source_density, run_of_rows(runs, n, shots.source.device), step)
    return [score(predicted.rows(r * n, (r + 1) * n), shots, config, sources) for r in range(runs)]


def score(predicted: Predicted, shots: ObservedShots, config: JointConfig, sources: list[str]) -> dict[str, Any]:
    """Loss and per-source errors of one run's flights of `shots` (`evaluate`)."""
    losses = shot_losses(predicted, shots, config.huber_delta)
    metrics: dict[str, Any] = {"loss": float(weighted_mean(losses, shots.weight)), "sources": {}}
    signed = predicted.observables - shots.targets
    error = signed.abs()
    ok = shots.target_mask & predicted.landed[:, None]
    landing_error = torch.linalg.vector_norm(predicted.observables[:, :2] - shots.targets[:, :2], dim=1)
    path_error = torch.linalg.vector_norm(predicted.path - shots.path_positions, dim=-1)
    for index, name in enumerate(sources):
        mine = shots.source == index
        if not mine.any():
            continue
        row: dict[str, float | int] = {"n_shots": int(mine.sum()),
                                       "loss": float(weighted_mean(losses[mine], torch.ones_like(losses[mine])))}
        landed = mine & ok[:, 0] & ok[:, 1]
        if landed.any():
            row["landing_error_m"] = float(landing_error[landed].mean())
        for column, observable in enumerate(OBSERVABLES):
            has = mine & ok[:, column]
            if has.any():
                row[f"{observable}_mae"] = float(error[has, column].mean())
                row[f"{observable}_bias"] = float(signed[has, column].mean())
        on_path = shots.path_mask & mine[:, None]
        if on_path.any():
            row["path_error_m"] = float(path_error[on_path].mean())
        metrics["sources"][name] = row
    return metrics


def conditions_report(latent: LatentConditions, data: ObservedData, train: ObservedShots, run: int = 0
                      ) -> dict[str, Any]:
    """Run `run`'s fitted latent conditions, readable: winds as speed and from-direction, density ratios, ball
    scales."""
    def count(index: torch.Tensor, i: int) -> int:
        return int((index == i).sum())

    wind = []
    for i, group in enumerate(data.wind_groups.names):
        x, y = (float(v) for v in latent.wind[run, i].detach())
        fitted = Wind.from_components(x, y)
        speed, from_deg = float(fitted.speed_mps), float(fitted.from_deg)
        source = data.sources[int(train.source[train.wind_group == i][0])]
        wind.append({"group": group, "source": source, "n_shots": count(train.wind_group, i), "x_mps": x,
                     "y_mps": y, "speed_mps": speed, "from_deg": from_deg})
    density, ball_scale = latent.log_density[run].detach().exp(), latent.log_ball_scale[run].detach().exp()
    air = [{"group": g, "n_shots": count(train.air_group, i), "density_ratio": float(density[i])}
           for i, g in enumerate(data.air_groups.names)]
    ball = [{"ball": b, "n_shots": count(train.ball, i), "lift_scale": float(ball_scale[i, 0]),
             "drag_scale": float(ball_scale[i, 1])} for i, b in enumerate(data.balls.names)]
    return {"wind": wind, "air": air, "ball": ball}


def _group_sources(group: torch.Tensor, source: torch.Tensor, n_groups: int) -> torch.Tensor:
    """The source index of each latent group [n_groups] (a group never spans two sources)."""
    out = torch.full((n_groups,), -1, dtype=torch.long, device=group.device)
    has = group >= 0
    out[group[has]] = source[has]
    return out


def _noise_report(noise: NoiseScales, data: ObservedData, run: int) -> dict[str, dict[str, float]]:
    factors = noise.factors()[run].detach()
    names = [*OBSERVABLES, "path"]
    return {source: {n: float(factors[i, j]) for j, n in enumerate(names)} for i, source in enumerate(data.sources)}


@dataclass
class JointResult:
    """A finished joint run: its directory, per-epoch history and its final epoch (epoch, val_loss, val)."""

    out_dir: Path
    history: list[dict[str, Any]]
    final: dict[str, Any] | None


def train_joint(data_path: str | os.PathLike, out_dir: str | os.PathLike, config: JointConfig,
                init: nn.Module, progress: bool = True, device: str = DEFAULT_DEVICE, compile_step: bool = False
                ) -> JointResult:
    """Train the coefficient module `init` (a copy: `init` is left as it is) jointly with the latent conditions on
    a merged file; writes OUT/last.pt (the `model_export.training` checkpoint format), history.json and
    conditions.json (the latent conditions and noise factors), all of the last epoch finished. The latent
    conditions are initialised and the batches drawn on the CPU whatever the device. `compile_step` fuses each
    Euler step's kernels, forward and backward, with torch.compile (once for every batch size)."""
    return train_joint_runs(data_path, [out_dir], [config], init, progress, device, compile_step)[0]


def train_joint_runs(data_path: str | os.PathLike, out_dirs: list[str | os.PathLike], configs: list[JointConfig],
                     init: nn.Module, progress: bool = True, device: str = DEFAULT_DEVICE, compile_step: bool = False
                     ) -> list[JointResult]:
    """Several joint runs from `init` that differ only in their seed, trained side by side in one rollout
    (`model_export.stacked_runs`): each run as `train_joint` trains it alone, written to its own folder."""
    if len(out_dirs) != len(configs) or not configs:
        raise InputError(f"one folder a run: {len(out_dirs)} folders for {len(configs)} configurations")
    differ = [c.seed for c in configs if replace(c, seed=0) != replace(configs[0], seed=0)]
    if differ:
        raise InputError(f"runs trained side by side may differ only in their seed; seeds {differ} differ from "
                         f"seed {configs[0].seed}'s configuration in more")
    where = resolve_device(device)
    torch.set_flush_denormal(True)
    try:
        return _train_joint(Path(data_path), [Path(d) for d in out_dirs], configs,
                            StackedNetworks(init, len(configs)).to(where), progress, where,
                            step_rule(compile_step))
    finally:
        torch.set_flush_denormal(False)


def _train_joint(data_path: Path, out_dirs: list[Path], configs: list[JointConfig], networks: StackedNetworks,
                 progress: bool, device: torch.device, step: StepRule) -> list[JointResult]:
    config, runs = configs[0], len(configs)
    for out_dir in out_dirs:
        out_dir.mkdir(parents=True, exist_ok=True)
    data = load_observed(data_path, config.weights)
    data = replace(data, train=data.train.to(device), val=data.val.to(device))
    torch.manual_seed(config.seed)
    latent = LatentConditions(data, runs).to(device)
    noise = NoiseScales(len(data.sources), runs).to(device)
    wind_source = _group_sources(data.train.wind_group, data.train.source, len(data.wind_groups))
    air_source = _group_sources(data.train.air_group, data.train.source, len(data.air_groups))
    optimizer = torch.optim.Adam([{"params": networks.parameters(), "lr": config.lr},
                                  {"params": latent.parameters(), "lr": config.latent_lr},
                                  {"params": noise.parameters(), "lr": config.noise_lr}])
    train = spread_heavy_rows(data.train)
    total_weight = float(train.weight.sum())
    total_steps = config.epochs * math.ceil(len(train) / config.batch_size)
    schedule = torch.optim.lr_scheduler.LambdaLR(
        optimizer, lambda step: cosine_factor(step, total_steps, config.final_lr_fraction))
    histories: list[list[dict[str, Any]]] = [[] for _ in configs]
    finals: list[dict[str, Any] | None] = [None] * runs
    for epoch in range(1, config.epochs + 1):
        started = time.perf_counter()
        orders = [torch.randperm(len(train), generator=torch.Generator().manual_seed(c.seed * 100_003 + epoch)
                                 ).to(device) for c in configs]
        sums, steps = [0.0] * runs, [0] * runs
        batches = range(0, len(train), config.batch_size)
        for start in progress_bar(batches, f"epoch {epoch}/{config.epochs}", unit="batch", shown=progress):
            picked = [order[start:start + config.batch_size] for order in orders]
            batch = train.take(picked[0] if runs == 1 else torch.cat(picked))
            size = len(picked[0])
            run = run_of_rows(runs, size, device)
            optimizer.zero_grad(set_to_none=True)
            losses = shot_losses(fly(networks, batch, config, latent, run=run, step=step), batch, config.huber_delta,
                                 noise.factors()[run, batch.source])
            loss = (losses * batch.weight).reshape(runs, size).sum(dim=1) / total_weight * (len(train) / size)
            loss = loss + latent.prior(config, wind_source, air_source, data.sources) / len(train)
            finite = torch.isfinite(loss)
            if not finite.any():
                continue
            (loss.sum() if finite.all() else loss[finite].sum()).backward()
            clip_per_run(networks.parameters(), config.grad_clip_norm, runs)
            with runs_held(optimizer, ~finite):
                optimizer.step()
            schedule.step()
            for r, (value, stepped) in enumerate(zip(loss.detach().tolist(), finite.tolist())):
                if stepped:
                    sums[r] += value
                    steps[r] += 1
        source_density = latent.source_density_factors(config, air_source, data.sources)
        metrics = evaluate(networks, data.val, config, data.sources, source_density, runs, step)
        seconds = time.perf_counter() - started
        for r, c in enumerate(configs):
            row = {"epoch": epoch, "train_loss": sums[r] / max(steps[r], 1), "val_loss": metrics[r]["loss"],
                   "val": metrics[r]["sources"], "seconds": seconds, "selection_loss": selection_loss(metrics[r], c),
                   "source_density": dict(zip(data.sources, source_density[r].tolist()))}
            histories[r].append(row)
            if progress:
                print_line(f"epoch {epoch}: " + (f"seed {c.seed}: " if runs > 1 else "")
                           + f"train {row['train_loss']:.3f}, felt {row['selection_loss']:.2f} m " + ", ".join(
                               f"{k} {felt_error_m(v):.2f}" for k, v in metrics[r]["sources"].items()))
            finals[r] = _save_run(out_dirs[r], epoch, c, networks.run_state(r), latent, noise, r, data,
                                  histories[r], metrics[r])
    return [JointResult(d, h, f) for d, h, f in zip(out_dirs, histories, finals)]


def felt_error_m(row: dict[str, float]) -> float:
    """What a simulator player feels of a source's validation error (m): the carry's mean absolute error plus its
    absolute bias, so a model 8 m short on every shot (16) loses to one with 4 m more scatter and no bias (12); on
    the apex where a source records no carry."""
    key = "carry_y_m" if "carry_y_m_mae" in row else "apex_m"
    return row[f"{key}_mae"] + abs(row[f"{key}_bias"])


def selection_loss(metrics: dict[str, Any], config: JointConfig) -> float:
    """What compares runs (weights, seeds, the soup): the mean over the `select_on` sources of their validation
    `felt_error_m`, each source counting equally."""
    selected = [v for k, v in metrics["sources"].items() if k in config.select_on] or list(
        metrics["sources"].values())
    return sum(felt_error_m(v) for v in selected) / len(selected)


def _save_run(out_dir: Path, epoch: int, config: JointConfig, model_state: dict[str, torch.Tensor],
              latent: LatentConditions, noise: NoiseScales, run: int, data: ObservedData,
              history: list[dict[str, Any]], metrics: dict[str, Any]) -> dict[str, Any]:
    """Write OUT/last.pt, conditions.json and history.json of run `run`'s latest epoch; its `final` record."""
    payload = {"format": CHECKPOINT_FORMAT, "kind": "joint", "epoch": epoch, "config": config.as_dict(),
               "model": model_state, "latent": latent.run_state(run), "noise": noise.run_state(run),
               "history": history}
    save_checkpoint(out_dir / "last.pt", payload)
    final = {"epoch": epoch, "val_loss": selection_loss(metrics, config), "val": metrics["sources"]}
    report = conditions_report(latent, data, data.train, run) | {"noise_factors": _noise_report(noise, data, run)}
    write_text_atomic(out_dir / "conditions.json", json.dumps(report, indent=2) + "\n")
    write_text_atomic(out_dir / "history.json",
                      json.dumps({"config": config.as_dict(), "final": final, "epochs": history}, indent=2) + "\n")
    return final


def _mean_state(states: list[dict[str, torch.Tensor]]) -> dict[str, torch.Tensor]:
    """The element-wise mean of state dicts with the same keys (integer buffers are taken from the first)."""
    return {name: torch.stack([s[name] for s in states]).mean(0) if states[0][name].is_floating_point()
            else states[0][name] for name in states[0]}


@torch.no_grad()
def soup_runs(data_path: str | os.PathLike, run_dirs: list[Path], out_dir: str | os.PathLike,
              model: nn.Module) -> JointResult:
    """A uniform model soup (Wortsman et al. 2022): the mean of the final weights of joint runs that started from
    the same network on the same data (seeds), evaluated on the validation split exactly as a run's last epoch.
    Its latent conditions and noise factors are the runs' means too. Written to OUT like a run (last.pt, ...)."""
    payloads = [load_checkpoint(Path(d) / "last.pt") for d in run_dirs]
    config = JointConfig(**payloads[0]["config"])
    data = load_observed(Path(data_path), config.weights)
    latent, noise = LatentConditions(data), NoiseScales(len(data.sources))
    model.load_state_dict(_mean_state([p["model"] for p in payloads]))
    latent.load_run_state(0, _mean_state([p["latent"] for p in payloads]))
    noise.load_run_state(0, _mean_state([p["noise"] for p in payloads]))
    model.eval()
    air_source = _group_sources(data.train.air_group, data.train.source, len(data.air_groups))
    metrics, = evaluate(model, data.val, config, data.sources,
                        latent.source_density_factors(config, air_source, data.sources))
    epoch = payloads[0]["epoch"]
    row = {"epoch": epoch, "val_loss": metrics["loss"], "val": metrics["sources"],
           "selection_loss": selection_loss(metrics, config), "soup_of": [str(d) for d in run_dirs]}
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    final = _save_run(out_dir, epoch, config, model.state_dict(), latent, noise, 0, data, [row], metrics)
    return JointResult(out_dir, [row], final)

