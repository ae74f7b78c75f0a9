"""`prove`: hide each effect (and none, a two-effect combination, effects outside the library) in synthetic
recordings at random realistic sizes and directions, diagnose them blind and score the diagnoses.

Two campaigns: `truth="model"` hides the effects in flights of the model being diagnosed, as the service flies it
(its own output plus launch-monitor noise: the method against the model users run); `truth="reference"` hides
them in the reference world's flights (the model-form campaign: what the diagnosed model's own difference from
that physics adds). Scores: detection rate (and false alarms on at least CLEAN_SETS clean sets), which effect was
named against which was hidden (confusion), the fitted parameters' error relative to the hidden effect's size, and
the share of the excess held-out error removed. Every case uses several seeds: new sessions, launches, noise and
effect size each time. `campaign="triples"` hides three library effects at once (`TRIPLES`) beside clean sets, and
scores whether all three are named and all three fitted within 10 % of their sizes; `campaign="pairs"` two (`PAIRS`),
scored alike.
"""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from golfflight.discovery.choices import CAMPAIGNS, CLEAN_SETS, DENSITY_ONLY_WORLDS, SHOTS, TRUTHS, Campaign, Truth
from golfflight.discovery.conceal import NOMINAL_AIR, NOMINAL_CONTEXT, OUTSIDE_EFFECT, conceal
from golfflight.discovery.diagnose import diagnose
from golfflight.discovery.effects import AIR_VARIANTS, BALL, DENSITY_ONLY, EFFECTS, LIBRARY, Draw, equivalent_altitude_m
from golfflight.discovery.effects.ball import DRAG_AND_LIFT
from golfflight.discovery.effects.parts import sign, uniform
from golfflight.discovery.form import LearnedForm, flown_by_rk4, learn_form
from golfflight.discovery.model import MIN_T_MAX_S, FlightModel
from golfflight.discovery.outside import HEIGHT_GUST, HIGH_SPIN_LIFT_LOSS, LOW_SPEED_DRAG, OUTSIDE
from golfflight.discovery.recordings import from_shot_set
from golfflight.flight.coefficients import QuadraticSpinRatio
from golfflight.flight.flyer import FixedCoefficients, Flyer
from golfflight.flight.integrator import RUNGE_KUTTA_4
from golfflight.flight.reference_aero import CALIBRATED
from golfflight.shots.files import write_text_atomic
from golfflight.shots.markdown import write_generated_section
from golfflight.shots.progress import progress_bar
from golfflight.shots.records import ShotSet

COMBINATION = ("wind", "ball_speed_bias")
"""The two-effect case: a carry-alike pair that only the other observables can separate."""

TRIPLES = (
    ("wind", "ball_speed_bias", "spin_axis_bias"),
    ("air_density", "launch_angle_bias", "spin_bias"),
    ("landing_elevation", "lift_scale", "launch_direction_bias"),
)
"""The three-effect cases of the `triples` campaign: a condition, a launch bias and a third effect of another kind
in each, so every library effect family is hidden beside two others."""

LOG_WIND = "wind, log profile"
"""A wind stated at 10 m that follows the log profile (slower low down, faster high up): `wind` must be named with
its uniform-equivalent speed (the stated speed x the profile's mean factor along the flights), and the service
settings must give back the stated 10 m speed."""

VENUE_RATIOS = (0.75, 0.95)
"""The density-only world's venue air, as a share of ICAO density (about 500 to 2,600 m)."""
PAIRS = (
    ("wind", "ball_speed_bias"),
    ("air_density", "launch_angle_bias"),
    ("landing_elevation", "spin_axis_bias"),
    ("spin_bias", "lift_scale"),
    ("drag_scale", "launch_direction_bias"),
    ("wind", "spin_bias"),
)
"""The two-effect cases of the `pairs` campaign: each library family beside another, so that the step from a single
to a pair is measured on its own (issue 41: pairs had regressed after the triple step)."""

