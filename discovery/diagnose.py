"""`diagnose`: locate the mismatch, fit every library effect (and combinations, and a learned correction) through
the simulator, choose by held-out error with a parameter penalty, and assemble the report.

The mismatch is called systematic only when the systematic test finds structure that noise and the model's own
error do not make (`discovery.locate`: shifts of means against their standard errors, trends with the launch values
and shot order, differences between clubs and sessions, scatter beyond the expected; one Holm family) AND a fitted
correction removes a material share of the excess on held-out sessions beyond doubt. Noise alone passes neither;
a consistent shift fails the first however large the expected per-shot error is.

Selection: every single effect is fitted (from a Gauss-Newton start); once the best beats the model as is, each of
the best singles is combined with the other effects that most reduce its linearised cost (pairs), and once the best
pair beats the best single, each of the best pairs with a third (triples). A candidate replaces a simpler one only if
its held-out error is lower beyond doubt (the lower end of a session-bootstrap interval of the improvement is above
zero) and by a material share, and, against a controlled model, by more than the model's own error of response to
the simpler explanation (`Diagnoser.response_error`); a candidate with a library parameter pinned at its bound is
never chosen (`inside`). The choice is then stated in physical terms: coefficient
scales that agree as air density, and on recordings without air, air set against it on equal terms
(`Diagnoser.in_physical_terms`); a venue condition or monitor bias that moves no recorded observable by more than
the model's own error is left to the model's form (`Diagnoser.within_form`). Structure the library explanation
leaves (the test run again on its residuals) leads to the learned correction; a library effect stays beside it only
if it beats the correction alone beyond doubt. Against a baseline session (`discovery.form`) the model carries the
form the baseline taught, the coefficient scales give way to another ball, and no correction is learned: what is
named is what changed since the baseline.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np
from golfflight.discovery import correction as learned
from golfflight.discovery.as_is import AsIs, as_is
from golfflight.discovery.effects import AIR_VARIANTS, BALL, LIBRARY, REYNOLDS_SCALE, Context, Effect
from golfflight.discovery.fit import (
    MAX_FIT_SHOTS,
    SCORED_SHOTS,
    Fit,
    Problem,
    Scored,
    blocks,
    cluster_bootstrap,
    fit,
    fit_rows,
    fold_thetas,
    folds,
    heldout,
    linear_starts,
    per_shot,
    stratified_rows,
)
from golfflight.discovery.form import (
    LearnedForm,
    formed_model,
    read_along_speed,
    with_form_uncertainty,
    with_reading_uncertainty,
)
from golfflight.discovery.headline import headline
from golfflight.discovery.invariance import Halves, halves, set_aside_sentence
from golfflight.discovery.locate import has_structure, locate, trajectory_residuals, trajectory_stats
from golfflight.discovery.model import FlightModel
from golfflight.discovery.noise import RADAR_NOISE, Scatter
from golfflight.discovery.recordings import LABELS, OBSERVABLES, Recordings
from golfflight.discovery.report import MATERIAL, ambiguity, effect_results, service_settings, statement
from golfflight.discovery.schema import AirRival, Candidate, Heldout, Located, ModelInfo, Report, ScatterStat, Unlisted
from golfflight.discovery.physical import ball_agrees, restatements
from golfflight.discovery.reach import baseline_info, baseline_sentence, comparable
from golfflight.discovery.venue_air import air_explanations, air_rival, air_sentence, with_air
from golfflight.flight.wind import FAIRWAY_ROUGHNESS_M, STATION_HEIGHT_M, uniform_equivalent_factor
from golfflight.shots.progress import progress_bar, progress_step
from golfflight.shots.synth import MeasurementNoise

MIN_RELATIVE_IMPROVEMENT = MATERIAL
"""A correction must remove at least this share of the held-out error to count (materiality)."""

SINGLE_LEVEL = 0.995
"""One-sided bootstrap level for 'a correction beats the model as is' (strict: guards against false alarms)."""

COMBINATION_LEVEL = 0.975
"""One-sided bootstrap level for 'a richer candidate beats a simpler one'."""

NOISE_SPREAD = 0.25
"""How far below the noise floor a held-out error may fall by chance: clean 300-shot sets flown by the served model
scored 0.56-0.84 around a floor of about 0.70 (docs/discovery.md), so only a fit more than this share below it is
said to absorb noise."""

AT_BOUND = 1e-3
"""A library parameter within this share of its range from a bound is at the bound (`inside`)."""

PAIR_ANCHORS = 3
"""Pairs are built on the best three single effects (greedy selection on the best one alone can be misled)."""

TRIPLE_ANCHORS = 2
"""Triples are built on the best two pairs, once a pair has beaten the best single."""

EXTENSION_FITS = 2
"""Effects added to each anchor and fitted through the simulator: the most promising by linearised cost."""

MAX_FORM_ROUNDS = 3
"""Rounds of setting aside the conditions that are the model's form (`Diagnoser.model_form`): the explanation left
after one round is checked again, its values having been fitted anew."""


@dataclass
class Diagnosis:
    """The report plus the arrays the HTML plots need."""

    report: Report
    recordings: Recordings
    before: np.ndarray
    after: np.ndarray
    heldout_before: np.ndarray
    heldout_after: np.ndarray
    positions_before: np.ndarray | None
    positions_after: np.ndarray | None
    chosen: Scored | None


@dataclass(frozen=True)
class Selection:
    """What the candidates decided: the null, every candidate fitted, the choice (the null unless the mismatch is
    systematic), the systematic test's numbers, the learned correction if chosen, and structure the choice leaves."""

    null: Scored
    scored: list[Scored]
    chosen: Scored
    systematic: bool
    test: dict
    unlisted: Unlisted | None
    unexplained: list[str]


