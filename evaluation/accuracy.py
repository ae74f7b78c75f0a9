"""`golfflight accuracy`: three models side by side on the real data none of them may be trained on, and on the
real training sets, through the flight core the engine's batch path runs (`flight.integrator`: NumPy physics + each
bundle's ONNX graph; Ferguson 2022's quadratics through the same call).

The models: the real-data model (`--model`), the synthetic model (`--synthetic`) and Ferguson, McNally & McPhee
2022. The sets (`evaluation.accuracy_sets`): the held-out ones of `shots.heldout` (TrackMan outdoor drivers from
line 2943, rounds 3-4 of the TOUR Championship 2020); the paper's own figures for context and slow shots against
published amateur launches (`accuracy_slow`); then training sets of the real-data model: the PGA 2023 averages
(a per-club fit), the Sentry 2022 trajectories with each shot's latent wind (`accuracy_winds`), and a fine-tuning
study on the Sony Open 2022 (`accuracy_finetune`). None of these sets records its weather: every shot is flown calm,
the TOUR Championship and the PGA table in their source's air (`shots.source_air`), every model alike, the others in
each model's own air.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.evaluation.accuracy_finetune import (
    MEASURED_ROUNDS,
    TRAIN_ROUNDS,
    Finetune,
    FinetuneStudy,
    finetune_study,
)
from golfflight.evaluation.accuracy_flyers import ferguson_flyer, is_bundle, model_flyer
from golfflight.evaluation.accuracy_sets import (
    APEX_MAE_YD,
    APEX_METRICS,
    DRIVER_FILE,
    FLIGHT_METRICS,
    LANDING_ERROR,
    OUTCOMES,
    PGA_TARGETS,
    PREMIUM,
    SONY_TRAJECTORIES,
    TEE_GROUPS,
    TOUR_CHAMPIONSHIP_HELD_OUT,
    TOUR_CHAMPIONSHIP_PBP,
    TOUR_CHAMPIONSHIP_TARGET_FT,
    TOURCAST_PBP,
    TOURCAST_TRAJECTORIES,
    TRACKMAN_TARGETS,
    ClubComparison,
    Metric,
    PathErrors,
    ball_types,
    compare_clubs,
    held_out_driver_shots,
    outcome_errors,
    path_errors,
    tee_groups,
    tour_championship_shots,
)
from golfflight.evaluation.accuracy_slow import OUTCOMES as SLOW_OUTCOMES
from golfflight.evaluation.accuracy_slow import SLOW_SHOTS, fly_slow
from golfflight.evaluation.accuracy_winds import (
    Anova,
    Consistency,
    GroupWind,
    TrainingWindComparison,
    WindFit,
    compare_training_winds,
    consistency,
    fit_winds,
    group_winds,
    measured_paths,
    training_winds,
)
from golfflight.flight.constants import YARD_M
from golfflight.flight.flyer import Flyer
from golfflight.shots.markdown import table, write_generated_section
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.pbp import hole_pars
from golfflight.shots.progress import progress_step
from golfflight.shots.records import ShotSet
from golfflight.shots.reference_world import TOUR_AVERAGES_FILE, read_tour_averages
from golfflight.shots.source_air import PGA_2023_TABLE, TOUR_CHAMPIONSHIP_2020
from golfflight.shots.tourcast import load_tourcast, read_flights
from golfflight.shots.trackman import ConversionReport

__all__ = [
    "COMMAND", "DRIVER_FILE", "OUTCOMES", "PATH_FIGURE", "PGA_TARGETS", "TOURCAST_PBP", "TOURCAST_TRAJECTORIES",
    "AccuracyReport", "ball_types", "compare_clubs", "ferguson_flyer", "model_flyer", "outcome_errors",
    "path_errors", "per_model", "run_accuracy",
]

COMMAND = "accuracy"
PATH_FIGURE = "accuracy_tourcast_path_error.png"
PATH_TIMES_S = (1.0, 2.0, 3.0, 4.0, 5.0)
MIN_HOLE_SHOTS = 4
"""Holes (in a round) listed in the latent-wind table: those with at least this many fitted shots."""

PAPER_TABLE_1 = (("Phys-Q (L_p + L_h)", 6.63, 1.64), ("NN (landing point straight from the launch)", 5.24, None),
                 ("Phys-NN+ (L_p + L_h)", 4.75, 1.31))
"""The paper's Table 1 (validation set of its private 90,233 TrackMan shots, yd): landing error L_p, max height L_h."""

