"""Accuracy of a shipped bundle on real data it never saw, through the runtime path (NumPy physics + ONNX Runtime).

Three real sets, read by path from the shared data folder (never copied): TrackMan's PGA TOUR 2023 averages per
club, the outdoor TrackMan driver shots, and the PGA TOUR TrackMan trajectories of the 2022 Sentry. None records
the weather, so every shot is flown calm in one stated air. A fine-tuning study adapts the model to the first half
of the driver shots and measures the second half before and after.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from model_export.data import MIN_APEX_M
from service.air import Air
from service.constants import YARD_M
from service.flight import Flight, simulate
from service.onnx_coefficients import OnnxCoefficients
from service.physics import initial_state
from shots.markdown import table, write_generated_section
from shots.paths import shared_data_dir
from shots.records import ShotSet, write_shots
from shots.reference_world import CALIBRATION_AIR, TOUR_AVERAGES_FILE, ClubAverage, read_tour_averages
from shots.tourcast import load_tourcast
from shots.trackman import load_trackman, read_table

COMMAND = "accuracy"
DRIVER_FILE = Path("real/trackman_driver_sessions/data.csv")
TOURCAST_TRAJECTORIES = Path("real/pga_tourcast_trackman/shot_trajectory/shot_trajectory_2021_016_656.csv")
TOURCAST_PBP = Path("real/pga_tourcast_trackman/pbp/pbp_2021_016_656.csv")
PATH_FIGURE = "accuracy_tourcast_path_error.png"
PATH_TIMES_S = (1.0, 2.0, 3.0, 4.0, 5.0)
PGA_TARGETS = (3.0, 2.0, 2.0)
"""Mean absolute error the default model must reach on the PGA table: carry (yd), max height (yd), land angle (deg)."""


class ModelFlyer:
    """A bundle flown through `service.flight.simulate` with its ONNX coefficient graph, at its card's step and
    simulated time, calm, in one air (its density and, through the graph's Reynolds scale, its viscosity)."""

    def __init__(self, bundle: str | os.PathLike) -> None:
        self.bundle = Path(bundle)
        self.coefficients = OnnxCoefficients(bundle)
        self.card = self.coefficients.card

    @property
    def density_kg_m3(self) -> float:
        """The card's air density: the air the model was trained to treat as nominal."""
        return self.card.physics.air_density_kg_m3

    def fly(self, launch: dict[str, np.ndarray], air: Air | None = None, keep_states: bool = False) -> Flight:
        """Fly launches calm in `air` (default: the card's air)."""
        physics = self.card.physics
        density = self.density_kg_m3 if air is None else float(air.density_kg_m3)
        viscosity = physics.kinematic_viscosity_m2_s if air is None else air.kinematic_viscosity_m2_s
        return simulate(
            initial_state(**launch),
            self.coefficients.in_air(viscosity),
            density,
            dt=physics.dt_s,
            t_max=physics.t_sim_s,
            keep_states=keep_states,
        )


@dataclass
class ClubComparison:
    """Model and TrackMan carry (yd), max height (yd) and land angle (deg) per club [n, 3]."""

    clubs: list[ClubAverage]
    model: np.ndarray
    density_kg_m3: float

    @property
    def targets(self) -> np.ndarray:
        return np.array([[c.carry_yd, c.max_height_yd, c.land_angle_deg] for c in self.clubs])

    @property
    def mean_absolute_error(self) -> np.ndarray:
        return np.mean(np.abs(self.model - self.targets), axis=0)

    @property
    def bias(self) -> np.ndarray:
        return np.mean(self.model - self.targets, axis=0)


def compare_clubs(flyer: ModelFlyer, clubs: Sequence[ClubAverage], air: Air | None = None) -> ClubComparison:
    """Fly each club's average launch (launch direction and spin axis 0) and compare with TrackMan's averages."""
    n = len(clubs)
    launch = {
        "ball_speed_mps": np.array([c.ball_speed_mps for c in clubs]),
        "launch_angle_deg": np.array([c.launch_angle_deg for c in clubs]),
        "launch_direction_deg": np.zeros(n),
        "spin_rpm": np.array([c.spin_rpm for c in clubs]),
        "spin_axis_deg": np.zeros(n),
    }
    density = flyer.density_kg_m3 if air is None else float(air.density_kg_m3)
    flight = flyer.fly(launch, air)
    model = np.stack([flight.carry_m / YARD_M, flight.apex_m / YARD_M, flight.landing_angle_deg], axis=1)
    return ClubComparison(list(clubs), model, density)


OUTCOMES = {
    "carry_m": ("carry", "m"),
    "side_m": ("side", "m"),
    "landing_m": ("landing point (distance)", "m"),
    "apex_m": ("max height", "m"),
    "landing_angle_deg": ("land angle", "deg"),
    "flight_time_s": ("flight time", "s"),
}
"""Outcome errors reported for real shots: key -> (name, unit)."""


def outcome_errors(flight: Flight, shots: ShotSet) -> dict[str, np.ndarray]:
    """Per-shot model - recorded errors of every outcome in OUTCOMES (NaN where not recorded or not landed);
    the landing-point error is the unsigned distance between the two landing points."""
    x, y = shots.column("carry_x_m"), shots.column("carry_y_m")
    return {
        "carry_m": flight.carry_m - np.hypot(x, y),
        "side_m": flight.lateral_m - x,
        "landing_m": np.hypot(flight.landing_position[:, 0] - x, flight.landing_position[:, 1] - y),
        "apex_m": flight.apex_m - shots.column("apex_m"),
        "landing_angle_deg": flight.landing_angle_deg - shots.column("landing_angle_deg"),
        "flight_time_s": flight.flight_time_s - shots.column("flight_time_s"),
    }


def _summary_rows(errors: dict[str, np.ndarray]) -> list[tuple[str, ...]]:
    rows = []
    for key, (name, unit) in OUTCOMES.items():
        values = errors[key][np.isfinite(errors[key])]
        if not len(values):
            continue
        bias, mae = float(np.mean(values)), float(np.mean(np.abs(values)))
        if unit == "m":
            bias_cell = "–" if key == "landing_m" else f"{bias:+.2f} m ({bias / YARD_M:+.2f} yd)"
            mae_cell = f"{mae:.2f} m ({mae / YARD_M:.2f} yd)"
        else:
            bias_cell, mae_cell = f"{bias:+.2f} {unit}", f"{mae:.2f} {unit}"
        rows.append((name, str(len(values)), bias_cell, mae_cell))
    return rows


def outcome_table(errors: dict[str, np.ndarray]) -> list[str]:
    """Markdown table of mean bias (model - recorded) and mean absolute error per outcome."""
    return table(("outcome", "shots", "mean bias", "mean abs error"), _summary_rows(errors))


@dataclass
class PathErrors:
    """3-D position error (m) between the model's flight and the measured path, for the shots in flight at each time."""

    times_s: np.ndarray
    errors_m: list[np.ndarray]

    def at(self, time_s: float) -> np.ndarray:
        return self.errors_m[int(np.argmin(np.abs(self.times_s - time_s)))]


def path_errors(flight: Flight, trajectories: Sequence[np.ndarray]) -> PathErrors:
    """Compare the model's states (every step, relative to its start point) with each measured trajectory [T, 4] of
    t, x, y, z (relative to the start), interpolated to the step times; a shot counts while both are in the air."""
    if flight.states is None or flight.times_s is None:
        raise ValueError("the flight was simulated without keep_states")
    positions = np.stack([s.position for s in flight.states]) - flight.states[0].position[None]
    model_end = np.where(flight.landed, flight.flight_time_s, np.inf)
    errors = []
    for i, t in enumerate(flight.times_s):
        in_air = [j for j, path in enumerate(trajectories) if t < min(model_end[j], path[-1, 0])]
        measured = np.array(
            [[np.interp(t, trajectories[j][:, 0], trajectories[j][:, k]) for k in (1, 2, 3)] for j in in_air]
        ).reshape(-1, 3)
        errors.append(np.linalg.norm(positions[i, in_air] - measured, axis=-1))
    return PathErrors(np.asarray(flight.times_s), errors)


def path_table(paths: PathErrors, times_s: Sequence[float] = PATH_TIMES_S) -> list[str]:
    """Markdown table of the median and 90th percentile 3-D position error at given times."""
    rows = []
    for t in times_s:
        e = paths.at(t)
        if len(e):
            p50, p90 = np.percentile(e, [50, 90])
            rows.append(
                (
                    f"{t:g} s",
                    str(len(e)),
                    f"{p50:.2f} m ({p50 / YARD_M:.2f} yd)",
                    f"{p90:.2f} m ({p90 / YARD_M:.2f} yd)",
                )
            )
    return table(("time", "shots in flight", "median error", "90th percentile"), rows)


def measured_driver_shots(path: str | os.PathLike) -> tuple[ShotSet, str]:
    """The outdoor (radar-tracked) driver shots of a TrackMan export whose apex reaches the training filter's 8 yd
    (malformed rows are left out, as the loader reports), and a sentence saying what was kept."""
    conversion = load_trackman(path, skip_bad_rows=True)
    shots = ShotSet(conversion.records)
    apex = shots.column("apex_m")
    landed = ~np.isnan(shots.column("carry_x_m")) & ~np.isnan(shots.column("carry_y_m"))
    keep = landed & (apex >= MIN_APEX_M)
    note = (
        f"{conversion.report.rows_in} rows; {conversion.report.kept} measured outdoor flights (radar track >= 90 % "
        f"of the flight, launch complete and in range); {int(keep.sum())} of them with a carry and a max height of "
        "at least 8 yd (the training filter)"
    )
    return shots.subset(keep), note


def ball_types(path: str | os.PathLike) -> dict[str, str]:
    """The 'Ball' cell of every row of a TrackMan export, keyed like the loader's shot_id (the file line number),
    read by the loader's own table reader (which also skips an optional 'sep=,' first line)."""
    header, _, rows = read_table(Path(path))
    if "Ball" not in header:
        return {}
    column = header.index("Ball")
    return {str(line): row[column].strip() for line, row in rows if len(row) > column}


@dataclass
class FinetuneStudy:
    """Held-out driver shots before and after fine-tuning on the first half, and what it did to the PGA table."""

    n_train: int
    n_val: int
    n_held_out: int
    epochs: int
    lr: float
    batch_size: int
    best_epoch: int | None
    improved: bool
    before: dict[str, np.ndarray]
    after: dict[str, np.ndarray]
    pga_after: ClubComparison | None = None


def finetune_study(
    flyer: ModelFlyer,
    shots: ShotSet,
    clubs: Sequence[ClubAverage] | None,
    epochs: int = 30,
    lr: float = 3e-4,
    batch_size: int = 64,
    val_fraction: float = 0.2,
) -> FinetuneStudy:
    """Fine-tune on the first half of the shots in file order (its last `val_fraction` picks the best epoch) and
    compare the second half before and after. Everything is written to a temporary directory, then deleted."""
    from model_export.finetune import assign_split, finetune

    order = np.argsort([int(s) for s in shots.column("shot_id")], kind="stable")
    half = len(order) // 2
    first, second = (ShotSet([shots.records[i] for i in part]) for part in (order[:half], order[half:]))
    launch = second.launch()
    before = outcome_errors(flyer.fly(launch), second)
    with tempfile.TemporaryDirectory(prefix="golfflight-finetune-") as work:
        train_file = Path(work) / "first_half.csv"
        split = assign_split(first, val_fraction)
        write_shots(train_file, split.records)
        result = finetune(flyer.bundle, train_file, Path(work) / "bundle", epochs, lr, batch_size, progress=False)
        tuned = ModelFlyer(Path(work) / "bundle") if result.improved else flyer
        after = outcome_errors(tuned.fly(launch), second)
        pga_after = compare_clubs(tuned, clubs) if clubs else None
    return FinetuneStudy(
        n_train=result.run.data.n_train,
        n_val=result.run.data.n_val,
        n_held_out=len(second),
        epochs=epochs,
        lr=lr,
        batch_size=batch_size,
        best_epoch=None if result.run.best is None else int(result.run.best["epoch"]),
        improved=result.improved,
        before=before,
        after=after,
        pga_after=pga_after,
    )


@dataclass
class AccuracyReport:
    """The generated markdown, the figures written, and the headline numbers."""

    markdown: str
    figures: list[Path] = field(default_factory=list)
    pga: ClubComparison | None = None
    driver: dict[str, np.ndarray] | None = None
    tourcast: dict[str, np.ndarray] | None = None
    paths: PathErrors | None = None
    study: FinetuneStudy | None = None


def _missing(path: Path) -> str:
    return f"_Skipped: `{path}` not found (set `GOLFFLIGHT_SHARED_DATA` or put the shared data beside the repository)._"


def _club_lines(comparison: ClubComparison, at_table_air: ClubComparison) -> list[str]:
    rows = []
    for club, model, target in zip(comparison.clubs, comparison.model, comparison.targets):
        rows.append((club.club, *(f"{m:.1f} / {t:g} / {m - t:+.1f}" for m, t in zip(model, target))))
    mae, bias = comparison.mean_absolute_error, comparison.bias
    rows.append(("**MAE (bias)**", *(f"**{e:.2f}** ({b:+.2f})" for e, b in zip(mae, bias))))
    other = at_table_air.mean_absolute_error
    rows.append(
        (
            f"MAE (bias) in TrackMan's normalisation air, rho {at_table_air.density_kg_m3:.3f}",
            *(f"{e:.2f} ({b:+.2f})" for e, b in zip(other, at_table_air.bias)),
        )
    )
    met = all(e <= t for e, t in zip(mae, PGA_TARGETS))
    verdict = "met" if met else "NOT met"
    return [
        *table(("club", "carry yd (model / TM / err)", "max height yd", "land angle deg"), rows, align="lrrr"),
        "",
        (
            f"Target MAE <= {PGA_TARGETS[0]:g} yd carry, {PGA_TARGETS[1]:g} yd max height, {PGA_TARGETS[2]:g} deg land "
            f"angle in the card's air (rho {comparison.density_kg_m3:.3f}), what the service flies a shot without "
            f"conditions in: **{verdict}**."
        ),
    ]


def _ball_lines(shots: ShotSet, errors: dict[str, np.ndarray], balls: dict[str, str]) -> list[str]:
    kinds = np.array([balls.get(s, "") for s in shots.column("shot_id")])
    rows = []
    for kind in sorted(set(kinds), key=lambda k: -np.sum(kinds == k)):
        mask = kinds == kind
        carry = errors["carry_m"][mask]
        rows.append(
            (
                kind or "(blank)",
                str(int(mask.sum())),
                f"{np.nanmean(carry) / YARD_M:+.2f}",
                f"{np.nanmean(np.abs(carry)) / YARD_M:.2f}",
                f"{np.nanmean(errors['landing_m'][mask]) / YARD_M:.2f}",
                f"{np.nanmean(errors['apex_m'][mask]) / YARD_M:+.2f}",
            )
        )
    return table(("ball", "shots", "carry bias yd", "carry MAE yd", "landing error yd", "max height bias yd"), rows)


def _study_lines(study: FinetuneStudy) -> list[str]:
    before = {row[0]: row for row in _summary_rows(study.before)}
    after = {row[0]: row for row in _summary_rows(study.after)}
    rows = [
        (name, before[name][1], before[name][2], before[name][3], after[name][2], after[name][3])
        for name in before
        if name in after
    ]
    outcome = (
        f"best epoch {study.best_epoch}, exported"
        if study.improved
        else "no epoch beat the base model on the validation rows: the base model is kept"
    )
    lines = [
        (
            f"Fine-tuned on the first half of the shots in file order ({study.n_train} train + {study.n_val} validation "
            f"rows, the last {study.n_val} picking the best epoch), {study.epochs} epochs at lr {study.lr:g}, batch "
            f"{study.batch_size}; {outcome}. Held out: the second half ({study.n_held_out} shots)."
        ),
        "",
        *table(("outcome (held-out half)", "shots", "bias before", "MAE before", "bias after", "MAE after"), rows),
    ]
    if study.pga_after is not None:
        mae = study.pga_after.mean_absolute_error
        lines += [
            "",
            (
                f"The fine-tuned model on the PGA 2023 table: MAE {mae[0]:.2f} yd carry, {mae[1]:.2f} yd max "
                f"height, {mae[2]:.2f} deg land angle."
            ),
        ]
    return lines


def run_accuracy(
    bundle: str | os.PathLike,
    out: str | os.PathLike,
    figures_dir: str | os.PathLike,
    data_dir: str | os.PathLike | None = None,
    finetune_epochs: int = 30,
) -> AccuracyReport:
    """Evaluate `bundle` on every real set found under `data_dir` (default: the shared data folder), run the
    fine-tuning study, write OUT's generated section and the path-error figure; missing sets are announced."""
    from model_export import figures

    data_dir = Path(data_dir) if data_dir is not None else shared_data_dir()
    flyer = ModelFlyer(bundle)
    card = flyer.card
    report = AccuracyReport("")
    rho = flyer.density_kg_m3
    lines = [
        (
            f"Model: `{Path(bundle)}` ({card.variant}, trained on `{card.training_data.file}`, checkpoint of epoch "
            f"{card.training.best_epoch}, validation landing error {card.validation.landing_error_yd:.2f} yd). Runtime "
            f"path: NumPy physics + ONNX Runtime, Euler dt {card.physics.dt_s:g} s. Every shot is flown calm in the "
            f"card's air, rho {rho:.3f} kg/m^3 (none of these sets records its weather); the PGA table also in "
            f"TrackMan's normalisation air (25 C, sea level, rho {CALIBRATION_AIR.density_kg_m3:.3f} kg/m^3), where the "
            "reference world was calibrated to it."
        ),
        "",
        "### PGA TOUR 2023 TrackMan averages per club",
        "",
    ]
    averages = data_dir / TOUR_AVERAGES_FILE
    clubs = read_tour_averages(averages) if averages.is_file() else None
    if clubs:
        report.pga = compare_clubs(flyer, clubs)
        lines += _club_lines(report.pga, compare_clubs(flyer, clubs, CALIBRATION_AIR))
    else:
        lines.append(_missing(averages))

    lines += ["", "### Outdoor TrackMan driver shots", ""]
    driver_file = data_dir / DRIVER_FILE
    driver = None
    if driver_file.is_file():
        driver, note = measured_driver_shots(driver_file)
        report.driver = outcome_errors(flyer.fly(driver.launch()), driver)
        lines += [
            f"`{DRIVER_FILE}`: {note}.",
            "",
            *outcome_table(report.driver),
            "",
            "By ball type:",
            "",
            *_ball_lines(driver, report.driver, ball_types(driver_file)),
        ]
    else:
        lines.append(_missing(driver_file))

    lines += ["", "### PGA TOUR TrackMan trajectories (2022 Sentry, Kapalua)", ""]
    trajectory_file, pbp_file = data_dir / TOURCAST_TRAJECTORIES, data_dir / TOURCAST_PBP
    if trajectory_file.is_file() and pbp_file.is_file():
        conversion = load_tourcast(trajectory_file, pbp_file)
        shots = ShotSet([r for r in conversion.records if r.shot_id in conversion.trajectories])
        flight = flyer.fly(shots.launch(), keep_states=True)
        report.tourcast = outcome_errors(flight, shots)
        report.paths = path_errors(flight, [conversion.trajectories[s] for s in shots.column("shot_id")])
        figure = figures.path_error(
            report.paths.times_s,
            report.paths.errors_m,
            Path(figures_dir).resolve() / PATH_FIGURE,
            f"{card.variant} vs TrackMan trajectories, 2022 Sentry ({len(shots)} tee shots)",
        )
        report.figures.append(figure)
        lines += [
            (
                f"`{TOURCAST_TRAJECTORIES.name}` joined with `{TOURCAST_PBP.name}` for spin: {conversion.report.rows_in} "
                f"flights, {len(shots)} with a measured spin and a complete polynomial (spin axis derived from the "
                "initial lift)."
            ),
            "",
            *outcome_table(report.tourcast),
            "",
            "Full path: 3-D distance between the model's position and the polynomial's at the same time since launch:",
            "",
            *path_table(report.paths),
            "",
            f"![path error]({os.path.relpath(figure, Path(out).resolve().parent)})",
        ]
    else:
        lines.append(_missing(trajectory_file if not trajectory_file.is_file() else pbp_file))

    lines += ["", "### Fine-tuning on part of the driver shots", ""]
    if driver is not None and finetune_epochs > 0:
        report.study = finetune_study(flyer, driver, clubs, epochs=finetune_epochs)
        lines += _study_lines(report.study)
    else:
        lines.append("_Skipped: needs the driver shots._" if driver is None else "_Skipped (no epochs asked for)._")
    report.markdown = "\n".join(lines) + "\n"
    write_generated_section(out, report.markdown, COMMAND)
    return report