HIGH_VENUE = "1,900 m air, density only"
"""The baseline campaign's fixed case: a venue at about 1,900 m (0.776 x ICAO) flown as density alone, against a
sea-level baseline: the air must be named, within 0.03."""
HIGH_VENUE_RATIO = 0.776
FINE_STEP_S = 0.01
"""The RK4 step of the worlds not flown as the service flies (Ferguson 2022's, `density-only-rk4`)."""
HIGH_VENUE_REAL = "1,900 m real air, against three lower venues"
"""The baseline campaign's case of a launch monitor taken up a mountain: the same 0.776 x ICAO as real air (the
Reynolds number with the density), against a baseline recorded at three lower venues (`LOWER_VENUES`, their air
recorded): the air must be named, within 0.03."""
LOWER_VENUES = (0.97, 0.93, 0.89)
"""The airs (x ICAO, real air) of that case's baseline venues, one session in three at each: within 10 % of each
other, about 250 to 1,000 m at 15 degC."""
HIGH_VENUES = {HIGH_VENUE: (DENSITY_ONLY, (1.0,)), HIGH_VENUE_REAL: ("air_density", LOWER_VENUES)}
"""Each high-venue case: its air variant (ratio HIGH_VENUE_RATIO) and the airs of its baseline's venues."""

BALL_AT_VENUE = "another ball, the air recorded"
"""The baseline campaign's case of two balls compared at one venue: another ball, the new session's air recorded
with its shots (the baseline's calm ICAO air), so that air cannot stand in for a ball whose drag and lift move alike.
Scored apart from the concealed changes, since its air is not concealed."""

BASELINE_LAUNCHES = 1
"""The baseline session's launch stream (`conceal`'s launch_seed): the new session's players and clubs, other
launches and noise, in the truth world's calm ICAO air."""


def command(
    model_spec: str,
    truth: Truth,
    only: str | None = None,
    seeds: int | None = None,
    campaign: Campaign = "library",
    shots: int = SHOTS,
) -> str:
    """The `golfflight` command whose generated section the tables go to: one per model and campaign (and case
    filter and session size), so such sections coexist."""
    extra = "" if campaign == "library" else f" --campaign {campaign}"
    extra += "" if only is None else f" --cases '{only}'"
    extra += f" --seeds {seeds}" if extra else ""
    extra += f" --shots {shots}" if shots != SHOTS else ""
    return f"prove --model {model_spec} --truth {truth}{extra}"


def _moved_crisis(rng: np.random.Generator) -> dict[str, float]:
    """The drag crisis 12-25 % above or below the calibrated critical Reynolds number."""
    return {"value": float(CALIBRATED.critical_reynolds * (1 + sign(rng) * rng.uniform(0.12, 0.25)))}


OUTSIDE_DRAWS: dict[str, Draw] = {
    OUTSIDE_EFFECT: _moved_crisis,
    LOW_SPEED_DRAG: uniform(rise=(0.08, 0.2), speed_mps=(35.0, 50.0)),
    HIGH_SPIN_LIFT_LOSS: uniform(loss=(0.15, 0.35), spin_ratio=(0.2, 0.28)),
    HEIGHT_GUST: uniform(rate_mps_per_m=(0.15, 0.35), height_m=(6.0, 14.0), from_deg=(0.0, 360.0)),
}
"""Realistic sizes of the effects outside the library (a library effect's are its own, `Effect.hiding.draw`)."""


def draw_effect(name: str, rng: np.random.Generator) -> dict[str, float]:
    """A realistic size and direction of one effect, in the report's conventions."""
    effect = EFFECTS.get(name)
    if effect is not None and effect.hiding is not None:
        return effect.hiding.draw(rng)
    return OUTSIDE_DRAWS[name](rng)


def cases(truth: Truth = "model", campaign: Campaign = "library") -> list[tuple[str, tuple[str, ...]]]:
    """(case name, hidden effects): clean, every library effect, the combination, the effects outside the library
    (the reference world takes the moved drag crisis and the gust that grows with height; the model's own flights
    every one of `discovery.outside.OUTSIDE`) and, in the reference world, a log-profile wind; or, in the `triples`
    campaign, clean and the three-effect cases `TRIPLES` (`pairs`: the two-effect cases `PAIRS`)."""
    if campaign in ("pairs", "triples"):
        return [("clean", ())] + [("+".join(group), group) for group in (PAIRS if campaign == "pairs" else TRIPLES)]
    if campaign == "baseline":
        return baseline_cases(truth)
    library = [(e.name, (e.name,)) for e in LIBRARY]
    if truth in DENSITY_ONLY_WORLDS:  # the air is recorded there: an air finding is wrong by construction
        library = [(name, effects) for name, effects in library if name not in AIR_VARIANTS]
    if truth == "reference":
        library.append((LOG_WIND, ("wind",)))
    outside = (OUTSIDE_EFFECT, HEIGHT_GUST) if truth == "reference" else OUTSIDE
    return (
        [("clean", ())]
        + library
        + [("+".join(COMBINATION), COMBINATION)]
        + [(f"outside: {name}", (name,)) for name in outside]
    )