T = TypeVar("T")


@dataclass
class AccuracyReport:
    """The generated markdown, the figures written, and the numbers behind them, per model label."""

    markdown: str
    labels: list[str] = field(default_factory=list)
    figures: list[Path] = field(default_factory=list)
    driver: dict[str, dict[str, np.ndarray]] | None = None
    driver_shots: ShotSet | None = None
    tour_championship: dict[str, dict[str, np.ndarray]] | None = None
    pga: dict[str, ClubComparison] | None = None
    slow: dict[str, dict[str, np.ndarray]] | None = None
    tourcast: dict[str, dict[str, np.ndarray]] | None = None
    paths: dict[str, PathErrors] | None = None
    winds: dict[str, WindFit] | None = None
    training_winds: TrainingWindComparison | None = None
    study: FinetuneStudy | None = None


def _key(flyer: Flyer) -> tuple:
    """What makes two flyers fly alike: the graph and the card's step and air, or the closed-form model."""
    if is_bundle(flyer):
        physics = flyer.card.physics
        return ("onnx", flyer.card.onnx.sha256, physics.dt_s, physics.t_sim_s, physics.air_density_kg_m3)
    closed_form = getattr(flyer.model, "model", flyer.model)  # a FixedCoefficients' own model
    return ("model", repr(closed_form), flyer.dt_s, flyer.max_flight_time_s, flyer.density_kg_m3)


def per_model(flyers: Sequence[Flyer], work: Callable[[Flyer], T]) -> dict[str, T]:
    """`work` for each model, by label; a model that flies exactly like an earlier one reuses its result."""
    done: dict[tuple, T] = {}
    results = {}
    for flyer in flyers:
        key = _key(flyer)
        if key not in done:
            done[key] = work(flyer)
        results[flyer.label] = done[key]
    return results


def _missing(path: Path) -> str:
    return f"_Skipped: `{path}` not found (set `GOLFFLIGHT_SHARED_DATA` or put the shared data beside the repository)._"


def _cell(value: float, digits: int = 2, signed: bool = False) -> str:
    if value is None or not math.isfinite(value):
        return "–"
    return f"{value:+.{digits}f}" if signed else f"{value:.{digits}f}"


def _metric_rows(metrics: Sequence[Metric], errors: dict[str, dict[str, np.ndarray]], labels: Sequence[str],
                 mask: np.ndarray | None = None, targets: dict[str, str] | None = None) -> list[tuple[str, ...]]:
    rows = []
    for metric in metrics:
        cells = [_cell(metric.of(errors[label], mask), metric.digits, metric.statistic == "bias") for label in labels]
        rows.append((metric.name, *cells) + (((targets or {}).get(metric.name, ""),) if targets is not None else ()))
    return rows


def _count(errors: dict[str, np.ndarray], mask: np.ndarray | None = None, key: str = "landing_m") -> int:
    """Shots with a model and a recorded value of `key` (by default: the landing point)."""
    values = errors[key] if mask is None else errors[key][mask]
    return int(np.sum(np.isfinite(values)))


def _verdict(name: str, value: float, limit: float, unit: str) -> str:
    met = math.isfinite(value) and value <= limit
    return f"{name} {_cell(value)} {unit} (target <= {limit:g}): **{'met' if met else 'not met'}**"


def _header(flyers: Sequence[Flyer], rho_note: str) -> list[str]:
    rows = []
    for flyer in flyers:
        if is_bundle(flyer):
            card = flyer.card
            sources = getattr(card.training_data, "sources", None) or []
            trained = f"`{card.training_data.file}`" + (f" ({', '.join(s.name for s in sources)})" if sources else "")
            what = (f"`{flyer.bundle_dir}`: {card.variant}, trained on {trained}, ONNX {card.onnx.sha256[:12]}, "
                    f"card air rho {flyer.density_kg_m3:.3f} kg/m^3")
        else:
            what = (f"C_L, C_D quadratic in spin ratio, C_M = 0.011 S (`flight.coefficients.FERGUSON_2022`), "
                    f"rho {flyer.density_kg_m3:.3f} kg/m^3")
        rows.append((flyer.label, what))
    models = [f for f in flyers if is_bundle(f)]
    same = len({f.card.onnx.sha256 for f in models}) < len(models)
    lines = [
        *table(("column", "model"), rows, align="ll"),
        "",
        (
            f"Every model is flown through `flight.flyer.Flyer` (NumPy physics, forward Euler, dt "
            f"{flyers[0].dt_s:g} s, up to {flyers[0].max_flight_time_s:g} s), calm, in the air named above: {rho_note}"
        ),
    ]
    if same:
        lines += ["", "_The real-data and synthetic slots hold the same ONNX graph: their columns are identical._"]
    return lines