@dataclass(frozen=True)
class Corrected:
    """The recordings as the chosen explanation predicts them (the model as is when none is chosen), with the flights'
    positions and, for a wind, the log profile's uniform-equivalent factor along them."""

    outcomes: np.ndarray
    positions: np.ndarray | None
    wind_factor: float | None


def _mean_sq(z: np.ndarray) -> float:
    return float(np.nanmean(z**2)) if np.isfinite(z).any() else float("nan")


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.nanmean(values**2)))


def inside(candidate: Scored) -> bool:
    """Whether every library parameter of a candidate lies inside its bounds (the learned correction's weights
    aside): a parameter pinned at its plausible bound says the effect stands in for something outside its range, so
    such a candidate is not chosen (it stays among the candidates the report lists)."""
    for effect, block in blocks(candidate.fit):
        if learned.is_correction(effect):
            continue
        for value, parameter in zip(candidate.fit.theta[block], effect.parameters, strict=True):
            margin = AT_BOUND * (parameter.high - parameter.low)
            if not parameter.low + margin < value < parameter.high - margin:
                return False
    return True


def library_for(air_recorded: bool, wind_recorded: bool = False, against_baseline: bool = False) -> tuple[Effect, ...]:
    """The effects offered: the whole library for recordings without air; for recordings that carry their air, no
    air density (with the air recorded there is no air finding) but the Reynolds scale (`effects.REYNOLDS_SCALE`,
    the model's form: how the recordings' physics reads that air). Recordings that carry their wind get no wind
    either, as with the air: a recorded wind of 0 says the carry was flown, or computed by the launch monitor, in
    still air. Against a baseline session the model's form is the baseline's, so the coefficient scales give way to
    another ball (`effects.BALL`: drag, lift and spin decay changed as one cause)."""
    recorded = ({"wind"} if wind_recorded else set()) | (set(AIR_VARIANTS) if air_recorded else set())
    offered = tuple(e for e in LIBRARY if e.name not in recorded and not (against_baseline and e.kind == "form"))
    return offered + ((BALL,) if against_baseline else ()) + ((REYNOLDS_SCALE,) if air_recorded else ())


def located_mismatch(recordings: Recordings, start: AsIs) -> Located:
    """The systematic test on the model's residuals, along the recorded trajectories too."""
    flown = start.flown
    along = (
        trajectory_stats(list(trajectory_residuals(recordings, flown.positions, flown.dt_s).values()))
        if flown.positions is not None
        else []
    )
    outliers = {name: int(start.wild[:, j].sum()) for j, name in enumerate(OBSERVABLES) if start.wild[:, j].any()}
    return locate(recordings, start.residual, start.expected.sigma, start.use, along, outliers, start.expected.dilution)


def corrected(
    problem: Problem, chosen: Fit, predicted: np.ndarray, keep_trajectories: bool, wind_factor: bool = True
) -> Corrected:
    """Fly every shot of the problem with the chosen effects (the model's own `predicted` when none); for a wind,
    with `wind_factor`, the flights' positions give the log profile's uniform-equivalent factor."""
    if not chosen.k:
        return Corrected(predicted, None, None)
    has_wind = wind_factor and any(e.name == "wind" for e in chosen.effects)
    everyone = np.arange(len(problem.recordings))
    theta_rows = np.repeat(chosen.theta[None], len(everyone), 0)
    flown = problem.outcomes(chosen.effects, theta_rows, everyone, keep_positions=keep_trajectories or has_wind)
    factor = (
        uniform_equivalent_factor(flown.positions[..., 2], STATION_HEIGHT_M, FAIRWAY_ROUGHNESS_M) if has_wind else None
    )
    return Corrected(flown.outcomes() + problem.offset, flown.positions, factor)


def model_info(model: FlightModel, context: Context, start: AsIs, estimate_scatter: bool) -> ModelInfo:
    """The report's account of the model: its settings, the error it is expected to make and its known error."""
    expected, scatter = start.expected, start.scatter
    return ModelInfo(
        name=model.name,
        dt_s=model.flyer.dt_s,
        integrator=model.flyer.rule.name,
        density_kg_m3=context.density_kg_m3,
        model_error=expected.model,
        model_error_source=expected.model_source,
        outcome_noise=expected.outcome_noise,
        launch_noise=expected.launch_noise,
        scatter={
            name: ScatterStat(ratio=ratio, low=scatter.low[name], applied=estimate_scatter and name in scatter.applied)
            for name, ratio in scatter.ratio.items()
        },
        control=None if model.control is None else model.control.name,
        known_model_error=None
        if model.control is None
        else {name: float(-np.mean(start.offset[:, j])) for j, name in enumerate(OBSERVABLES)},
    )


