"""The model's form learned from a baseline session: smooth multipliers of C_L, C_D and C_M as functions of the spin
ratio and the Reynolds number, fitted through the simulator on shots recorded in known conditions.

A model's form error and a venue or monitor cause are confounded within one session (Kennedy & O'Hagan 2001;
Brynjarsdottir & O'Hagan 2014): what informs the form is a baseline session with the same monitor and ball in known
air. The form lives in the coefficients, so it flies through every later change as the ball's own aerodynamics
would: thinner air scales it with the dynamic pressure, a wind or a launch bias moves it with the spin ratio and
the Reynolds number the ball then meets. What the baseline cannot inform (how the flight responds to air it never
flew in, launches far from its own) is reported, not assumed (`Coverage`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from golfflight.discovery.as_is import as_is
from golfflight.discovery.discrepancy import Discrepancy, fit_discrepancy
from golfflight.discovery.effects import Context, Effect, Parameter, Reported
from golfflight.discovery.fit import (
    Fit,
    Problem,
    fit_at,
    fit_rows,
    fitted_parameters,
    folds,
    held_nuisance_covariance,
    linear_starts,
    residuals_and_jacobian,
)
from golfflight.discovery.form_terms import TERMS, formed_flyer
from golfflight.discovery.model import FlightModel
from golfflight.discovery.noise import RADAR_NOISE
from golfflight.discovery.recordings import OBSERVABLES, Recordings
from golfflight.discovery.simulator import Setup
from golfflight.errors import InputError
from golfflight.flight.integrator import RUNGE_KUTTA_4
from golfflight.shots.progress import progress_step
from golfflight.shots.synth import MeasurementNoise

NAME = "form"
FIT_ROUNDS = 3
RK4_STEP_S = 0.25
"""The step discovery flies RK4 at: 300 launches of `conceal`'s bag flown by the served model at 0.25 s land within
0.07 m (carry) and 0.07 deg of RK4 at 0.01 s (RMS 0.03 m), against 2.0 m and 2.0 deg for forward Euler at the card's
0.1 s, at 1.6 coefficient evaluations per 0.1 s of flight where RK4 at 0.1 s takes 4 (tests/test_discovery_baseline).
Stable for every form: `form_terms.LOG_MULTIPLIER_BOUND`."""


def _apply(theta: np.ndarray, conditions: Setup) -> Setup:
    return replace(conditions.copy(), form_weights=theta)


def _describe(theta: np.ndarray, covariance: np.ndarray, context: Context) -> Reported:
    names = [term.name for term in TERMS]
    return (
        {n: float(t) for n, t in zip(names, theta)},
        {n: float(np.sqrt(max(covariance[i, i], 0.0))) for i, n in enumerate(names)},
    )


FORM = Effect(
    NAME,
    tuple(Parameter(term.name, "1", 0.0, -term.bound, term.bound, 0.05, 0.005) for term in TERMS),
    _apply,
    _describe,
    "the model's form learned from the baseline: C_L, C_D and C_M times smooth functions of the spin ratio and the "
    "Reynolds number",
    kind="form",
)
"""The form as an effect the fitter treats like any other (fitted on the baseline session only)."""


@dataclass(frozen=True)
class LearnedForm:
    """What a baseline session teaches: the form's weights and covariance, the discrepancy it leaves, how much of the
    baseline's held-out error the two remove, and the launches and airs they were learned in."""

    source: str
    n_shots: int
    theta: np.ndarray
    covariance: np.ndarray
    discrepancy: Discrepancy
    error_before: float
    """Mean squared standardized residual of the model as is on the baseline (1 = noise alone)."""
    error_after: float
    """The same on held-out baseline shots: the form fitted on every shot, the discrepancy without their fold."""
    launches: dict[str, np.ndarray]
    """The baseline's recorded launch values."""
    density_kg_m3: np.ndarray
    """The air density each baseline shot flew in (recorded, else the model's): the airs it was learned in."""
    kinematic_viscosity_m2_s: float
    """The median kinematic viscosity of the airs it was learned in: where the form read along the speed
    (`read_along_speed`) is read."""

    def weights(self) -> dict[str, float]:
        """The form's weights by term name."""
        return {term.name: float(value) for term, value in zip(TERMS, self.theta, strict=True)}

    @property
    def informs(self) -> tuple[str, ...]:
        """The observables the baseline recorded on enough shots to learn their discrepancy: a new session's other
        outcomes have nothing to be compared against."""
        processes = self.discrepancy.processes
        return tuple(name for name, process in zip(OBSERVABLES, processes, strict=True) if len(process.points))