def _drivers(data_dir: Path, flyers: Sequence[Flyer], report: AccuracyReport) -> list[str]:
    lines = ["### TrackMan outdoor drivers (held out: lines 2943 on)", ""]
    path = data_dir / DRIVER_FILE
    if not path.is_file():
        return lines + [_missing(path)]
    shots, note = held_out_driver_shots(path)
    report.driver_shots = shots
    labels = [f.label for f in flyers]
    report.driver = per_model(flyers, lambda flyer: outcome_errors(flyer.flight(launch_problem(shots.launch())), shots))
    balls = ball_types(path)
    kinds = np.array([r.ball or balls.get(r.shot_id or "", "") for r in shots.records], dtype=object)
    premium = kinds == PREMIUM
    targets = {LANDING_ERROR.name: f"<= {TRACKMAN_TARGETS['landing']:g}",
               APEX_MAE_YD.name: f"<= {TRACKMAN_TARGETS['apex']:g}"}
    lines += [f"`{DRIVER_FILE}`: {note}.", ""]
    for title, mask, with_targets in ((f"**{PREMIUM} balls** (the target row)", premium, True),
                                      ("All balls", None, False)):
        n = [_count(report.driver[label], mask) for label in labels]
        rows = _metric_rows(FLIGHT_METRICS, report.driver, labels, mask, targets if with_targets else {})
        rows.append(("shots", *(str(k) for k in n), ""))
        lines += [title + ":", "", *table(("", *labels, "target"), rows), ""]
    counts = Counter(k or "(blank)" for k in kinds).most_common()
    lines.append(f"Ball types among the kept shots: {', '.join(f'{kind} {n}' for kind, n in counts)}.")
    lines += ["", "Targets on the Premium row:", ""]
    for label in labels:
        errors = report.driver[label]
        lines.append(
            f"- {label}: "
            + "; ".join([
                _verdict("landing error", LANDING_ERROR.of(errors, premium), TRACKMAN_TARGETS["landing"], "yd"),
                _verdict("max height MAE", APEX_MAE_YD.of(errors, premium), TRACKMAN_TARGETS["apex"], "yd"),
            ])
        )
    return lines


def _tee_group_title(name: str) -> str:
    """'par4_5' -> 'par 4-5 tee shots'."""
    return "par " + "-".join(str(par) for par in TEE_GROUPS[name]) + " tee shots"


def _tour_championship_verdict(label: str, errors: dict[str, dict[str, np.ndarray]], ferguson: str) -> str:
    """The target on all tee shots: apex MAE at most TOUR_CHAMPIONSHIP_TARGET_FT and below Ferguson 2022's."""
    metric = APEX_METRICS[0]
    mae = metric.of(errors[label])
    verdict = _verdict("apex MAE", mae, TOUR_CHAMPIONSHIP_TARGET_FT, "ft")
    if label == ferguson:
        return f"- {label}: {verdict}"
    theirs = metric.of(errors[ferguson])
    below = math.isfinite(mae) and mae < theirs
    return f"- {label}: {verdict}; below {ferguson}'s {_cell(theirs)} ft: **{'met' if below else 'not met'}**"


def _tee_group_rows(errors: dict[str, dict[str, np.ndarray]], labels: Sequence[str],
                    groups: dict[str, np.ndarray]) -> list[tuple[str, ...]]:
    """Apex MAE, bias and shot count of each group of tee shots and of them all; the target on all of them."""
    rows = []
    for title, mask in [*((_tee_group_title(n), m) for n, m in groups.items()), ("all tee shots", None)]:
        targets = {APEX_METRICS[0].name: f"<= {TOUR_CHAMPIONSHIP_TARGET_FT:g}"} if mask is None else {}
        rows += [(f"{title}: {name}", *cells) for name, *cells in _metric_rows(APEX_METRICS, errors, labels, mask,
                                                                                targets)]
        rows.append((f"{title}: shots", *(str(_count(errors[label], mask, "apex_m")) for label in labels), ""))
    return rows