def candidates(selection: Selection, context: Context) -> list[Candidate]:
    """Every candidate tried, the null among them, best score first."""
    return [
        Candidate(
            name=s.fit.name,
            effects=effect_results(s.fit, context),
            n_parameters=s.fit.k,
            heldout_error=s.error,
            penalty=s.penalty,
            score=s.score,
        )
        for s in sorted([selection.null] + selection.scored, key=lambda s: s.score)
    ]


class Diagnoser:
    """One diagnosis. Making it flies the model on the recordings (`as_is`) and sets up the problem, folds and fit
    rows every candidate shares; its methods read only those, and `run` fits, chooses and reports. With `progress`,
    each step and a bar over the fits go to standard error (`shots.progress`): a large set takes minutes.

    The model as is, the systematic test and the chosen explanation's held-out errors use every shot (`everyone`);
    candidates are fitted and scored on `problem`: every shot up to `scored_shots`, above that a stratified
    subsample of that many (`scored`, by session and club), with the least-squares fits on at most MAX_FIT_SHOTS of
    those (`rows`); the report says how many."""

    def __init__(
        self,
        recordings: Recordings,
        model: FlightModel,
        noise: MeasurementNoise = RADAR_NOISE,
        seed: int = 0,
        with_correction: bool = True,
        estimate_scatter: bool = True,
        progress: bool = True,
        scored_shots: int = SCORED_SHOTS,
        baseline: LearnedForm | None = None,
    ):
        self.started = time.perf_counter()
        self.recordings, self.model, self.baseline = recordings, model, baseline
        self.air_recorded = recordings.density_kg_m3 is not None
        self.library = library_for(self.air_recorded, recordings.wind_xy_mps is not None, baseline is not None)
        self.estimate_scatter, self.progress = estimate_scatter, progress
        # against a baseline the form it taught is held: a learned correction would trade against the change itself
        self.with_correction = with_correction and baseline is None
        self.rng = np.random.default_rng(seed)
        self.step(f"flying {len(recordings):,} recorded shots through the model and its expected error...")
        self.as_is = as_is(recordings, model, noise, seed, estimate_scatter, progress)
        start = self.as_is
        self.everyone = Problem(model, recordings, start.base, start.expected.sigma, start.use, start.offset)
        self.fold, self.grouping = folds(recordings.session)
        self.scored = stratified_rows(recordings, scored_shots, np.random.default_rng([seed, 2]))
        if len(self.scored) == len(recordings):
            self.problem, self.rows = self.everyone, fit_rows(recordings, self.rng)
        else:  # a large set: its own stratified fit rows among the scored ones
            self.problem = self.everyone.subset(self.scored)
            self.rows = stratified_rows(self.problem.recordings, MAX_FIT_SHOTS, self.rng)
        self.scored_fold = self.fold[self.scored]
        self._response_errors: dict[tuple[str, bytes], float] = {}  # memo: asked up to three times
        # what the model's response is measured against: its control, or the form the baseline cannot tell from its
        # own in another air
        self.other_reading = model.control if baseline is None else read_along_speed(model, baseline)
        self.set_aside: list[Halves] = []  # the conditions set aside as changing with the launch (`model_form`)

    def run(self) -> Diagnosis:
        """Locate the mismatch, choose its explanation, and report it with the arrays the plots need."""
        start = self.as_is
        self.step("locating the mismatch...")
        located = located_mismatch(self.recordings, start)
        selection = self.select(has_structure(located))
        if self.baseline is not None and selection.systematic:
            selection = self.counting_the_baseline(selection)
        chosen = selection.chosen
        self.step("the chosen explanation's flights and held-out errors...")
        trajectories = bool(self.recordings.trajectories)
        after = corrected(self.problem, chosen.fit, start.predicted[self.scored], trajectories)
        everywhere = (
            after
            if self.problem is self.everyone
            else corrected(self.everyone, chosen.fit, start.predicted, trajectories, wind_factor=False)
        )
        null_everywhere, chosen_everywhere = self.everywhere(selection.null), self.everywhere(chosen)
        heldout_block = self.heldout_summary(null_everywhere, chosen_everywhere)
        ambiguities = (
            ambiguity(self.problem, chosen, after.outcomes, selection.scored, self.rng) if selection.systematic else []
        )
        rival = (  # recordings without air: the venue's air set against the choice (`discovery.venue_air`)
            air_rival(self.problem, chosen, after.outcomes, selection.scored, self.score, self.rows, start.expected,
                      self.set_aside)
            if selection.systematic and not self.air_recorded
            else None
        )
        report = self.report(located, selection, after, heldout_block, with_air(ambiguities, chosen, rival), rival)
        sigma = start.expected.sigma
        return Diagnosis(
            report,
            self.recordings,
            start.predicted,
            everywhere.outcomes,
            null_everywhere.heldout_z * sigma,
            chosen_everywhere.heldout_z * sigma,
            start.flown.positions,
            everywhere.positions,
            chosen if selection.systematic else None,
        )

    def step(self, message: str) -> None:
        """Name the step that starts now on standard error, with `progress`."""
        progress_step(message, self.progress)

    def report(
        self,
        located: Located,
        selection: Selection,
        after: Corrected,
        heldout_block: Heldout,
        ambiguities: list,
        rival: AirRival | None = None,
    ) -> Report:
        """The report of a finished selection."""
        recordings, model, chosen = self.recordings, self.model, selection.chosen
        context = Context(float(np.median(self.as_is.base.density_kg_m3)), model.temperature_c)
        effects = effect_results(chosen.fit, context)
        words = statement(
            selection.systematic,
            located,
            effects,
            selection.unlisted,
            heldout_block,
            ambiguities,
            selection.scored,
            chosen,
        )
        if "varies_with_ball_speed" in selection.test:
            words += set_aside_sentence(selection.test["varies_with_ball_speed"])
        against = (
            None if self.baseline is None else baseline_info(self.baseline, recordings, self.as_is.base.density_kg_m3)
        )
        report = Report(
            recordings=recordings.source,
            n_shots=len(recordings),
            n_sessions=recordings.n_sessions,
            fit_shots=len(self.rows),
            scored_shots=len(self.scored),
            observables=list(recordings.observed_names),
            trajectories=len(recordings.trajectories),
            model=model_info(model, context, self.as_is, self.estimate_scatter),
            systematic=selection.systematic,
            systematic_test=selection.test,
            located=located,
            effects=effects,
            unlisted=selection.unlisted,
            candidates=candidates(selection, context),
            ambiguities=ambiguities,
            air_rival=rival,
            heldout=heldout_block,
            baseline=against,
            statement=("" if against is None else baseline_sentence(against, len(recordings)))
            + words
            + air_sentence(rival)
            + left_sentence(selection.unexplained)
            + control_sentence(model, self.as_is.offset, self.response_error(chosen))
            + (scatter_sentence(self.as_is.scatter) if self.estimate_scatter else "")
            + sampling_sentence(len(recordings), len(self.scored), len(self.rows)),
            service_settings=service_settings(effects, context, after.wind_factor),
            seconds=time.perf_counter() - self.started,
        )
        return report.model_copy(update={"headline": headline(report)})

    def null_candidate(self) -> Scored:
        """The model as is, scored like any candidate (no parameters, no penalty)."""
        null_z = self.problem.standardize(self.as_is.predicted[self.scored], np.arange(len(self.scored)))
        empty = Fit((), np.zeros(0), null_z, np.zeros(null_z.shape + (0,)), np.zeros((0, 0)))
        return Scored(empty, null_z, _mean_sq(null_z), 0.0)

    def everywhere(self, candidate: Scored) -> Scored:
        """A candidate scored on the shots it was chosen on, scored on every shot: each fold flown with the
        parameters its scored shots gave without it (the candidate itself where every shot was scored)."""
        if self.problem is self.everyone:
            return candidate
        result, n = candidate.fit, len(self.recordings)
        if result.k == 0:
            z = self.everyone.standardize(self.as_is.predicted, np.arange(n))
        else:
            z = heldout(self.everyone, result, self.fold, fold_thetas(result, self.scored_fold))
        error = _mean_sq(z)
        return Scored(result, z, error, error * result.k * np.log(n) / n)

    def select(self, structure: bool) -> Selection:
        """Fit the singles and pairs, choose among them, try the learned correction where structure is left, and
        call the mismatch systematic only if the test found `structure` and something beat the null."""
        null = self.null_candidate()
        singles = self.fit_singles()
        chosen, richer, test = self.choose(null, singles)
        if chosen is not null:
            chosen, restated = self.in_physical_terms(chosen, singles + richer, test)
            richer += restated
        scored = singles + richer
        for _ in range(MAX_FORM_ROUNDS):
            model_form = self.model_form(chosen, test)
            if not model_form:
                break
            chosen, refitted = self.form_instead(null, chosen, model_form, scored)
            scored += refitted
        unlisted, left = None, self.structure_left(chosen) if structure and self.with_correction else []
        if left:
            library_best = chosen
            chosen, tried, entries = self.try_correction(null, chosen)
            scored += tried
            test.update(entries)
            if self.within_form(chosen):  # its company within the model's own error: the correction alone, if any
                alone = [t for t in tried if len(t.fit.effects) == 1 and learned.is_correction(t.fit.effects[0])]
                against = max(null.error - 1.0, 0.0)
                chosen = next((t for t in alone if self.better(t, null, SINGLE_LEVEL, against=against)[0]), null)
            if any(learned.is_correction(e) for e in chosen.fit.effects):
                unlisted = learned.summary(chosen.fit, chosen.error, library_best.error)
        unexplained = left if chosen.fit.k and unlisted is None else []
        systematic = structure and chosen is not null
        test.update(
            before_error=null.error,
            structure_found=structure,
            decision="systematic" if systematic else "consistent with noise and the model's own error",
        )
        if not systematic:
            return Selection(null, scored, null, False, test, None, [])
        return Selection(null, scored, chosen, True, test, unlisted, unexplained)

    def counting_the_baseline(self, selection: Selection) -> Selection:
        """The selection with its choice's ± counting what the baseline leaves unsure: its form's own error
        (`form.with_form_uncertainty`) and, where the two readings of the form part (another air than the
        baseline's), the reading it cannot rule out (`form.with_reading_uncertainty`). The ± the report quotes; the
        choice was made before, on the fits."""
        chosen = selection.chosen
        counted = with_form_uncertainty(self.problem, chosen.fit, self.baseline, self.rows)
        if self.response_error(chosen) > 0.0:
            counted = with_reading_uncertainty(self.problem, counted, self.other_reading, self.rows)
        counted = replace(chosen, fit=counted)
        scored = [counted if s is chosen else s for s in selection.scored]
        return replace(selection, chosen=counted, scored=scored)

    def score(self, result: Fit) -> Scored:
        z = heldout(self.problem, result, self.scored_fold)
        n = len(self.scored)
        error = _mean_sq(z)
        return Scored(result, z, error, error * result.k * np.log(n) / n)

    def better(
        self, rich: Scored, simple: Scored, level: float, tolerance: float = 0.0, against: float | None = None
    ) -> tuple[bool, float, float, float]:
        """Whether `rich` beats `simple` on held-out error beyond doubt, materially (a share of `against`, default
        `simple`'s error) and by more than `tolerance` (the model's own error of response to `simple`, see
        `response_error`); (flag, gain, low, high)."""
        a, count = per_shot(simple.heldout_z)
        b, _ = per_shot(rich.heldout_z)
        draws = cluster_bootstrap(a - b, count, self.problem.recordings.session, self.rng)
        gain = float((a - b).sum() / count.sum())
        low, high = np.quantile(draws, [1 - level, level])
        against = simple.error if against is None else against
        material = gain >= max(MIN_RELATIVE_IMPROVEMENT * against, tolerance)
        return bool(low > 0 and material and rich.score < simple.score), gain, float(low), float(high)

    def claims_more(self, rich: Scored, simple: Scored) -> bool:
        """Whether `rich` adds a venue condition, monitor bias or ball to `simple`; against a baseline, one that adds
        only the model's form (the Reynolds scale that reads recorded air) does not: fitting the model's own error is
        what such a term is for, so the model's error of response does not hold it back."""
        added = [e for e in rich.fit.effects if e not in simple.fit.effects]
        return self.baseline is None or any(e.kind != "form" for e in added)

    def response_error(self, candidate: Scored) -> float:
        """How much of the candidate's remaining error is the model's own: the mean squared standardized
        difference between the model (plus its known error at the assumed conditions) and its control, both
        flown with the candidate's effects; against a baseline, between the form read along the Reynolds number
        and along the speed (`form.read_along_speed`). Zero without either or without effects.

        The control takes out the model's error at the assumed conditions only; once an effect changes them, the
        model responds to it a little differently from the physics it imitates (e.g. the bundle gains more carry
        in thin air than the reference world). A baseline teaches the form in its own airs only: in another air the
        two readings it cannot tell apart differ. A richer explanation that removes no more than that difference
        is fitting the model's error, not left-out physics."""
        control, result = self.other_reading, candidate.fit
        if control is None or result.k == 0:
            return 0.0
        key = (result.name, result.theta.tobytes())
        if key not in self._response_errors:
            everyone = np.arange(len(self.scored))
            theta_rows = np.repeat(result.theta[None], len(everyone), 0)
            truth = self.problem.outcomes(result.effects, theta_rows, everyone, model=control).outcomes()
            model = self.problem.predict(result.effects, result.theta, everyone)[0]
            z = np.where(self.problem.use, (model - truth) / self.problem.sigma, np.nan)
            self._response_errors[key] = _mean_sq(z)
        return self._response_errors[key]

    def fit_singles(self) -> list[Scored]:
        """Every library effect alone, from Gauss-Newton starts out of one Jacobian; best score first."""
        self.step(f"fitting {len(self.library)} effects...")
        starts = linear_starts(self.problem, None, self.library, self.rows)
        fits = progress_bar(
            zip(self.library, starts), "effects", total=len(self.library), unit="fit", shown=self.progress
        )
        singles = [self.score(fit(self.problem, (e,), start, self.rows)) for e, (start, _) in fits]
        return sorted(singles, key=lambda s: s.score)

    def fit_extensions(self, bases: list[Scored], anchors: int, label: str) -> list[Scored]:
        """Each of the best `anchors` candidates with the EXTENSION_FITS effects that most reduce its linearised
        cost (one Jacobian per candidate), fitted through the simulator; best score first."""
        extended, tried = [], set()
        for base in progress_bar(bases[:anchors], label, unit="candidate", shown=self.progress):
            others = tuple(e for e in self.library if e not in base.fit.effects)
            screened = sorted(
                zip(others, linear_starts(self.problem, base.fit, others, self.rows)), key=lambda item: item[1][1]
            )
            names = frozenset(e.name for e in base.fit.effects)
            fresh = [
                (o, start)
                for o, (start, _) in screened
                if names | {o.name} not in tried and not {o.name} | names >= set(AIR_VARIANTS)
            ]
            for other, start in fresh[:EXTENSION_FITS]:
                tried.add(names | {other.name})
                extended.append(self.score(fit(self.problem, base.fit.effects + (other,), start, self.rows)))
        return sorted(extended, key=lambda s: s.score)

    def choose(self, null: Scored, singles: list[Scored]) -> tuple[Scored, list[Scored], dict]:
        """No effect, the best single, the best pair or the best triple: each step only when it beats the simpler
        one (the first by a material share of the excess over the expected error: a shift hides in a large expected
        error), and the next step's candidates fitted only on a choice that passed. (choice, the pairs and triples
        fitted, the systematic test's entries)."""
        chosen, test = null, {}
        singles = [s for s in singles if inside(s)]
        if not singles:
            return chosen, [], test
        flag, gain, low, _ = self.better(singles[0], null, SINGLE_LEVEL, against=max(null.error - 1.0, 0.0))
        test.update(best_single=singles[0].fit.name, best_single_gain=gain, best_single_gain_low=low)
        if not flag:
            return chosen, [], test
        chosen, richer, bases = singles[0], [], singles
        for step, simpler, anchors in (("pair", "single", PAIR_ANCHORS), ("triple", "pair", TRIPLE_ANCHORS)):
            extended = self.fit_extensions(bases, anchors, f"{step}s on the best {simpler}s")
            richer += extended
            extended = [e for e in extended if inside(e)]
            if not extended:
                break
            tolerance = self.response_error(chosen) if self.claims_more(extended[0], chosen) else 0.0
            flag, gain, low, _ = self.better(extended[0], chosen, COMBINATION_LEVEL, tolerance)
            test.update(
                {
                    f"best_{step}": extended[0].fit.name,
                    f"best_{step}_gain_over_{simpler}": gain,
                    f"best_{step}_gain_low": low,
                    f"model_response_error_of_{chosen.fit.name}": tolerance,
                }
            )
            if not flag:
                break
            chosen, bases = extended[0], extended
        return chosen, richer, test

    def in_physical_terms(self, chosen: Scored, scored: list[Scored], test: dict) -> tuple[Scored, list[Scored]]:
        """On recordings without air: the choice with air density in place of its coefficient scales
        (`discovery.physical`) and in place of its main effect (`venue_air.air_explanations`); an air explanation
        with fewer parameters stands unless the choice beats it beyond doubt and materially. Recordings that carry
        their air get no air explanation at all (the library leaves air out for them). (choice, the explanations
        fitted). Another ball whose drag and lift agree is air (`physical.ball_agrees`)."""
        if self.air_recorded:
            return chosen, []
        known = {frozenset(e.name for e in s.fit.effects): s for s in scored}
        tried = restatements(self.problem, chosen, self.rows, self.score, known)
        tried += air_explanations(self.problem, chosen, scored, self.score, self.rows)
        seen = {id(s) for s in scored}
        fresh = list({id(s): s for s in tried if id(s) not in seen}.values())
        simpler_ones = {id(s): s for s in tried if s.fit.k < chosen.fit.k and inside(s)}.values()
        airs = [s for s in simpler_ones if not any(e.kind == "ball" for e in s.fit.effects)]
        if ball_agrees(chosen.fit) and airs:  # a ball changed as air changes it is air
            simpler = min(airs, key=lambda s: s.error)
            test.update(in_physical_terms=simpler.fit.name, in_physical_terms_from=chosen.fit.name)
            return simpler, fresh
        for simpler in sorted(simpler_ones, key=lambda s: s.error):
            if not self.better(chosen, simpler, COMBINATION_LEVEL)[0]:
                test.update(in_physical_terms=simpler.fit.name, in_physical_terms_from=chosen.fit.name)
                return simpler, fresh
        return chosen, fresh

    def model_form(self, chosen: Scored, test: dict) -> list[str]:
        """The venue conditions and monitor biases of `chosen` that are the model's form, not claimed: those within
        its own error (`within_form`) and those whose value changes with the launch (`discovery.invariance`), each
        group added to the systematic test's entries."""
        within = self.within_form(chosen)
        varying = [h for h in halves(self.problem, chosen.fit, self.rows) if h.varies and h.effect not in within]
        if within:
            test["within_model_form"] = "+".join(filter(None, (test.get("within_model_form"), *within)))
        self.set_aside += varying
        if varying:
            test["varies_with_ball_speed"] = "; ".join(
                filter(None, (test.get("varies_with_ball_speed"), *(h.describe() for h in varying)))
            )
        return within + [h.effect for h in varying]

    def within_form(self, chosen: Scored) -> list[str]:
        """The venue conditions and monitor biases of `chosen` whose own part of its prediction moves every recorded
        observable by less (RMS over the shots) than the model's own error there (the card's `own_error`, measured
        where the truth is known): the model's form alone makes differences that large, so they are not claimed.
        Empty against a model without an own error (the reference world, a controlled bundle)."""
        if not chosen.fit.k or not any(self.as_is.expected.model.values()):
            return []
        return [
            effect.name
            for effect, block in blocks(chosen.fit)
            if effect.kind != "form" and self.share_of_own_error(chosen, effect, block) < 1.0
        ]

    def share_of_own_error(self, candidate: Scored, effect: Effect, block: slice) -> float:
        """How far one effect of a candidate (its parameters at `block`) moves the candidate's predictions (with and
        without it, RMS over the shots), in units of the model's own error, on the recorded observable it moves
        most."""
        own, recorded = self.as_is.expected.model, self.problem.recordings.observed_names
        without = candidate.fit.theta.copy()
        without[block] = effect.null
        rows = np.arange(len(self.scored))
        both = self.problem.predict(candidate.fit.effects, np.stack([candidate.fit.theta, without]), rows)
        part = np.sqrt(np.nanmean((both[0] - both[1]) ** 2, axis=0))
        return max(part[OBSERVABLES.index(name)] / max(own.get(name, 0.0), 1e-12) for name in recorded)

    def form_instead(
        self, null: Scored, chosen: Scored, within: list[str], scored: list[Scored]
    ) -> tuple[Scored, list[Scored]]:
        """The choice without its effects `within` the model's form (`model_form`; refitted), or an explanation of
        the model's form alone (coefficient scales), whichever scores best among those that beat the model as is; the
        model as is where none does (the learned correction, the model's form too, is tried after). Against a
        baseline, whose form is held, also every explanation fitted without an effect set aside (air, say, where
        another ball was set aside for a spin decay that changes with the launch): it is then judged the same way.
        (choice, the refit)."""
        options = [s for s in scored if s.fit.k and all(e.kind == "form" for e in s.fit.effects)]
        if self.baseline is not None:
            aside = set(within) | {h.effect for h in self.set_aside}
            options += [s for s in scored if s.fit.k and not aside & {e.name for e in s.fit.effects}]
        kept = [(e, block) for e, block in blocks(chosen.fit) if e.name not in within]
        refitted = []
        if kept:
            start = np.concatenate([chosen.fit.theta[block] for _, block in kept])
            refitted.append(self.score(fit(self.problem, tuple(e for e, _ in kept), start, self.rows)))
        against = max(null.error - 1.0, 0.0)
        eligible = [s for s in options + refitted if inside(s)]
        passing = [s for s in eligible if self.better(s, null, SINGLE_LEVEL, against=against)[0]]
        return min(passing, key=lambda s: s.score, default=null), refitted

    def try_correction(self, null: Scored, chosen: Scored) -> tuple[Scored, list[Scored], dict]:
        """The learned correction on top of the chosen explanation and alone; it replaces the choice if better. A
        library effect is kept beside it only if that beats the correction alone beyond doubt: an effect that
        explains the size of the mismatch but not its structure is not named. (choice, corrections tried, the
        systematic test's entries)."""
        self.step("fitting a learned correction...")
        tolerance, tried, test = self.response_error(chosen), [], {}
        if tolerance:
            test[f"model_response_error_of_{chosen.fit.name}"] = tolerance
        library, alone = chosen, None
        for foundation in {id(chosen): chosen, id(null): null}.values():
            term = learned.fit_correction(self.problem, self.rows, foundation.fit)
            if term is None:
                continue
            candidate = self.score(term)
            tried.append(candidate)
            level = SINGLE_LEVEL if library is null else COMBINATION_LEVEL
            against = max(null.error - 1.0, 0.0) if library is null else None
            flag, gain, low, _ = self.better(candidate, library, level, tolerance, against)
            test[f"correction_on_{foundation.fit.name}_gain"] = gain
            test[f"correction_on_{foundation.fit.name}_gain_low"] = low
            if foundation is null:
                alone = candidate
            if flag and candidate.error < chosen.error and inside(candidate):
                chosen = candidate
        if alone is not None and chosen is not alone and chosen is not library:
            flag, gain, low, _ = self.better(chosen, alone, COMBINATION_LEVEL, tolerance)
            test["library_beside_correction_gain"], test["library_beside_correction_gain_low"] = gain, low
            if not flag:
                chosen = alone
        return chosen, tried, test

    def structure_left(self, explanation: Scored) -> list[str]:
        """What the systematic test still finds in the residuals that `explanation` leaves (its summary lines; empty
        when nothing is left; "the whole mismatch" for no explanation)."""
        if explanation.fit.k == 0:
            return ["the whole mismatch"]
        problem = self.problem
        after = problem.predict(explanation.fit.effects, explanation.fit.theta, np.arange(len(self.scored)))[0]
        residual = problem.observed - after
        use = problem.use & np.isfinite(after)
        dilution = {name: slopes[self.scored] for name, slopes in self.as_is.expected.dilution.items()}
        left = locate(problem.recordings, residual, problem.sigma, use, [], {}, dilution)
        return left.summary if has_structure(left) else []

    def heldout_summary(self, null: Scored, chosen: Scored) -> Heldout:
        """Held-out errors before and after the choice, its improvement with bootstrap intervals, and how much of
        the excess over the noise floor it explains."""
        expected = self.as_is.expected
        sigma = expected.sigma
        before_r, after_r = null.heldout_z * sigma, chosen.heldout_z * sigma
        names = [(j, n) for j, n in enumerate(OBSERVABLES) if np.isfinite(null.heldout_z[:, j]).any()]
        a, count = per_shot(null.heldout_z)
        b, _ = per_shot(chosen.heldout_z)
        sessions = self.recordings.session
        draws = cluster_bootstrap(a - b, count, sessions, self.rng)
        by_observable = {}
        for j, name in names:
            used = np.isfinite(null.heldout_z[:, j]) & np.isfinite(chosen.heldout_z[:, j])
            d = np.where(used, null.heldout_z[:, j] ** 2 - chosen.heldout_z[:, j] ** 2, 0.0)
            obs_draws = cluster_bootstrap(d, used.astype(float), sessions, self.rng)
            by_observable[name] = (
                float(d.sum() / max(used.sum(), 1)),
                *map(float, np.quantile(obs_draws, [0.025, 0.975])),
            )
        improvement = null.error - chosen.error
        share = np.where(np.isfinite(null.heldout_z), (expected.noise_sigma / sigma) ** 2, 0.0).sum(axis=1)
        noise_floor = float(share.sum() / max(count.sum(), 1.0))
        fraction, fraction_ci, absorbs = None, None, False
        if null.error > noise_floor and chosen is not null:
            before_draws = cluster_bootstrap(a, count, sessions, np.random.default_rng(1))
            gain_draws = cluster_bootstrap(a - b, count, sessions, np.random.default_rng(1))
            floor_draws = cluster_bootstrap(share, count, sessions, np.random.default_rng(1))
            fraction = improvement / (null.error - noise_floor)
            ratio = gain_draws / np.maximum(before_draws - floor_draws, 1e-9)
            fraction_ci = tuple(float(q) for q in np.quantile(ratio, [0.025, 0.975]))
            absorbs = fraction_ci[0] > 1.0 and chosen.error < (1.0 - NOISE_SPREAD) * noise_floor
        return Heldout(
            grouping=self.grouping,
            n_folds=int(self.fold.max()) + 1,
            before={n: _rms(before_r[:, j]) for j, n in names},
            after={n: _rms(after_r[:, j]) for j, n in names},
            expected={n: float(np.sqrt(np.mean(sigma[:, j] ** 2))) for j, n in names},
            before_error=null.error,
            after_error=chosen.error,
            improvement=improvement,
            improvement_ci=tuple(float(q) for q in np.quantile(draws, [0.025, 0.975])),
            improvement_by_observable=by_observable,
            noise_floor=noise_floor,
            explained_fraction=fraction,
            explained_fraction_ci=fraction_ci,
            absorbs_noise=absorbs,
        )


