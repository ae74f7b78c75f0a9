"""Table 1 on our data: every trained variant's validation errors beside the noise floor (`noise_floor`), the
shipped bundle through the runtime path, and the paper's Figures 6 and 7.

Physics variants are flown through the torch Euler rollout in float64 with the inference landing (hard argmax,
interpolated to r_z = 0); the NN baseline predicts the landing point directly.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import torch
from golfflight.evaluation.noise_floor import Floor, noise_floors, nominal_conditions
from golfflight.evaluation.report import metres_yards
from golfflight.evaluation.validation import Errors, Prediction, errors_of, gap
from golfflight.flight.air import Air
from golfflight.flight.conditions import BatchAir
from golfflight.flight.flyer import load_flyer
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import initial_state, spin_ratio
from golfflight.flight.problem import FlightProblem
from golfflight.flight.reference_aero import CALIBRATED, ReferenceAerodynamics
from golfflight.flight.rollout import euler_rollout, hard_landing
from golfflight.model_export.training import (
    VALIDATION_BATCH,
    TrainConfig,
    load_checkpoint,
    model_from_checkpoint,
    predict,
)
from golfflight.model_export.validation import ValidationSet, load_validation
from golfflight.model_export.variants import PhysNN, PhysQ
from golfflight.shots.markdown import table, write_generated_section
from golfflight.shots.progress import progress_bar, progress_step
from torch import nn

COMMAND = "evaluate"
FIGURES = ("fig6_errors.png", "fig7_coefficients.png")


class PaperRow(NamedTuple):
    """A row of the paper's Table 1 (validation, yards)."""

    landing_yd: float
    max_height_yd: float | None
    epochs: int
    loss: str


PAPER_TABLE1 = {
    "phys-q": PaperRow(6.63, 1.64, 50, "lp+lh"),
    "nn": PaperRow(5.24, None, 100, "lp"),
    "phys-nn": PaperRow(5.66, 10.7, 20, "lp"),
    "phys-nn-pm": PaperRow(5.78, 1.39, 20, "lp+lh"),
    "phys-nn-pm-cq": PaperRow(5.24, 3.92, 20, "lp"),
    "phys-nn+": PaperRow(4.75, 1.31, 50, "lp+lh"),
}
"""The paper's numbers for each variant, with the loss of that row (Phys-NN-pM: its L_p + L_h row)."""

DISPLAY = {
    "phys-q": "Phys-Q",
    "nn": "NN",
    "phys-nn": "Phys-NN",
    "phys-nn-pm": "Phys-NN-pM",
    "phys-nn-pm-cq": "Phys-NN-pM-cQ",
    "phys-nn+": "Phys-NN+",
}
LOSS = {"lp": "L_p", "lp+lh": "L_p + L_h"}


@torch.no_grad()
def predict_validation(model: nn.Module, config: TrainConfig, val: ValidationSet) -> Prediction:
    """Float64 inference over the validation shots in batches (hard landing for the physics variants)."""
    model = model.double().eval()
    landings, apexes = [], []
    for start in range(0, len(val), VALIDATION_BATCH):
        batch = val.tensors.take(torch.arange(start, min(start + VALIDATION_BATCH, len(val))))
        landing, apex = predict(model, batch, config, soft=False)
        landings.append(landing.numpy())
        if apex is not None:
            apexes.append(apex.numpy())
    return Prediction(np.concatenate(landings), np.concatenate(apexes) if apexes else None)


@dataclass
class RunEvaluation:
    """One trained variant on the validation shots."""

    name: str
    config: TrainConfig
    model: nn.Module
    epochs_trained: int
    best_epoch: int
    train_seconds: float
    prediction: Prediction
    errors: Errors
    world_gap: tuple[float, float | None] | None = None
    """Mean landing distance and max-height difference from the nominal reference world (set by `run_evaluation`)."""

    @property
    def variant(self) -> str:
        return self.config.variant


def _history(source: Path, payload: dict[str, Any]) -> list[dict[str, Any]]:
    """All epochs of the run: history.json of a run directory, else the checkpoint's own history."""
    history_file = source / "history.json" if source.is_dir() else source.with_name("history.json")
    if history_file.is_file():
        return json.loads(history_file.read_text())["epochs"]
    return payload["history"]