def baseline_cases(truth: Truth) -> list[tuple[str, tuple[str, ...]]]:
    """The baseline campaign's cases: no change, each venue condition and monitor bias, another ball, and a high
    venue flown as density alone (none of the air cases where the world's venue air is recorded)."""
    changes = [e.name for e in LIBRARY if e.kind in ("venue", "monitor")] + [BALL.name]
    if truth in DENSITY_ONLY_WORLDS:
        changes = [name for name in changes if name not in AIR_VARIANTS]
    air_told = []  # the cases whose air is set against the baseline's: none where the venue air is always recorded
    if truth not in DENSITY_ONLY_WORLDS:
        air_told = [(case, (variant,)) for case, (variant, _) in HIGH_VENUES.items()] + [(BALL_AT_VENUE, (BALL.name,))]
    return [("clean", ())] + [(name, (name,)) for name in changes] + air_told


_LEARNED: dict[tuple[str, str, int, int, tuple[float, ...]], LearnedForm] = {}


def baseline_form(
    model: FlightModel, truth: Truth, n_shots: int, seed: int, venues: tuple[float, ...] = (1.0,)
) -> LearnedForm:
    """What the clean baseline session of a seed's players and clubs teaches (other launches and noise, the truth
    world's calm air: ICAO, or one session in len(venues) at each venue's real air, x ICAO, recorded with its
    shots); the same for every case of the seed, so learned once and kept for the seed's cases."""
    key = (model.name, truth, n_shots, seed, venues)
    if key not in _LEARNED:
        shots = venue_baseline(truth_world(truth, model), n_shots, seed, venues)
        while len(_LEARNED) >= 2:  # a seed's two baselines (ICAO, lower venues); the seeds run one after another
            _LEARNED.pop(next(iter(_LEARNED)))
        _LEARNED[key] = learn_form(from_shot_set(shots, source=f"clean baseline seed {seed}"), model, seed=seed)
    return _LEARNED[key]


def venue_baseline(world: FlightModel | None, n_shots: int, seed: int, venues: tuple[float, ...]) -> ShotSet:
    """The clean baseline of a seed's players and clubs (`BASELINE_LAUNCHES`), in ICAO air (venues (1.0,)) or with
    its k-th session flown at venues[k % len(venues)] x ICAO as real air, that air recorded with its shots (15 degC,
    the equivalent altitude)."""
    if venues == (1.0,):
        return conceal({}, n_shots, seed, model=world, launch_seed=BASELINE_LAUNCHES).shots
    records = []
    for k, ratio in enumerate(venues):
        hidden = {"air_density": {"ratio": ratio}} if ratio != 1.0 else {}
        flown = conceal(hidden, n_shots, seed, model=world, launch_seed=BASELINE_LAUNCHES).shots
        sessions = sorted({r.session for r in flown.records})
        here = set(sessions[k :: len(venues)])
        records += recorded_in([r for r in flown.records if r.session in here], ratio)
    return ShotSet(records)


def recorded_in(records: list, ratio: float) -> list:
    """The shot records with a venue's air written on them: dry air at 15 degC at the standard-atmosphere height whose
    density is `ratio` x ICAO (what the service reads back as that density and its viscosity)."""
    air = {"temperature_c": 15.0, "altitude_m": equivalent_altitude_m(ratio, NOMINAL_CONTEXT), "humidity_pct": 0.0}
    return [r.model_copy(update=air) for r in records]


def recorded_air(case: str, venue: dict[str, dict[str, float]]) -> float | None:
    """The air (x ICAO) written on a new session's shots: the density-only world's venue air, the baseline's ICAO
    air where two balls are compared at one venue (`BALL_AT_VENUE`), else none (the air left blank)."""
    if venue:
        return venue[DENSITY_ONLY]["ratio"]
    return 1.0 if case == BALL_AT_VENUE else None


def _outside(effects: tuple[str, ...] | dict) -> bool:
    return any(name == OUTSIDE_EFFECT or name in OUTSIDE for name in effects)


def internal(name: str, parameters: dict[str, float]) -> np.ndarray:
    """A hidden or fitted effect as the library's internal parameter vector (`Effect.internal`)."""
    return EFFECTS[name].internal(parameters)