def _tour_championship(data_dir: Path, flyers: Sequence[Flyer], report: AccuracyReport) -> list[str]:
    held = TOUR_CHAMPIONSHIP_HELD_OUT
    lines = [f"### TOUR Championship 2020, East Lake (held out: {held.rows()})", ""]
    path = data_dir / TOUR_CHAMPIONSHIP_PBP
    if not path.is_file():
        return lines + [_missing(path)]
    shots, note = tour_championship_shots(path)
    labels = [f.label for f in flyers]
    air = TOUR_CHAMPIONSHIP_2020.air()
    report.tour_championship = per_model(
        flyers, lambda flyer: outcome_errors(flyer.flight(launch_problem(shots.launch(), air)), shots))
    pars = hole_pars(path)
    rows = _tee_group_rows(report.tour_championship, labels, tee_groups(shots, pars))
    par_three = ", ".join(str(hole) for hole, par in pars.items() if par == 3)
    ferguson = next(f.label for f in flyers if not is_bundle(f))
    lines += [
        (
            f"`{TOUR_CHAMPIONSHIP_PBP.name}`: {note}. Every model flown in the event's air "
            f"(`shots.source_air.TOUR_CHAMPIONSHIP_2020`, rho {air.density_kg_m3:.3f} kg/m^3: "
            f"{TOUR_CHAMPIONSHIP_2020.basis}). Tee shots grouped by the par of their hole, which the file does not "
            f"name: each player's strokes on the hole less the strokes over par of its score (`textScore`; "
            f"`shots.pbp.hole_pars`) gives the par 3s, holes {par_three}."
        ),
        "",
        *table(("", *labels, "target"), rows),
        "",
        f"Targets on all tee shots (apex MAE, and below {ferguson}'s on the same shots):",
        "",
    ]
    return lines + [_tour_championship_verdict(label, report.tour_championship, ferguson) for label in labels]


PGA_OUTCOMES = (("carry", "yd"), ("max height", "yd"), ("land angle", "deg"))
"""The PGA table's outcomes, in the order of `ClubComparison` columns and PGA_TARGETS."""


def _pga_outcome(index: int, comparisons: dict[str, ClubComparison], labels: Sequence[str]) -> list[str]:
    """One outcome per club for every model, as model (error), and its MAE and bias rows against the target."""
    name, unit = PGA_OUTCOMES[index]
    first = comparisons[labels[0]]
    rows = [(club.club, f"{target:g}", *(f"{comparisons[l].model[k, index]:.1f} "
                                         f"({comparisons[l].model[k, index] - target:+.1f})" for l in labels), "")
            for k, (club, target) in enumerate(zip(first.clubs, first.targets[:, index]))]
    rows.append(("**MAE**", "", *(_cell(float(comparisons[l].mean_absolute_error[index])) for l in labels),
                 f"<= {PGA_TARGETS[index]:g}"))
    rows.append(("**bias**", "", *(_cell(float(comparisons[l].bias[index]), signed=True) for l in labels), ""))
    return [f"{name.capitalize()}, {unit}: each model's value (its error, model - TrackMan):", "",
            *table(("club", "TrackMan", *labels, "target"), rows), ""]


def _pga(data_dir: Path, flyers: Sequence[Flyer], report: AccuracyReport):
    lines = ["### PGA TOUR 2023 TrackMan averages per club (a TRAINING set: a fit, not a check)", ""]
    path = data_dir / TOUR_AVERAGES_FILE
    if not path.is_file():
        return lines + [_missing(path)], None
    clubs = read_tour_averages(path)
    labels = [f.label for f in flyers]
    air = PGA_2023_TABLE.air()
    report.pga = per_model(flyers, lambda flyer: compare_clubs(flyer, clubs, air))
    lines += [
        (
            f"Not held out (`shots.heldout`): `golfflight train-real` trains the real-data model on this table, so its "
            f"column is a training fit. Each club's average launch (launch direction and spin axis 0) against "
            f"TrackMan's average carry, max height and land angle, {len(clubs)} clubs, every model flown in the "
            f"table's air (`shots.source_air.PGA_2023_TABLE`, rho {air.density_kg_m3:.3f} kg/m^3: "
            f"{PGA_2023_TABLE.basis})."
        ),
        "",
    ]
    for index in range(len(PGA_OUTCOMES)):
        lines += _pga_outcome(index, report.pga, labels)
    lines += ["Targets (MAE):", ""]
    for label in labels:
        mae = report.pga[label].mean_absolute_error
        lines.append(f"- {label}: " + "; ".join(
            _verdict(f"{name} MAE", float(mae[i]), PGA_TARGETS[i], unit) for i, (name, unit) in enumerate(PGA_OUTCOMES)))
    return lines, clubs