def evaluate_run(source: str | os.PathLike, val: ValidationSet) -> RunEvaluation:
    """Evaluate a run directory's best.pt (or a checkpoint file) on the validation shots."""
    source = Path(source)
    checkpoint = source / "best.pt" if source.is_dir() else source
    if not checkpoint.is_file():
        raise FileNotFoundError(f"no checkpoint at {checkpoint}")
    payload = load_checkpoint(checkpoint)
    model, config = model_from_checkpoint(payload)
    history = _history(source, payload)
    prediction = predict_validation(model, config, val)
    return RunEvaluation(
        name=source.name if source.is_dir() else source.stem,
        config=config,
        model=model,
        epochs_trained=max(row["epoch"] for row in history),
        best_epoch=int(payload["metrics"]["epoch"]),
        train_seconds=float(sum(row["epoch_seconds"] for row in history)),
        prediction=prediction,
        errors=errors_of(prediction, val),
    )


@dataclass
class BundleCheck:
    """A shipped bundle flown through NumPy + ONNX Runtime, against its own weights in the torch path."""

    bundle: Path
    variant: str
    numpy_errors: Errors
    torch_errors: Errors
    max_landing_difference_m: float
    max_apex_difference_m: float
    not_landed: int


def runtime_flight(bundle_dir: str | os.PathLike | None, launch: dict[str, np.ndarray], air: Air) -> Flight:
    """Launches (the canonical launch columns) flown in `air` by a bundle's Flyer: the runtime path of
    `check_bundle`."""
    flyer = load_flyer(bundle_dir)
    air_columns = BatchAir(air.density_kg_m3, air.kinematic_viscosity_m2_s)
    return flyer.flight(FlightProblem(initial_state(**launch), air_columns))


def check_bundle(bundle_dir: str | os.PathLike, val: ValidationSet) -> BundleCheck:
    """Validation errors of a bundle flown by its Flyer (`flight.flyer.load_flyer`: the runtime path, for the
    engine's maximum flight time) and the largest per-shot difference from the torch float64 evaluation of the same
    weights."""
    from golfflight.model_export.bundle_model import config_from_card, model_from_bundle

    flight = runtime_flight(bundle_dir, val.shots.launch(), val.shots.air())
    runtime = Prediction(flight.landing_position[:, :2], flight.apex_m)
    model, card = model_from_bundle(bundle_dir)
    reference = predict_validation(model, config_from_card(card), val)
    return BundleCheck(
        bundle=Path(bundle_dir),
        variant=card.variant,
        numpy_errors=errors_of(runtime, val),
        torch_errors=errors_of(reference, val),
        max_landing_difference_m=float(np.nanmax(np.linalg.norm(runtime.landing_m - reference.landing_m, axis=-1))),
        max_apex_difference_m=float(np.max(np.abs(runtime.apex_m - reference.apex_m))),
        not_landed=int((~flight.landed).sum()),
    )


@dataclass
class CoefficientSamples:
    """Coefficients along the flights (every Euler step before the landing) of the validation shots."""

    spin_ratio: np.ndarray
    c_lift: np.ndarray
    c_drag: np.ndarray
    c_q: np.ndarray
    reference_lift: np.ndarray
    reference_drag: np.ndarray