def truth_world(truth: Truth, model: FlightModel) -> FlightModel | None:
    """The world the effects are hidden in: the diagnosed model (its own flights, or in density-only venue air, as
    the service flies it or by RK4 at 0.01 s), Ferguson 2022's closed-form coefficients (RK4 at 0.01 s), or None for
    the reference world."""
    if truth == "reference":
        return None
    if truth == "ferguson":
        return ferguson_world()
    if truth == "density-only-rk4":  # without the service's forward-Euler step error (`form.accurately_flown`)
        return flown_by_rk4(model, FINE_STEP_S)
    return model


def ferguson_world() -> FlightModel:
    """Ferguson, McNally & McPhee 2022's coefficients as a world (RK4 at 0.01 s, ICAO air): the best open model,
    another form than any trained bundle."""
    air = NOMINAL_AIR
    flyer = Flyer(
        FixedCoefficients(QuadraticSpinRatio()),
        dt_s=FINE_STEP_S,
        max_flight_time_s=MIN_T_MAX_S,
        density_kg_m3=float(air.density_kg_m3),
        kinematic_viscosity_m2_s=float(air.kinematic_viscosity_m2_s),
        rule=RUNGE_KUTTA_4,
    )
    return FlightModel("Ferguson 2022 (RK4, dt 0.01 s)", flyer)


def fitted_as(name: str, fitted: dict[str, dict[str, float]]) -> str | None:
    """The fitted effect that stands for the hidden `name`: itself, or one of its stand-ins (`Effect.stand_ins`: for
    air either variant); None if not fitted."""
    if name in fitted:
        return name
    stand_ins = EFFECTS[name].stand_ins if name in EFFECTS else ()
    return next((other for other in stand_ins if other in fitted), None)


def relative_error(name: str, fitted: dict[str, float], hidden: dict[str, float]) -> float:
    """|fitted - hidden| / |hidden - no effect| in the library's internal parameters."""
    truth = internal(name, hidden)
    size = np.linalg.norm(truth - EFFECTS[name].null)
    return float(np.linalg.norm(internal(name, fitted) - truth) / size)


@dataclass
class Run:
    """One blind diagnosis of one concealed set."""

    case: str
    seed: int
    hidden: dict[str, dict[str, float]]
    n_shots: int
    n_sessions: int
    systematic: bool
    named: str
    correct: bool
    fitted: dict[str, dict[str, float]]
    uncertainty: dict[str, dict[str, float]]
    parameter_error: dict[str, float]
    before_error: float
    after_error: float
    explained_fraction: float | None
    absorbs_noise: bool
    heldout_before: dict[str, float]
    heldout_after: dict[str, float]
    ambiguities: list[str]
    seconds: float
    named_kinds: list[str] = field(default_factory=list)
    """The kinds of the effects named (`effects.Kind`: venue, monitor, form), one per effect."""


def expected_label(case_effects: tuple[str, ...]) -> str:
    if not case_effects:
        return "none"
    if _outside(case_effects):
        return "unlisted"
    return "+".join(sorted(case_effects))