def _paper() -> list[str]:
    rows = [(name, f"{landing:.2f}", "–" if height is None else f"{height:.2f}")
            for name, landing, height in PAPER_TABLE_1]
    return [
        "### The paper's figures (context)",
        "",
        "Table 1 of the paper: validation error on its own private set of 90,233 TrackMan shots (the most recent "
        "10 %), in yards. A different data set from every set above (other players, balls, ranges and weather), so "
        "these numbers are a scale for ours, not a score to compare with directly.",
        "",
        *table(("model (paper)", "landing error, yd", "max height MAE, yd"), rows),
    ]


def _slow(flyers: Sequence[Flyer], report: AccuracyReport) -> list[str]:
    labels = [f.label for f in flyers]
    report.slow = per_model(flyers, fly_slow)
    rows = []
    for index, shot in enumerate(SLOW_SHOTS):
        launch = f"{shot.name}: {shot.launch_angle_deg:g} deg, {shot.spin_rpm:,.0f} rpm"
        for key, name in SLOW_OUTCOMES:
            digits = 1
            rows.append((f"{launch}, {name}" if key == "carry" else f"… {name}",
                         *(_cell(float(report.slow[l][key][index]), digits) for l in labels), shot.published[key]))
    lines = [
        "### Slow shots against published amateur launches",
        "",
        "Ball speed as named, launch angle and spin from the sources below (launch direction and spin axis 0), calm, "
        "each model in its own air. The last column is a published outcome for that launch, where one was found.",
        "",
        *table(("shot", *labels, "published"), rows),
        "",
        "Sources:",
        "",
    ]
    lines += [f"- {shot.name}: {shot.source}" for shot in SLOW_SHOTS]
    return lines


def _sentry(data_dir: Path, flyers: Sequence[Flyer], out: Path, figures_dir: Path, report: AccuracyReport) -> list[str]:
    from golfflight.evaluation import figures

    lines = ["### PGA TOUR trajectories, 2022 Sentry at Kapalua (a TRAINING set of the real-data model)", ""]
    trajectory_file, pbp_file = data_dir / TOURCAST_TRAJECTORIES, data_dir / TOURCAST_PBP
    if not (trajectory_file.is_file() and pbp_file.is_file()):
        return lines + [_missing(trajectory_file if not trajectory_file.is_file() else pbp_file)]
    conversion = load_tourcast(trajectory_file, pbp_file)
    shots = ShotSet([r for r in conversion.records if r.shot_id in conversion.trajectories])
    trajectories = [conversion.trajectories[s] for s in shots.column("shot_id")]
    labels = [f.label for f in flyers]

    def evaluate(flyer: Flyer):
        flight = flyer.flight(launch_problem(shots.launch(), keep_states=True))
        return outcome_errors(flight, shots), path_errors(flight, trajectories)

    results = per_model(flyers, evaluate)
    report.tourcast = {label: results[label][0] for label in labels}
    report.paths = {label: results[label][1] for label in labels}
    rows = _metric_rows(FLIGHT_METRICS, report.tourcast, labels)
    for t in PATH_TIMES_S:
        rows.append((f"path error at {t:g} s, median m", *(
            _cell(float(np.median(report.paths[l].at(t)))) if len(report.paths[l].at(t)) else "–" for l in labels)))
    rows.append(("shots", *(str(_count(report.tourcast[l])) for l in labels)))
    first = labels[0]
    figure = figures.path_error(
        report.paths[first].times_s,
        report.paths[first].errors_m,
        Path(figures_dir).resolve() / PATH_FIGURE,
        f"{first} vs TrackMan trajectories, 2022 Sentry ({len(shots)} tee shots)",
    )
    report.figures.append(figure)
    lines += [
        (
            f"Not held out: `golfflight train-real` trains the real-data model on these shots, so its column is a "
            f"training error, shown for the full-path comparison and the winds. `{TOURCAST_TRAJECTORIES.name}` joined "
            f"with `{TOURCAST_PBP.name}` for spin: {conversion.report.rows_in} flights, {len(shots)} with a measured "
            "spin and a complete polynomial (spin axis derived from the initial lift). Path error: 3-D distance between "
            "the model's position and the polynomial's at the same time since launch."
        ),
        "",
        *table(("", *labels), rows),
        "",
        f"![path error, {first}]({os.path.relpath(figure, Path(out).resolve().parent)})",
        "",
    ]
    return lines + _winds(trajectory_file, conversion, shots, flyers, report)