def diagnose(
    recordings: Recordings,
    model: FlightModel,
    noise: MeasurementNoise = RADAR_NOISE,
    seed: int = 0,
    with_correction: bool = True,
    estimate_scatter: bool = True,
    progress: bool = True,
    baseline: LearnedForm | None = None,
) -> Diagnosis:
    """Run the whole diagnosis of recordings against a model (its steps on standard error with `progress`); with
    what a `baseline` session taught (`discovery.form.learn_form`), against the model with that form: what changed."""
    if baseline is not None:
        model, recordings = formed_model(model, baseline), comparable(recordings, baseline)
    return Diagnoser(
        recordings, model, noise, seed, with_correction, estimate_scatter, progress, baseline=baseline
    ).run()


def scatter_sentence(scatter: Scatter) -> str:
    """Where the recordings' own scatter replaced the assumed noise, in words (empty where it did not)."""
    if not scatter.applied:
        return ""
    parts = ", ".join(f"{LABELS[name].split(' (')[0]} {ratio:.1f}x" for name, ratio in scatter.applied.items())
    return (
        f" The recordings scatter more from shot to shot than the assumed launch-monitor noise ({parts}, about a "
        "linear trend in the launch within each session and club), so that scatter is what they are expected to "
        "miss by."
    )


def sampling_sentence(n_shots: int, scored: int, fitted: int) -> str:
    """How many shots the candidates were fitted and scored on and what that does to the quoted uncertainties, in
    words (empty where every shot was scored)."""
    if scored == n_shots:
        return ""
    return (
        f" The candidates were fitted on {fitted:,} and scored on {scored:,} of the {n_shots:,} shots (a subsample "
        "stratified by session and club); the ± quoted are from those shots: the whole set would narrow them by up to "
        f"{np.sqrt(n_shots / scored):.1f}x where its shots scatter independently, by much less where each session's "
        "own conditions dominate. The systematic test and the chosen explanation's held-out errors use every shot."
    )


def left_sentence(left: list[str]) -> str:
    """Structure the named library explanation leaves and the learned correction could not follow, in words (empty
    where none is left): the explanation then accounts for the size of the mismatch, not all of its structure."""
    if not left:
        return ""
    return (
        f" Structure remains after it ({'; '.join(left[:2])}) that neither it nor a learned correction over speed, "
        "spin and height explains: part of the mismatch may lie outside the library, so its parameters are "
        "approximate."
    )


def control_sentence(model: FlightModel, offset: np.ndarray, response: float) -> str:
    """What the control took out, and how differently the model responds to the chosen effect, in words (empty
    without a control)."""
    if model.control is None:
        return ""
    known = -np.mean(offset, axis=0)
    text = (
        f" Before fitting, the model's own error on these launches was taken out: against {model.control.name}, the "
        f"physics it was trained to imitate, it carries {known[0]:+.1f} m along the line and {known[1]:+.1f} m across "
        f"it, peaks {known[2]:+.1f} m and lands {known[4]:+.1f} deg steeper."
    )
    if response > 0:
        text += (
            f" With the fitted effect the model responds differently from that physics by {response:.2f} in mean "
            "squared standardized error; finer explanations that remove no more than that are not claimed."
        )
    return text