def run_case(
    model: FlightModel,
    case: str,
    effects: tuple[str, ...],
    seed: int,
    n_shots: int,
    truth: Truth = "model",
    against_baseline: bool = False,
) -> Run:
    """Conceal (in the model's own flights or the reference world's), diagnose blind, score; `against_baseline`: a
    clean baseline session of the same players and clubs in the world's calm ICAO air (other launches and noise; at
    three lower venues for `HIGH_VENUE_REAL`) is diagnosed against first, and the set is diagnosed for what changed
    since."""
    rng = np.random.default_rng(10_000 + seed)
    hidden = {name: draw_effect(name, rng) for name in effects}
    venues = (1.0,)
    if case in HIGH_VENUES:
        variant, venues = HIGH_VENUES[case]
        hidden = {variant: {"ratio": HIGH_VENUE_RATIO}}
    profile = "log" if case == LOG_WIND else "uniform"
    world, venue = truth_world(truth, model), {}
    if truth in DENSITY_ONLY_WORLDS:
        venue = {DENSITY_ONLY: {"ratio": float(rng.uniform(*VENUE_RATIOS))}}
    concealed = conceal({**hidden, **venue}, n_shots, seed, wind_profile=profile, model=world)
    shots = concealed.shots
    recorded = recorded_air(case, venue)
    if recorded is not None:
        shots = ShotSet(recorded_in(shots.records, recorded))
    recordings = from_shot_set(shots, source=f"concealed {case} seed {seed}")
    baseline = baseline_form(model, truth, n_shots, seed, venues) if against_baseline else None
    started = time.perf_counter()
    report = diagnose(recordings, model, seed=seed, progress=False, baseline=baseline).report
    seconds = time.perf_counter() - started
    fitted = {e.name: dict(e.parameters) for e in report.effects}
    if profile == "log":
        stated = hidden["wind"]["speed_mps"]
        hidden["wind"] = {**hidden["wind"], "speed_mps": stated * concealed.wind_factor, "speed_10m_mps": stated}
        station = report.service_settings.wind_at_station
        if "wind" in fitted and station is not None:
            fitted["wind"]["speed_10m_mps"] = station.speed_mps
    names = sorted(fitted)
    named = "+".join(names) if report.systematic else "none"
    if "unlisted" in fitted:
        named = "unlisted"
    errors = {
        name: relative_error(name, fitted[found], hidden[name])
        for name in hidden
        if name in EFFECTS and (found := fitted_as(name, fitted)) is not None
    }
    return Run(
        case,
        seed,
        hidden,
        len(recordings),
        recordings.n_sessions,
        report.systematic,
        named,
        named == expected_label(effects),
        fitted,
        {e.name: e.uncertainty for e in report.effects},
        errors,
        report.heldout.before_error,
        report.heldout.after_error,
        report.heldout.explained_fraction,
        report.heldout.absorbs_noise,
        report.heldout.before,
        report.heldout.after,
        [a.note for a in report.ambiguities],
        seconds,
        [e.kind for e in report.effects],
    )


def prove(
    model: FlightModel,
    seeds: int = 4,
    n_shots: int = SHOTS,
    report: Callable[[str], None] | None = None,
    only: str | None = None,
    truth: Truth = "model",
    clean_sets: int = CLEAN_SETS,
    progress: bool = True,
    campaign: Campaign = "library",
) -> list[Run]:
    """Every case of the campaign (or those whose name matches the regular expression `only`) at `seeds` seeds,
    the clean case `clean_sets` times; `report` gets a line on each run as it ends, and with `progress` a bar over
    the runs goes to standard error (`shots.progress`)."""
    planned = [
        (case, effects, seed)
        for case, effects in cases(truth, campaign)
        if only is None or re.search(only, case)
        for seed in range(seeds if effects else clean_sets)
    ]
    if campaign == "baseline":  # a seed's cases share its baseline session, learned once
        planned.sort(key=lambda plan: plan[2])
    runs = []
    for case, effects, seed in progress_bar(planned, "concealed sets", unit="set", shown=progress):
        run = run_case(model, case, effects, seed, n_shots, truth, against_baseline=campaign == "baseline")
        runs.append(run)
        if report:
            report(
                f"{case:32s} seed {seed}: named {run.named:28s} systematic {run.systematic!s:5s} "
                f"param err {', '.join(f'{v:.1%}' for v in run.parameter_error.values()) or '-':>8s} "
                f"explained {'-' if run.explained_fraction is None else f'{run.explained_fraction:.1%}'} "
                f"({run.seconds:.1f} s)"
            )
    return runs


def _fmt_hidden(hidden: dict[str, dict[str, float]]) -> str:
    return (
        "; ".join(f"{k}: " + ", ".join(f"{p} {v:.4g}" for p, v in params.items()) for k, params in hidden.items())
        or "-"
    )


def _among(run: Run) -> bool:
    """The hidden effects are all among the named ones (or the outside effect was reported as unlisted)."""
    fitted = run.fitted if run.systematic else {}
    hidden = {"unlisted"} if _outside(run.hidden) else set(run.hidden)
    return bool(hidden) and all(fitted_as(name, fitted) is not None for name in hidden)


def _within(run: Run, tolerance: float = 0.1) -> bool:
    """Every hidden effect was fitted with its parameters within `tolerance` of its size (a missed effect is not)."""
    return set(run.parameter_error) == set(run.hidden) and all(e <= tolerance for e in run.parameter_error.values())