def _anova_cells(result: Anova) -> tuple[str, ...]:
    p = "–" if not math.isfinite(result.p) else (f"{result.p:.2g}" if result.p >= 1e-4 else "<1e-4")
    return (_cell(result.within_sd), _cell(result.between_sd),
            "–" if not math.isfinite(result.f) else f"{result.f:.1f} ({p})", _cell(result.between_fraction))


def _winds(trajectory_file: Path, conversion, shots: ShotSet, flyers: Sequence[Flyer],
           report: AccuracyReport) -> list[str]:
    flights = read_flights(trajectory_file, ConversionReport(str(trajectory_file)))
    tracked = {f.shot_id: f.measured_time_s for f in flights}
    ids = list(shots.column("shot_id"))
    labels = [f.label for f in flyers]

    def fit(flyer: Flyer) -> WindFit:
        return fit_winds(flyer, measured_paths(ids, shots.launch(), conversion.trajectories, tracked, flyer.dt_s))

    report.winds = per_model(flyers, fit)
    quality = [
        (label, str(len(w.shot_ids)), _cell(float(np.median(w.rms_calm_m))), _cell(float(np.median(w.rms_fit_m))),
         _cell(float(np.median(np.hypot(w.x_mps, w.y_mps)))), str(w.evaluations))
        for label, w in report.winds.items()
    ]
    lines = [
        "#### Latent winds: does one wind fit the players on the same hole?",
        "",
        (
            "With each model fixed, every shot gets its own uniform wind (x right, y down the target line, m/s): the "
            "least-squares fit (`scipy.optimize.least_squares`) of the model's positions to the radar's at the "
            "integrator's step times, up to the radar-tracked time of the shot (beyond it the polynomial is TrackMan's "
            "extrapolation). The fitted wind also absorbs whatever the model gets wrong for that launch; if it is the "
            "weather, the shots of one hole in one round agree, and the holes differ."
        ),
        "",
        *table(("model", "shots", "median RMS path error calm, m", "with its fitted wind, m",
                "median fitted wind, m/s", "flights flown"), quality),
        "",
        "Per round: spread of the shots' winds within a hole (pooled SD), spread of the hole means across the round's "
        "holes (SD), one-way ANOVA F (p) and the share of the variance between holes (SS_between / SS_total), per "
        "component; the last row of each model pools the whole event (every hole and round a group):",
        "",
    ]
    rows = []
    results: dict[str, Consistency] = {label: consistency(report.winds[label]) for label in labels}
    for label in labels:
        result = results[label]
        for name, (x, y) in [*result.rounds.items(), ("all rounds", result.event)]:
            rows.append((label, name, f"{x.n_groups} ({x.n_shots})", *_anova_cells(x), *_anova_cells(y)))
    lines += table(("model", "round", "holes (shots)", "x: within SD", "x: SD of hole means", "x: F (p)",
                    "x: between share", "y: within SD", "y: SD of hole means", "y: F (p)", "y: between share"), rows)
    groups = {label: {g.group: g for g in group_winds(report.winds[label])} for label in labels}
    listed = [g for g in groups[labels[0]].values() if g.n >= MIN_HOLE_SHOTS]

    def describe(wind: GroupWind | None) -> str:
        if wind is None:
            return "–"
        return (f"{wind.speed_mps:.1f} m/s from {wind.from_deg:.0f} deg (SD {_cell(wind.sd_x_mps, 1)}, "
                f"{_cell(wind.sd_y_mps, 1)})")

    lines += [
        "",
        f"Holes with at least {MIN_HOLE_SHOTS} fitted shots: mean wind (speed and the direction it blows from, "
        "0 = headwind, 90 = from the right; `flight.wind.Wind.from_components`) and the within-hole SD of x, y:",
        "",
        *(table(("round-hole", "shots", *labels),
                [(g.group, str(g.n), *(describe(groups[l].get(g.group)) for l in labels)) for g in listed])
          if listed else ["_None._"]),
        "",
        _wind_answer(results, labels),
    ]
    lines += ["", *_training_wind_lines(flyers[0], groups[labels[0]], report)]
    return lines