def accurately_flown(model: FlightModel) -> FlightModel:
    """The model's coefficients flown by RK4 at RK4_STEP_S (or the card's step, if longer): what a baseline's form is
    learned and a new session diagnosed with. The service's forward Euler at 0.1 s leaves a step error that no
    coefficient carries and that follows no change of air: a 1,900 m venue flown as density alone in Ferguson 2022's
    world, against a sea-level baseline, was named as nothing (held-out error 22.7 before, 1.15 for a ball, wind and
    spin bias, set aside as the model's form) by Euler and as air 0.770 by RK4 (seed 0; the baseline's held-out error
    19.4 -> 1.17 and 10.3 -> 1.14)."""
    return flown_by_rk4(model, max(RK4_STEP_S, model.flyer.dt_s))


def flown_by_rk4(model: FlightModel, step_s: float) -> FlightModel:
    """The model's coefficients, air and card flown by RK4 at `step_s` (the model itself where it already is)."""
    flyer = model.flyer
    if flyer.rule is RUNGE_KUTTA_4 and flyer.dt_s == step_s:
        return model
    rk4 = flyer.replaced(rule=RUNGE_KUTTA_4, dt_s=step_s)
    return replace(model, name=f"{model.name}, flown by RK4 at {step_s:g} s", flyer=rk4)


def learn_form(
    recordings: Recordings,
    model: FlightModel,
    noise: MeasurementNoise = RADAR_NOISE,
    seed: int = 0,
    progress: bool = False,
) -> LearnedForm:
    """Learn the form (`FORM`) and the discrepancy it leaves from a baseline session in its known conditions
    (recorded air and wind, else the model's air, calm), the model's coefficients flown by RK4 (`accurately_flown`),
    expecting measurement noise only (and the session's own scatter where larger), and score both on held-out
    sessions."""
    if model.control is not None:
        raise InputError("a baseline session and --reference-control cannot be combined: the baseline is the control")
    bare = replace(
        accurately_flown(model),
        model_error={name: 0.0 for name in OBSERVABLES},
        error_source={name: "none: the baseline session informs it" for name in OBSERVABLES},
    )
    progress_step(f"learning the model's form from the baseline session's {len(recordings):,} shots...", progress)
    start = as_is(recordings, bare, noise, seed, estimate_scatter=True)
    problem = Problem(bare, recordings, start.base, start.expected.sigma, start.use, start.offset)
    rows = fit_rows(recordings, np.random.default_rng([seed, 3]))
    result = converged(problem, linear_starts(problem, None, (FORM,), rows)[0][0], rows)
    everyone = np.arange(len(recordings))
    formed = problem.predict((FORM,), result.theta, everyone)[0]
    discrepancy = _discrepancy(problem, formed, everyone, seed)
    after = heldout_with_discrepancy(problem, formed, discrepancy, seed)
    return LearnedForm(
        recordings.source or "the baseline session",
        len(recordings),
        result.theta,
        result.covariance,
        discrepancy,
        float(np.nanmean(problem.standardize(start.predicted, everyone) ** 2)),
        float(np.nanmean(after**2)),
        {k: v.copy() for k, v in recordings.launch.items()},
        start.base.density_kg_m3.copy(),
        float(np.median(start.base.viscosity(model.flyer.kinematic_viscosity_m2_s))),
    )


def _discrepancy(
    problem: Problem, formed: np.ndarray, rows: np.ndarray, seed: int, like: Discrepancy | None = None
) -> Discrepancy:
    """The discrepancy the form's predictions `formed` [N,5] leave on the shots at `rows`."""
    residual = np.where(problem.use[rows], problem.observed[rows] - formed[rows], np.nan)
    launch = {k: v[rows] for k, v in problem.recordings.launch.items()}
    return fit_discrepancy(launch, residual, problem.sigma[rows], seed, like)


def converged(problem: Problem, start: np.ndarray, rows: np.ndarray, rounds: int = FIT_ROUNDS) -> Fit:
    """The form fitted from `start`, restarted from where each fit stopped (a fit stops after a fixed number of
    evaluations; the form's many weights may need more) until its error on every shot stops falling by 1 %. A restart
    flies its fit and every shot once; the Jacobian on every shot, for the covariance, is flown for the last alone."""
    theta = fitted_parameters(problem, (FORM,), start, rows)[0]
    error = _error(problem, theta)
    for _ in range(rounds - 1):
        again = fitted_parameters(problem, (FORM,), theta, rows)[0]
        again_error = _error(problem, again)
        stalled = again_error > 0.99 * error
        theta, error = again, again_error
        if stalled:
            break
    return fit_at(problem, (FORM,), theta)