def _ball_drag_and_lift_within(run: Run, tolerance: float = 0.1) -> bool:
    """Another ball named with its drag and lift scales within `tolerance` of their part of its size: how it scores
    with its spin decay, which the outcomes cannot measure, left to its ± (`ball.DRAG_AND_LIFT`)."""
    fitted = run.fitted.get(BALL.name) if run.systematic else None
    if fitted is None:
        return False
    hidden = np.array([run.hidden[BALL.name][k] for k in DRAG_AND_LIFT])
    got = np.array([fitted[k] for k in DRAG_AND_LIFT])
    return bool(np.linalg.norm(got - hidden) <= tolerance * np.linalg.norm(hidden - 1.0))


def _acted_on(run: Run) -> bool:
    """A venue condition, a launch-monitor bias or another ball was named: the findings a user acts on."""
    return run.systematic and any(kind in ("venue", "monitor", "ball") for kind in run.named_kinds)


def _air_within(run: Run, tolerance: float = 0.03) -> bool:
    """Air density (either variant) was named with its ratio within `tolerance` of the hidden one."""
    fitted = run.fitted if run.systematic else {}
    (variant, hidden), = run.hidden.items()
    found = fitted_as(variant, fitted)
    return found is not None and abs(fitted[found]["ratio"] - hidden["ratio"]) <= tolerance


def hidden_within_uncertainty(run: Run, widths: float = 2.0) -> list[bool]:
    """For each parameter of each hidden effect that was fitted: whether the hidden value lies within `widths` of the
    reported ± of the fitted one (the ± tells the truth about the error: 95 % for a calibrated one at 2)."""
    fitted = run.fitted if run.systematic else {}
    out = []
    for name, hidden in run.hidden.items():
        found = fitted_as(name, fitted)
        if found is None:
            continue
        for key, value in hidden.items():
            sd = run.uncertainty.get(found, {}).get(key)
            if key in fitted[found] and sd is not None:
                out.append(abs(fitted[found][key] - value) <= widths * sd)
    return out


def _baseline_rows(runs: list[Run]) -> list[str]:
    """The baseline campaign's headline rows: no-change sessions, the change named within 10 %, the high venue."""
    clean = [r for r in runs if r.case == "clean"]
    changed = [r for r in runs if r.case not in ("clean", BALL_AT_VENUE, *HIGH_VENUES)]
    errors = [e for r in changed for e in r.parameter_error.values()]
    covered = [c for r in runs if r.case != "clean" for c in hidden_within_uncertainty(r)]
    rows = []
    if clean:
        rows.append(
            f"| no-change sessions naming no venue condition, monitor bias or ball | "
            f"{_share([not _acted_on(r) for r in clean])} | ≥ 95 % |"
        )
    if changed:
        rows += [
            f"| the change named (beside others or not), within 10 % of its size | "
            f"{_share([_among(r) and _within(r) for r in changed])} | ≥ 90 % |",
            f"| the change named alone | {_share([r.correct for r in changed])} | - |",
            f"| parameters within 10 % of the change's size | {sum(e <= 0.1 for e in errors)} of {len(errors)} "
            f"(median error {np.median(errors):.1%}) | - |" if errors else "",
            f"| hidden values within 2 ± of the fitted ones (each parameter) | {_share(covered)} | - |"
            if covered else "",
        ]
    for case, label in ((BALL.name, "another ball"), (BALL_AT_VENUE, "another ball, the air recorded")):
        balls = [r for r in runs if r.case == case]
        if not balls:
            continue
        if case == BALL_AT_VENUE:  # scored apart from `changed`: its whole size here
            whole = _share([_among(r) and _within(r) for r in balls])
            rows.append(f"| {label}: named within 10 % of its size | {whole} | - |")
        drag_and_lift = _share([_ball_drag_and_lift_within(r) for r in balls])
        rows.append(f"| {label}: named, its drag and lift within 10 % of their size (spin decay left to its ±) | "
                    f"{drag_and_lift} | - |")
    for case in HIGH_VENUES:
        venue = [r for r in runs if r.case == case]
        if venue:
            rows.append(f"| {case}: air named within 0.03 | {_share([_air_within(r) for r in venue])} | all |")
    return [row for row in rows if row]


def _share(flags: list[bool]) -> str:
    return f"{sum(flags)} of {len(flags)} ({np.mean(flags):.0%})"