def _wind_answer(results: dict[str, Consistency], labels: Sequence[str]) -> str:
    """The numbers' own answer: in how many rounds with several holes the hole means differ (p < 0.05), and how
    the within-hole spread compares with the spread of the hole means."""
    parts = []
    for label in labels:
        tested = [(x, y) for x, y in results[label].rounds.values() if x.n_groups >= 2]
        if not tested:
            parts.append(f"{label}: no round has two holes with shots, so nothing to compare")
            continue
        significant = [sum(1 for pair in tested if pair[axis].p < 0.05) for axis in (0, 1)]
        within = [float(np.mean([pair[axis].within_sd for pair in tested])) for axis in (0, 1)]
        between = [float(np.mean([pair[axis].between_sd for pair in tested])) for axis in (0, 1)]
        parts.append(
            f"{label}: the hole means differ (p < 0.05) in {significant[0]} of {len(tested)} rounds for x and "
            f"{significant[1]} of {len(tested)} for y; within a hole the shots scatter by {within[0]:.2f} (x) and "
            f"{within[1]:.2f} (y) m/s SD against {between[0]:.2f} and {between[1]:.2f} m/s between the hole means"
        )
    return "In numbers: " + "; ".join(parts) + "."


def _training_wind_lines(flyer: Flyer, fitted: dict[str, GroupWind], report: AccuracyReport) -> list[str]:
    if not is_bundle(flyer):
        return []
    entries = training_winds(flyer.bundle_dir)
    if entries is None:
        return [f"_No `training_conditions.json` beside `{flyer.bundle_dir}`: the comparison with the winds the model "
                "was trained with is skipped._"]
    comparison = compare_training_winds(entries, list(fitted.values()))
    report.training_winds = comparison
    return [
        (
            f"`{flyer.bundle_dir}/training_conditions.json` holds {comparison.n_training_groups} group winds; "
            f"{comparison.n_groups} of them are Sentry holes fitted here. Correlation of the training winds with the "
            f"fitted group means: x {_cell(comparison.correlation_x)}, y {_cell(comparison.correlation_y)} (NaN with "
            f"fewer than 3 groups); mean difference (training - fitted) x "
            f"{_cell(comparison.mean_difference_x, 2, True)}, y {_cell(comparison.mean_difference_y, 2, True)} m/s."
        )
    ]


def _summary_rows(errors: dict[str, np.ndarray]) -> list[tuple[str, ...]]:
    rows = []
    for key, (name, unit) in OUTCOMES.items():
        values = errors[key][np.isfinite(errors[key])]
        if not len(values):
            continue
        bias, mae = float(np.mean(values)), float(np.mean(np.abs(values)))
        if unit == "m":
            bias_cell = "–" if key == "landing_m" else f"{bias / YARD_M:+.2f} yd"
            mae_cell = f"{mae / YARD_M:.2f} yd"
        else:
            bias_cell, mae_cell = f"{bias:+.2f} {unit}", f"{mae:.2f} {unit}"
        rows.append((name, str(len(values)), bias_cell, mae_cell))
    return rows