def _error(problem: Problem, theta: np.ndarray) -> float:
    """Mean squared standardized residual of every shot flown with the form's weights `theta`."""
    everyone = np.arange(len(problem.recordings))
    return float(np.nanmean(problem.standardize(problem.predict((FORM,), theta, everyone)[0], everyone) ** 2))


def heldout_with_discrepancy(problem: Problem, formed: np.ndarray, whole: Discrepancy, seed: int) -> np.ndarray:
    """Standardized residuals [N,5] of every shot predicted by the form (`formed`: fitted on every shot, its few
    weights against five outcomes a shot) and the discrepancy learned without its fold (whole sessions, or blocks of
    shots; the length scales and amplitudes of the `whole` one), the expected error including that discrepancy's SD
    there, as a new session's would."""
    fold, _ = folds(problem.recordings.session)
    z = np.full(problem.observed.shape, np.nan)
    for f in np.unique(fold):
        held, train = np.flatnonzero(fold == f), np.flatnonzero(fold != f)
        launch = {k: v[held] for k, v in problem.recordings.launch.items()}
        mean, sd = _discrepancy(problem, formed, train, seed, whole).predict(launch)
        sigma = np.sqrt(problem.sigma[held] ** 2 + sd**2)
        z[held] = np.where(problem.use[held], (problem.observed[held] - formed[held] - mean) / sigma, np.nan)
    return z


def formed_model(model: FlightModel, form: LearnedForm) -> FlightModel:
    """The model (flown by RK4) with the learned form held in its coefficients and the discrepancy beside it: what a
    new session is diagnosed against (its own error is the discrepancy's SD at each shot's launch)."""
    model = accurately_flown(model)
    return FlightModel(
        f"{model.name}, with the form learned from {form.source} ({form.n_shots:,} shots)",
        formed_flyer(model.flyer, form.theta),
        {name: 0.0 for name in OBSERVABLES},
        {name: "the baseline session: its discrepancy at each shot's launch" for name in OBSERVABLES},
        model.temperature_c,
        discrepancy=form.discrepancy,
    )


def with_form_uncertainty(problem: Problem, result: Fit, form: LearnedForm, rows: np.ndarray) -> Fit:
    """`result` (a fit against the model with `form` held) with the form's own uncertainty in its covariance: the
    form was estimated on the baseline and then held, so its error moves the new fit too, alike for every new shot,
    which their scatter cannot show (`fit.held_nuisance_covariance`). How far the fit moves per unit of the form's
    weights is a ratio of sums over the shots, read on the fit's `rows` (every shot up to `fit.MAX_FIT_SHOTS`).
    Fitted on the new shots alone, a
    launch-angle bias of -1.18 ± 0.019 deg came out for the hidden -1.25 (3.8 ± off); with the form's error counted,
    ± 0.040 (1.8 ± off; reference world, seed 0)."""
    if not result.k:
        return result
    theta = np.concatenate([result.theta, FORM.null])
    z, jacobian = residuals_and_jacobian(problem, result.effects + (FORM,), theta, rows)
    k = result.k
    added = held_nuisance_covariance(z, jacobian[..., :k], jacobian[..., k:], form.covariance)
    return replace(result, covariance=result.covariance + added)


def with_reading_uncertainty(problem: Problem, result: Fit, other_reading: FlightModel, rows: np.ndarray) -> Fit:
    """`result` with the reading of the form the baseline cannot rule out in its covariance: refitted from where it
    stands against the form read along the speed (`read_along_speed`), half the move is one ± more. In another air
    than the baseline's the truth's response lay between the two readings in every world the docs measure
    (docs/discovery.md, "How far a sea-level form carries into other air"); in the baseline's air they agree."""
    if not result.k:
        return result
    refit = fitted_parameters(replace(problem, model=other_reading), result.effects, result.theta, rows)[0]
    half = (refit - result.theta) / 2.0
    return replace(result, covariance=result.covariance + np.outer(half, half))


def read_along_speed(formed: FlightModel, form: LearnedForm) -> FlightModel:
    """The formed model (`formed_model`) with its form read along the speed, at the median viscosity of the airs the
    baseline was learned in, instead of along the Reynolds number: the same flights in that air, and in another air
    the other reading the baseline cannot rule out (at one air the Reynolds number and the speed are one variable;
    airs within 10 % of each other barely part them). The two differ by what the baseline cannot inform of the new
    air (`Diagnoser.response_error`)."""
    flyer = formed.flyer.replaced(model=replace(formed.flyer.model, read_at=form.kinematic_viscosity_m2_s))
    return replace(formed, name=f"{formed.name}, its form read along the speed", flyer=flyer)