def _measure_rows(runs: list[Run], truth: Truth) -> list[str]:
    """The headline table's rows: false alarms, detection, naming, parameter error and the error removed."""
    clean = [r for r in runs if r.case == "clean"]
    hidden = [r for r in runs if r.case != "clean"]
    library = [r for r in hidden if r.case in EFFECTS]
    outside = [r for r in hidden if _outside(r.hidden)]
    triples = [r for r in hidden if len(r.hidden) == 3]
    pairs = [r for r in hidden if len(r.hidden) == 2]
    errors = [e for r in hidden for e in r.parameter_error.values()]
    fractions = [r.explained_fraction for r in hidden if r.explained_fraction is not None]
    rows = []
    form_rows = []
    if clean and truth == "model":
        rows.append(f"| false alarms on clean sets | {sum(r.systematic for r in clean)} of {len(clean)} | 0 |")
    elif clean:
        form_rows += [
            f"| clean sets called systematic (the model's form differs from this world's) | "
            f"{sum(r.systematic for r in clean)} of {len(clean)} | - |",
            f"| clean sets naming no venue condition and no monitor bias | "
            f"{_share([not _acted_on(r) for r in clean])} | ≥ 90 % |",
        ]
    if library and truth != "model":
        form_rows.append(
            "| hidden library effect named (alone or beside others), parameter within 10 % | "
            f"{_share([_among(r) and _within(r) for r in library])} | ≥ 70 % |"
        )
    if hidden:
        rows += [
            f"| detection (hidden effect present) | {sum(r.systematic for r in hidden)} of {len(hidden)} | all |",
            f"| right effect named, all hidden cases | {_share([r.correct for r in hidden])} | ≥ 90 % |",
            (
                f"| hidden effect among those named (extra effects allowed) | {sum(_among(r) for r in hidden)} of "
                f"{len(hidden)} | - |"
            ),
        ]
    if library:
        rows.insert(
            2 if clean else 1,
            f"| right effect named, library effects | {_share([r.correct for r in library])} | ≥ 95 % |",
        )
    if outside:
        rows.append(f"| outside effects reported as unlisted | {_share([r.correct for r in outside])} | ≥ 80 % |")
    if pairs:
        rows += [
            f"| two effects: both among those named | {_share([_among(r) for r in pairs])} | - |",
            f"| two effects: both fitted within 10 % of their sizes | {_share([_within(r) for r in pairs])} | - |",
        ]
    if triples:
        rows += [
            f"| three effects: all three among those named | {_share([_among(r) for r in triples])} | ≥ 80 % |",
            f"| three effects: exactly these three named | {_share([r.correct for r in triples])} | - |",
            (
                "| three effects: all three fitted within 10 % of their sizes | "
                f"{_share([_within(r) for r in triples])} | ≥ 60 % |"
            ),
        ]
    if hidden:
        rows.append(
            "| fits flagged as absorbing noise (over 100 % beyond doubt, error 25 % below the noise floor) | "
            f"{sum(r.absorbs_noise for r in hidden)} | - |"
        )
    if errors:
        rows.append(
            f"| parameters within 10 % of the effect's size | {sum(e <= 0.1 for e in errors)} of {len(errors)} "
            f"(median error {np.median(errors):.1%}) | all |"
        )
    if fractions:
        rows.append(
            f"| excess held-out error removed (median; min) | {np.median(fractions):.1%}; {min(fractions):.1%} "
            "| ≥ 70 % |"
        )
    if truth != "model":  # the targets above are the model's own flights'; a world of another form has its own two
        rows = form_rows + [row.rsplit("|", 2)[0] + "| - |" for row in rows]
    return rows


def _confusion(runs: list[Run], present: list[tuple[str, tuple[str, ...]]]) -> list[str]:
    """Hidden case (rows) against the named explanation (columns), the right cell in bold."""
    labels = sorted({r.named for r in runs} | {expected_label(e) for _, e in present}, key=lambda s: (s != "none", s))
    lines = [
        "### Confusion: hidden case (rows) vs named explanation (columns)",
        "",
        "| hidden \\ named | " + " | ".join(labels) + " |",
        "|---|" + "---:|" * len(labels),
    ]
    for case, effects in present:
        row = [r for r in runs if r.case == case]
        counts = [sum(r.named == label for r in row) for label in labels]
        cells = [
            f"**{c}**" if label == expected_label(effects) and c else (str(c) if c else "·")
            for label, c in zip(labels, counts)
        ]
        lines.append(f"| {case} | " + " | ".join(cells) + " |")
    return lines