def _study(data_dir: Path, flyer: Flyer, clubs, epochs: int, finetune: Finetune | None,
           report: AccuracyReport, progress: bool) -> list[str]:
    lines = ["### Fine-tuning on a tour event's early rounds (Sony Open 2022)", ""]
    path = data_dir / SONY_TRAJECTORIES
    if not path.is_file():
        return lines + [_missing(path)]
    if epochs <= 0:
        return lines + ["_Skipped (no epochs asked for)._"]
    if finetune is None:
        return lines + ["_Skipped (no fine-tuning given: it needs the training side, `model_export.finetune`)._"]
    conversion = load_tourcast(path, None, estimate_spin=True)
    shots = ShotSet(conversion.records)
    try:
        study = finetune_study(flyer, shots, clubs, finetune, epochs=epochs, progress=progress)
    except ValueError as error:
        return lines + [f"_Skipped: {error}._"]
    report.study = study
    before = {row[0]: row for row in _summary_rows(study.before)}
    after = {row[0]: row for row in _summary_rows(study.after)}
    rows = [(name, before[name][1], before[name][2], before[name][3], after[name][2], after[name][3])
            for name in before if name in after]
    outcome = (f"best epoch {study.best_epoch}, exported" if study.improved
               else "no epoch beat the base model on the validation round: the base model is kept")
    tried = ", ".join(f"lr {lr:g}: {error / YARD_M:.2f} yd (epoch {epoch})" for lr, (error, epoch) in
                      study.validation.items())
    lines += [
        (
            f"`{SONY_TRAJECTORIES.name}` ({len(shots)} tee shots; no pbp file with spin exists for this event, so "
            "every spin is the loader's ESTIMATE from the initial lift, and the spin axis is derived from it). "
            f"`golfflight finetune` from the {flyer.label} on rounds {'-'.join(map(str, TRAIN_ROUNDS))} "
            f"({study.n_train} train + {study.n_val} validation shots, split by the command's own rule: the latest "
            f"session, here a round, picks the best epoch), {study.epochs} epochs, batch {study.batch_size}, at "
            f"each of {len(study.validation)} learning rates; the rate kept is the one with the lowest validation "
            f"landing error (base model {study.base_validation_m / YARD_M:.2f} yd; {tried}): lr {study.lr:g}, "
            f"{outcome}. Measured: rounds {'-'.join(map(str, MEASURED_ROUNDS))} ({study.n_measured} shots), never "
            "seen by the fine-tuning or any choice in it."
        ),
        "",
        *table(("outcome (rounds 3-4)", "shots", "bias before", "MAE before", "bias after", "MAE after"), rows),
    ]
    if study.pga_after is not None:
        mae, bias = study.pga_after.mean_absolute_error, study.pga_after.bias
        lines += ["", (f"The fine-tuned model on the PGA 2023 table, in the table's air: MAE (bias) "
                       f"{mae[0]:.2f} ({bias[0]:+.2f}) yd carry, {mae[1]:.2f} ({bias[1]:+.2f}) yd max height, "
                       f"{mae[2]:.2f} ({bias[2]:+.2f}) deg land angle.")]
    return lines


def run_accuracy(
    bundle: str | os.PathLike,
    out: str | os.PathLike,
    figures_dir: str | os.PathLike,
    data_dir: str | os.PathLike | None = None,
    finetune_epochs: int = 30,
    synthetic: str | os.PathLike | None = None,
    finetune: Finetune | None = None,
    progress: bool = True,
) -> AccuracyReport:
    """Compare the real-data model `bundle`, the `synthetic` one (default: the same bundle) and Ferguson 2022 on every
    real set found under `data_dir` (default: the shared data folder), run the fine-tuning study with `finetune`
    (`model_export.finetune.finetune`; None skips it), and write OUT's generated section and the path-error figure;
    missing sets are announced. With `progress`, each set's step goes to standard error as it starts."""
    data_dir = Path(data_dir) if data_dir is not None else shared_data_dir()
    real = model_flyer(bundle, "real-data model")
    flyers: list[Flyer] = [
        real,
        model_flyer(synthetic if synthetic is not None else bundle, "synthetic model"),
        ferguson_flyer(real.dt_s, real.max_flight_time_s),
    ]
    report = AccuracyReport("", labels=[f.label for f in flyers])
    lines = _header(flyers, "none of these sets records its weather; the TOUR Championship and the PGA table are "
                            "flown in their own air (`shots.source_air`), every model alike.")
    lines += ["", "## Held-out sets (never trained on, never used to choose a model; `shots.heldout`)", ""]
    progress_step("the held-out TrackMan drivers...", progress)
    lines += _drivers(data_dir, flyers, report)
    progress_step("the TOUR Championship 2020...", progress)
    lines += ["", *_tour_championship(data_dir, flyers, report)]
    progress_step("slow shots...", progress)
    lines += ["", "## Context", "", *_paper(), "", *_slow(flyers, report)]
    lines += ["", "## Training data and studies", ""]
    progress_step("the PGA TOUR 2023 averages...", progress)
    pga_lines, clubs = _pga(data_dir, flyers, report)
    lines += [*pga_lines, ""]
    progress_step("the Sentry 2022 paths and each shot's wind...", progress)
    lines += _sentry(data_dir, flyers, Path(out), Path(figures_dir), report)
    progress_step("the fine-tuning study on the Sony Open 2022...", progress)
    lines += ["", *_study(data_dir, real, clubs, finetune_epochs, finetune, report, progress)]
    report.markdown = "\n".join(lines) + "\n"
    write_generated_section(out, report.markdown, COMMAND)
    return report