@torch.no_grad()
def coefficient_samples(model: nn.Module, config: TrainConfig, val: ValidationSet, air: Air) -> CoefficientSamples:
    """The model's C_L, C_D, C_Q against the spin ratio at every in-flight step of its own validation rollouts (each
    stopped once its shots are down), and the reference world's C_L, C_D at the same states in `air` (its Reynolds
    numbers)."""
    model = model.double().eval()
    parts: list[list[np.ndarray]] = [[] for _ in range(4)]
    states: list[tuple[np.ndarray, np.ndarray]] = []
    for start in range(0, len(val), VALIDATION_BATCH):
        batch = val.tensors.take(torch.arange(start, min(start + VALIDATION_BATCH, len(val))))
        scale = batch.reynolds_scale.double()
        trajectory = euler_rollout(
            batch.position,
            batch.velocity,
            batch.spin,
            model,
            batch.density,
            config.dt_s,
            config.t_sim_s,
            scale[:, None],
            stop_after_s=0.0,
        )
        landing_time = hard_landing(trajectory).time_s
        times = torch.arange(trajectory.positions.shape[0], dtype=torch.float64)[:, None] * config.dt_s
        flying = times < landing_time[None, :]
        velocity, spin = trajectory.velocities[flying], trajectory.spins[flying]
        k = scale.expand(flying.shape)[flying][:, None]
        values = model(velocity * k, spin * k)
        ratio = spin_ratio(velocity, spin)
        for part, value in zip(parts, (ratio, values[:, 0], values[:, 1], values[:, 3])):
            part.append(value.numpy())
        states.append((velocity.numpy(), spin.numpy()))
    velocity = np.concatenate([v for v, _ in states])
    spin = np.concatenate([w for _, w in states])
    reference = ReferenceAerodynamics(CALIBRATED, float(np.mean(air.kinematic_viscosity_m2_s)))(velocity, spin)
    ratio, c_lift, c_drag, c_q = (np.concatenate(part) for part in parts)
    return CoefficientSamples(ratio, c_lift, c_drag, c_q, reference[:, 0], reference[:, 1])