def _per_case(runs: list[Run], present: list[tuple[str, tuple[str, ...]]]) -> list[str]:
    """Per case: named right, detected, parameter error, error removed and held-out error before and after."""
    lines = [
        "### Per case",
        "",
        (
            "| case | named right | detected | parameter error (median, max) | excess error removed (median) | "
            "held-out error before → after (median) |"
        ),
        "|---|---:|---:|---:|---:|---:|",
    ]
    for case, _ in present:
        row = [r for r in runs if r.case == case]
        errs = [e for r in row for e in r.parameter_error.values()]
        fr = [r.explained_fraction for r in row if r.explained_fraction is not None and r.systematic]
        lines.append(
            f"| {case} | {sum(r.correct for r in row)}/{len(row)} | {sum(r.systematic for r in row)}/{len(row)} | "
            + (f"{np.median(errs):.1%}, {max(errs):.1%}" if errs else "-")
            + " | "
            + (f"{np.median(fr):.1%}" if fr else "-")
            + " | "
            + f"{np.median([r.before_error for r in row]):.2f} → {np.median([r.after_error for r in row]):.2f} |"
        )
    return lines


def _every_run(runs: list[Run]) -> list[str]:
    """One row a run: what was hidden, what was named and fitted, and how far off."""
    lines = [
        "### Every run",
        "",
        "| case | seed | hidden | named | fitted | parameter error | removed |",
        "|---|---:|---|---|---|---:|---:|",
    ]
    for r in runs:
        fitted = (
            "; ".join(
                f"{k}: " + ", ".join(f"{p} {v:.4g}" for p, v in params.items() if p != "density_kg_m3")
                for k, params in r.fitted.items()
            )
            or "-"
        )
        errs = ", ".join(f"{v:.1%}" for v in r.parameter_error.values()) or "-"
        removed = "-" if r.explained_fraction is None or not r.systematic else f"{r.explained_fraction:.0%}"
        lines.append(f"| {r.case} | {r.seed} | {_fmt_hidden(r.hidden)} | {r.named} | {fitted} | {errs} | {removed} |")
    return lines


def tables(runs: list[Run], model_name: str, truth: Truth = "model", campaign: Campaign = "library") -> str:
    """The markdown tables of a prove run."""
    flown = {
        "model": "the diagnosed model's own flights",
        "reference": "the reference world's flights",
        "ferguson": "flights with Ferguson 2022's coefficients (RK4, 0.01 s)",
        "density-only": "the diagnosed model's own flights in venue air that scales density only (0.75-0.95 x ICAO, "
        "recorded)",
        "density-only-rk4": "the diagnosed model's coefficients flown by RK4 at 0.01 s in venue air that scales "
        "density only (0.75-0.95 x ICAO, recorded)",
    }[truth]
    opening = (
        f"Model diagnosed: {model_name}; effects hidden in {flown}. {len(runs)} concealed sets, "
        f"{int(np.mean([r.n_shots for r in runs]))} shots and {np.mean([r.n_sessions for r in runs]):.1f} sessions "
        f"each on average; diagnose took {np.median([r.seconds for r in runs]):.1f} s per set (median)."
    )
    present = [(case, effects) for case, effects in cases(truth, campaign) if any(r.case == case for r in runs)]
    measures = _baseline_rows(runs) if campaign == "baseline" else _measure_rows(runs, truth)
    if campaign == "baseline":
        opening += (
            " Each set is diagnosed against a clean baseline session of the same players and clubs (other launches "
            "and noise) in the world's calm ICAO air; the real-air venue's against one whose sessions were recorded at "
            f"three lower venues ({', '.join(f'{v:g}' for v in LOWER_VENUES)} x ICAO, real air, recorded)."
        )
    lines = [opening, "", "| measure | reached | target |", "|---|---:|---:|", *measures, ""]
    lines += [*_confusion(runs, present), "", *_per_case(runs, present), "", *_every_run(runs)]
    return "\n".join(lines) + "\n"


def read_runs(path: Path) -> list[Run]:
    """The runs a `--json` dump holds, to write their tables again without flying them again."""
    return [Run(**item) for item in json.loads(Path(path).read_text())]


def write_tables(
    runs: list[Run],
    markdown: Path,
    json_path: Path | None,
    model_name: str,
    command: str,
    truth: Truth = "model",
    campaign: Campaign = "library",
) -> None:
    """Put the tables into the markdown file's section of `command`; optionally dump every run as JSON."""
    write_generated_section(markdown, tables(runs, model_name, truth, campaign), command)
    if json_path is not None:
        write_text_atomic(json_path, json.dumps([asdict(r) for r in runs], indent=1) + "\n")