def _quadratic_curves(params: Sequence[float], grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    p = [float(v) for v in params]
    return grid, np.maximum(0.0, p[0] + p[1] * grid + p[2] * grid**2), p[3] + p[4] * grid + p[5] * grid**2


def _series(errors: Errors) -> dict[str, np.ndarray | None]:
    return {"landing": errors.landing_m, "length": errors.length_m, "side": errors.side_m, "apex": errors.apex_m}


HIGH_SPIN_RATIO = 0.5
"""Figure 7's summary splits the effective lift's difference from the reference world at this spin ratio."""


def coefficient_summary(samples: CoefficientSamples, scale: np.ndarray, model: nn.Module, label: str) -> str:
    """Figure 7 in numbers: the raw heads, the learned dynamic pressure, and the effective coefficients against the
    reference world's at the same states (the drag as a median relative difference, the lift as a median
    difference below and above HIGH_SPIN_RATIO), and p_M where the model learns one."""
    lift, drag = scale * samples.c_lift, scale * samples.c_drag
    high = samples.spin_ratio > HIGH_SPIN_RATIO
    relative_drag = np.median(drag / samples.reference_drag - 1.0)
    lift_gap = lift - samples.reference_lift
    low_c_q, high_c_q = np.percentile(samples.c_q, [5, 95])
    text = (
        f"Figure 7 in numbers ({label}, {len(samples.spin_ratio)} in-flight steps): raw C_L median "
        f"{np.median(samples.c_lift):.2f} (99.9th percentile {np.percentile(samples.c_lift, 99.9):.2f}); C_Q median "
        f"{np.median(samples.c_q):.2f} (5th-95th percentile {low_c_q:.2f}-{high_c_q:.2f}); effective C_D against "
        f"the reference world's at the same states: median relative difference {relative_drag:+.1%}; effective "
        f"C_L minus the reference's: median {np.median(lift_gap[~high]):+.3f} below S = {HIGH_SPIN_RATIO:g}, "
        f"{np.median(lift_gap[high]):+.3f} above ({int(high.sum())} steps)"
    )
    if hasattr(model, "log_p_m"):
        text += f"; learned p_M = {float(model.p_m):.4f}"
    return text + "."


def write_figures(
    runs: list[RunEvaluation], floors: list[Floor], val: ValidationSet, air: Air, directory: str | os.PathLike
) -> tuple[list[Path], str]:
    """Figure 6 (error histograms of Phys-Q, NN, Phys-NN+ and the nominal floor) and Figure 7 (Phys-NN+ coefficients
    with Phys-Q's curves), for the variants among `runs`, and Figure 7's summary line (empty without a network
    variant). Figure 7's effective coefficients are C x 2 C_Q x rho_trained / rho_air: the force the model applies,
    expressed in the reference world's (nominal) air."""
    from golfflight.evaluation import figures
    from golfflight.flight.coefficients import FERGUSON_2022

    directory = Path(directory)
    by_variant = {run.variant: run for run in runs}
    written, summary = [], ""
    series = {DISPLAY[v]: _series(by_variant[v].errors) for v in ("phys-q", "nn", "phys-nn+") if v in by_variant}
    if floors[0].errors is not None:
        series[f"noise floor ({floors[0].name})"] = _series(floors[0].errors)
    if series:
        written.append(figures.error_histograms(series, directory / FIGURES[0]))
    phys_nn = by_variant.get("phys-nn+") or next((r for r in runs if isinstance(r.model, PhysNN)), None)
    if phys_nn is not None:
        samples = coefficient_samples(phys_nn.model, phys_nn.config, val, air)
        grid = np.linspace(0.0, float(np.percentile(samples.spin_ratio, 99.9)), 200)
        curves = {}
        if "phys-q" in by_variant and isinstance(by_variant["phys-q"].model, PhysQ):
            curves["Phys-Q (trained)"] = _quadratic_curves(by_variant["phys-q"].model.params.detach().tolist(), grid)
        curves["Ferguson 2022 (Phys-Q start)"] = _quadratic_curves(FERGUSON_2022, grid)
        scale = 2.0 * samples.c_q * float(val.tensors.density.mean()) / float(np.mean(air.density_kg_m3))
        written.append(
            figures.coefficient_clouds(
                samples.spin_ratio,
                {"C_L": samples.c_lift, "C_D": samples.c_drag},
                {"C_L": scale * samples.c_lift, "C_D": scale * samples.c_drag},
                {"C_L": samples.reference_lift, "C_D": samples.reference_drag},
                curves,
                directory / FIGURES[1],
                model_label=DISPLAY[phys_nn.variant],
            )
        )
        summary = coefficient_summary(samples, scale, phys_nn.model, DISPLAY[phys_nn.variant])
    return written, summary


def _order(run: RunEvaluation) -> int:
    return list(PAPER_TABLE1).index(run.variant) if run.variant in PAPER_TABLE1 else len(PAPER_TABLE1)


def _minutes(seconds: float) -> str:
    return f"{seconds / 60:.0f} min" if seconds >= 60 else f"{seconds:.0f} s"


def _gap_cell(world_gap: tuple[float, float | None] | None) -> str:
    if world_gap is None:
        return "–"
    landing, apex = world_gap
    return f"{landing:.2f}" + ("" if apex is None else f" / {apex:.2f}")


def _paper_cells(variant: str) -> tuple[str, str, str]:
    """The paper's Table 1 landing, max height and (epochs, loss) of a variant, or dashes where it has no row."""
    paper = PAPER_TABLE1.get(variant)
    if paper is None:
        return ("–", "–", "–")
    return (
        f"{paper.landing_yd:.2f}",
        "–" if paper.max_height_yd is None else f"{paper.max_height_yd:.2f}",
        f"{paper.epochs}, {LOSS[paper.loss]}",
    )


def _table1_row(run: RunEvaluation) -> tuple[Any, ...]:
    """One run's Table 1 row: how it trained, its errors, its gap to the nominal world, the paper's row beside."""
    return (
        f"{DISPLAY.get(run.variant, run.variant)} (`{run.name}`)",
        f"{run.epochs_trained} ({run.best_epoch})",
        LOSS[run.config.loss],
        *metres_yards(run.errors.mean_landing_m),
        *metres_yards(run.errors.mean_abs_apex_m),
        _gap_cell(run.world_gap),
        *_paper_cells(run.variant),
        int(np.isfinite(run.errors.landing_m).sum()),
        _minutes(run.train_seconds),
    )


TABLE1_HEADER = (
    "model (run)",
    "epochs (best)",
    "loss",
    "L_p m",
    "L_p yd",
    "L_h m",
    "L_h yd",
    "vs nominal world m",
    "paper L_p yd",
    "paper L_h yd",
    "paper epochs, loss",
    "val shots",
    "train time",
)


def _table1_lines(runs: list[RunEvaluation], val: ValidationSet) -> list[str]:
    """The validation set, Table 1 (runs in the paper's order) and what its 'vs nominal world' column means."""
    return [
        f"Validation: {len(val)} shots of `{val.path.name}` (rows marked `val`, after the training filters).",
        "",
        "### Table 1: mean landing error (L_p) and mean absolute max-height error (L_h) on validation",
        "",
        *table(TABLE1_HEADER, [_table1_row(run) for run in sorted(runs, key=_order)], align="lrlrrrrrrrlrr"),
        "",
        (
            "'vs nominal world': mean landing distance / max-height difference between the model and the reference "
            "world in the nominal floor's conditions, on the same recorded launches (the model-form error alone)."
        ),
    ]


def _noise_floor_lines(floors: list[Floor]) -> list[str]:
    """The reference world's own errors on the recorded launches, one row a floor."""
    return [
        "",
        "### Noise floor: the reference world itself, fed the recorded (noisy) launches",
        "",
        *table(
            ("floor", "conditions", "L_p m", "L_p yd", "L_h m", "L_h yd"),
            ((f.name, f.description, *metres_yards(f.landing_m), *metres_yards(f.max_height_m)) for f in floors),
            align="llrrrr",
        ),
    ]


def _bundle_lines(bundle: BundleCheck) -> list[str]:
    """The shipped bundle's errors through the runtime path and the torch path, and how far the two differ."""
    return [
        "",
        f"### Shipped bundle `{bundle.bundle}` ({bundle.variant}) through the runtime path",
        "",
        *table(
            ("path", "L_p m", "L_p yd", "L_h m", "L_h yd"),
            (
                (
                    "NumPy + ONNX Runtime (`flight.flyer.Flyer`)",
                    *metres_yards(bundle.numpy_errors.mean_landing_m),
                    *metres_yards(bundle.numpy_errors.mean_abs_apex_m),
                ),
                (
                    "torch float64, same weights",
                    *metres_yards(bundle.torch_errors.mean_landing_m),
                    *metres_yards(bundle.torch_errors.mean_abs_apex_m),
                ),
            ),
            align="lrrrr",
        ),
        "",
        (
            "Largest per-shot difference between the two paths: landing "
            f"{bundle.max_landing_difference_m * 1e3:.3f} mm, "
            f"max height {bundle.max_apex_difference_m * 1e3:.3f} mm (the runtime's apex lies between the steps, "
            "on the parabola through the highest one and its neighbours, up to about g dt^2/8 = 12 mm above the "
            f"torch path's highest step); {bundle.not_landed} shots did not land within t_sim in the runtime path."
        ),
    ]


def render(runs: list[RunEvaluation], floors: list[Floor], val: ValidationSet, bundle: BundleCheck | None) -> str:
    """Markdown: Table 1 with the paper's numbers, the noise floors, and the shipped bundle's runtime check."""
    lines = _table1_lines(runs, val) + _noise_floor_lines(floors)
    if bundle is not None:
        lines += _bundle_lines(bundle)
    return "\n".join(lines) + "\n"


@dataclass
class EvaluationReport:
    """Everything `golfflight evaluate` computed and wrote."""

    runs: list[RunEvaluation]
    floors: list[Floor]
    bundle: BundleCheck | None
    markdown: str
    figures: list[Path]


def run_evaluation(
    data: str | os.PathLike,
    runs: Sequence[str | os.PathLike],
    out_dir: str | os.PathLike,
    bundle: str | os.PathLike | None = None,
    progress: bool = True,
) -> EvaluationReport:
    """Evaluate runs (and a bundle) on the file's validation shots; write OUT/training.md's generated section and
    OUT/figures/fig6_errors.png, fig7_coefficients.png. With `progress`, a bar over the runs and each later step go
    to standard error."""
    torch.set_flush_denormal(True)
    out_dir = Path(out_dir)
    val = load_validation(data)
    evaluations = [evaluate_run(run, val) for run in progress_bar(runs, "runs", unit="run", shown=progress)]
    progress_step("the reference world's noise floor...", progress)
    air, described = nominal_conditions(val)
    floors = noise_floors(val, air, described)
    for evaluation in evaluations:
        evaluation.world_gap = gap(evaluation.prediction, floors[0].prediction)
    progress_step(f"the bundle {bundle} through the runtime path...", progress and bundle is not None)
    check = check_bundle(bundle, val) if bundle is not None else None
    progress_step("figures...", progress)
    written, summary = write_figures(evaluations, floors, val, air, out_dir / "figures")
    markdown = render(evaluations, floors, val, check) + (f"\n{summary}\n" if summary else "")
    write_generated_section(out_dir / "training.md", markdown, COMMAND)
    return EvaluationReport(evaluations, floors, check, markdown, written)
