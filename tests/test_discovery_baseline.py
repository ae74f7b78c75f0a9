"""Discovery against a baseline session: the form's coefficients, the discrepancy, learning both from a baseline, and
a change named against it where the model's form alone would be confounded with it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from golfflight.discovery.conceal import conceal
from golfflight.discovery.diagnose import Diagnoser, diagnose, library_for
from golfflight.discovery.discrepancy import fit_discrepancy
from golfflight.discovery.effects import BALL, EFFECTS
from golfflight.discovery.fit import fit, linear_starts
from golfflight.discovery.form import (
    FORM,
    RK4_STEP_S,
    accurately_flown,
    formed_model,
    learn_form,
    read_along_speed,
    with_form_uncertainty,
    with_reading_uncertainty,
)
from golfflight.discovery.form_terms import (
    LOG_MULTIPLIER_BOUND,
    REYNOLDS_REF,
    SPIN_RATIO_REF,
    TERMS,
    log_multipliers,
)
from golfflight.discovery.model import load_model, reference
from golfflight.discovery.noise import base_conditions
from golfflight.discovery.prove import ferguson_world
from golfflight.discovery.recordings import OBSERVABLES, UNKNOWN_CLUB, from_shot_set
from golfflight.discovery.reach import baseline_info, comparable, needed_words, outside_baseline
from golfflight.discovery.schema import Report
from golfflight.flight.constants import BALL_RADIUS_M
from golfflight.flight.integrator import RUNGE_KUTTA_4
from golfflight.errors import InputError
from golfflight.shots.records import write_shots

from golfflight.cli import main

WEIGHTS = {term.name: k for k, term in enumerate(TERMS)}


def _weights(**named: float) -> np.ndarray:
    theta = np.zeros(len(TERMS))
    for name, value in named.items():
        theta[WEIGHTS[name.replace("_", " ")]] = value
    return theta


def test_the_form_features_at_a_hand_worked_state():
    """A ball at 40 m/s spinning 750 rad/s in air of nu = 1.5e-5: S = 0.021335 * 750 / 40 = 0.4000 (s = ln 2), Re =
    2 * 0.021335 * 40 / 1.5e-5 = 113,787 (r = ln(0.7586)); C_L is multiplied by exp(0.1 s + 0.2 r)."""
    v, w = np.array([[0.0, 40.0, 0.0]]), np.array([[-750.0, 0.0, 0.0]])
    theta = _weights(lift_x_s=0.1, lift_x_r=0.2, drag_x_1=0.05, spin_decay=0.3)
    out = log_multipliers(v, w, 1.5e-5, theta)[0]
    s = np.log(BALL_RADIUS_M * 750 / 40 / SPIN_RATIO_REF)
    r = np.log(2 * BALL_RADIUS_M * 40 / 1.5e-5 / REYNOLDS_REF)
    assert s == pytest.approx(np.log(2.0), rel=1e-3) and r == pytest.approx(np.log(0.75858), rel=1e-3)
    assert out == pytest.approx([0.1 * s + 0.2 * r, 0.05, 0.3])


def test_the_form_is_held_within_its_bound_and_the_coarse_step_flies_every_corner(served):
    """Every weight at its own bound sums to ln C_M multipliers of about e^18 on a wedge (S = 1.5, Re = 33,000): the
    sum is held at LOG_MULTIPLIER_BOUND, and at every corner of the bounds RK4 at RK4_STEP_S lands the shots a fine
    step lands within 5 m (unheld, spin decay x e^13 flew two wedges to NaN; lift and drag held at 1.5, 130 m off)."""
    v, w = np.array([[0.0, 12.0, 0.0]]), np.array([[-1500.0, 0.0, 0.0]])
    top = np.array([term.bound for term in TERMS])
    assert log_multipliers(v, w, 1.5e-5, top)[0] == pytest.approx(LOG_MULTIPLIER_BOUND)
    assert log_multipliers(v, w, 1.5e-5, -top)[0] == pytest.approx(-LOG_MULTIPLIER_BOUND)
    base = base_conditions(from_shot_set(conceal({}, 60, seed=8).shots), served)
    fine = replace(served, flyer=served.flyer.replaced(rule=RUNGE_KUTTA_4, dt_s=0.05))
    for sign in np.array(np.meshgrid(*[[-1.0, 1.0]] * 3)).T.reshape(-1, 3):
        formed = FORM.apply(np.repeat((top * sign[[term.column for term in TERMS]])[None], len(base), 0), base)
        coarse, close = accurately_flown(served).simulate(formed).outcomes(), fine.simulate(formed).outcomes()
        assert np.array_equal(np.isfinite(coarse), np.isfinite(close)), sign
        assert np.nanmax(np.abs(coarse - close)) < 5.0, sign


def test_a_constant_drag_weight_flies_as_the_drag_scale():
    """exp(b0) on C_D everywhere is the library's drag scale of exp(b0), to rounding."""
    recordings = from_shot_set(conceal({}, 40, seed=3).shots)
    model = reference()
    base = base_conditions(recordings, model)
    scaled = EFFECTS["drag_scale"].apply(np.full((len(base), 1), 1.05), base)
    formed = FORM.apply(np.repeat(_weights(drag_x_1=np.log(1.05))[None], len(base), 0), base)
    assert model.simulate(formed).outcomes() == pytest.approx(model.simulate(scaled).outcomes(), abs=1e-9)
    none = FORM.apply(np.zeros((len(base), len(TERMS))), base)
    assert np.array_equal(model.simulate(none).outcomes(), model.simulate(base).outcomes())


def test_the_discrepancy_follows_a_smooth_function_and_doubts_far_launches():
    rng = np.random.default_rng(0)
    n = 300
    launch = {
        "ball_speed_mps": rng.normal(60, 5, n),
        "launch_angle_deg": rng.normal(15, 2, n),
        "spin_rpm": rng.normal(5000, 800, n),
        "spin_axis_deg": rng.normal(0, 3, n),
    }
    truth = 2.0 * np.sin((launch["ball_speed_mps"] - 60) / 5)
    residual = np.zeros((n, len(OBSERVABLES)))
    residual[:, 0] = truth + rng.normal(0, 0.3, n)
    discrepancy = fit_discrepancy(launch, residual, np.full((n, len(OBSERVABLES)), 0.3))
    mean, sd = discrepancy.predict(launch)
    assert np.sqrt(np.mean((mean[:, 0] - truth) ** 2)) < 0.2
    assert np.all(sd[:, 0] < 0.3)
    far = {k: np.array([v.mean() + 10 * v.std()]) for k, v in launch.items()}
    far_mean, far_sd = discrepancy.predict(far)
    assert abs(far_mean[0, 0]) < 0.1 and far_sd[0, 0] > 0.9 * discrepancy.processes[0].amplitude


@pytest.fixture(scope="module")
def served():
    return load_model(None)


@pytest.fixture(scope="module")
def ferguson_baseline(served):
    """What a clean 200-shot baseline in Ferguson 2022's world teaches the served model (another form)."""
    clean = conceal({}, 200, seed=4, model=ferguson_world(), launch_seed=1)
    return learn_form(from_shot_set(clean.shots, source="home"), served, seed=4)


def test_the_baseline_teaches_the_form_on_held_out_shots(ferguson_baseline):
    """Against the model as is a clean Ferguson set misses by several times the noise; with the form and the
    discrepancy learned without each fold, its held-out shots miss by about the noise."""
    assert ferguson_baseline.error_before > 3.0
    assert ferguson_baseline.error_after < 0.5 * ferguson_baseline.error_before and ferguson_baseline.error_after < 2.0


def test_a_wind_is_named_against_the_baseline_where_the_form_differs(served, ferguson_baseline):
    hidden = {"wind": {"speed_mps": 4.0, "from_deg": 20.0}}
    new = from_shot_set(conceal(hidden, 200, seed=4, model=ferguson_world()).shots, source="windy")
    report = diagnose(new, served, seed=4, progress=False, baseline=ferguson_baseline).report
    assert [e.name for e in report.effects] == ["wind"]
    assert report.effects[0].parameters["speed_mps"] == pytest.approx(4.0, rel=0.1)
    assert report.baseline is not None and report.baseline.source == "home"
    assert report.statement.startswith("Against the baseline session home (200 shots)")


def test_a_no_change_session_claims_nothing_against_the_baseline(served, ferguson_baseline):
    new = from_shot_set(conceal({}, 200, seed=4, model=ferguson_world()).shots, source="same")
    report = diagnose(new, served, seed=4, progress=False, baseline=ferguson_baseline).report
    assert not any(e.kind in ("venue", "monitor", "ball") for e in report.effects)


def test_against_a_baseline_the_coefficient_scales_give_way_to_another_ball():
    plain, against = library_for(False), library_for(False, against_baseline=True)
    assert "drag_scale" in {e.name for e in plain} and BALL not in plain
    assert BALL in against and not {"drag_scale", "lift_scale", "spin_decay"} & {e.name for e in against}
    assert {e.name for e in plain if e.kind != "form"} == {e.name for e in against if e.kind != "ball"}


def test_new_shots_outside_the_baseline_are_found_and_named(served, ferguson_baseline):
    """Launches far from the baseline's are outside, the discrepancy doubts them more than the baseline's own, and
    the report says which baseline shots would cover them."""
    launch = {k: v.copy() for k, v in ferguson_baseline.launches.items()}
    assert not outside_baseline(ferguson_baseline, launch).any()
    slow = {k: v[:5] for k, v in launch.items()}
    slow["ball_speed_mps"] = np.full(5, 15.0)
    assert outside_baseline(ferguson_baseline, slow).all()
    model = formed_model(served, ferguson_baseline)
    far_sd, near_sd = model.discrepancy.predict(slow)[1], model.discrepancy.predict(launch)[1]
    assert (far_sd.mean(axis=0) > near_sd.mean(axis=0)).all()
    words = needed_words({"ball_speed_mps": [15.0, 15.0]}, ["putter"])
    assert words == "Record baseline shots at ball speed 15–15 m/s (the new session's putter), with the same launch " \
        "monitor and ball."


def test_the_cli_diagnoses_against_a_baseline_and_refuses_a_tiny_one(tmp_path, capsys):
    home = conceal({}, 120, seed=9, launch_seed=1)
    windy = conceal({"wind": {"speed_mps": 5.0, "from_deg": 180.0}}, 120, seed=9)
    write_shots(tmp_path / "home.csv", home.shots.records)
    write_shots(tmp_path / "new.csv", windy.shots.records)
    argv = ["diagnose", str(tmp_path / "new.csv"), "--model", "reference", "--quiet"]
    assert main([*argv, "--baseline", str(tmp_path / "home.csv"), "--out", str(tmp_path / "out")]) == 0
    report = Report.model_validate_json((tmp_path / "out" / "report.json").read_text())
    assert report.baseline is not None and report.baseline.n_shots == len(home.shots.records)
    assert [e.name for e in report.effects] == ["wind"]
    write_shots(tmp_path / "tiny.csv", home.shots.records[:10])
    assert main([*argv, "--baseline", str(tmp_path / "tiny.csv"), "--out", str(tmp_path / "x")]) == 2
    assert "--baseline" in capsys.readouterr().err


def _apex_only(recordings):
    keep = np.array([name == "apex_m" for name in OBSERVABLES])
    return replace(recordings, observed=np.where(keep, recordings.observed, np.nan))


def test_outcomes_the_baseline_never_recorded_are_not_compared(served):
    """A baseline that records only the apex (as tour feeds do) teaches nothing about carry: a new session's carry,
    side, time and landing angle are set aside and said so, not read as a change (the form's own carry error was
    once named another ball), and a new session with nothing the baseline records is refused."""
    clean = conceal({}, 90, seed=5, model=ferguson_world(), launch_seed=1)
    baseline = learn_form(_apex_only(from_shot_set(clean.shots, source="apex feed")), served, seed=5)
    assert baseline.informs == ("apex_m",)
    new = from_shot_set(conceal({}, 90, seed=5, model=ferguson_world()).shots, source="same")
    report = diagnose(new, served, seed=5, progress=False, baseline=baseline).report
    assert not any(e.kind in ("venue", "monitor", "ball") for e in report.effects)
    assert any("carry along the line" in note and "not compared" in note for note in report.baseline.cannot_inform)
    carry_only = replace(new, observed=np.where(np.isin(OBSERVABLES, ["carry_y_m"]), new.observed, np.nan))
    with pytest.raises(InputError, match="records none of the new session's outcomes"):
        diagnose(carry_only, served, seed=5, progress=False, baseline=baseline)


def test_discovery_flies_rk4_at_a_step_within_centimetres_of_a_fine_one(served):
    """RK4 at RK4_STEP_S lands within 0.1 m and 0.1 deg of RK4 at 0.01 s (the card's forward Euler misses by metres):
    the accuracy a baseline's form is learned at, at 2.5x fewer network calls than RK4 at the card's 0.1 s."""
    base = base_conditions(from_shot_set(conceal({}, 120, seed=3).shots), served)
    flown = accurately_flown(served)
    assert flown.flyer.rule is RUNGE_KUTTA_4 and flown.flyer.dt_s == RK4_STEP_S
    fine = replace(served, flyer=served.flyer.replaced(rule=RUNGE_KUTTA_4, dt_s=0.01)).simulate(base).outcomes()
    carry, angle = OBSERVABLES.index("carry_y_m"), OBSERVABLES.index("landing_angle_deg")
    assert np.abs(flown.simulate(base).outcomes() - fine)[:, [carry, angle]].max() < 0.1
    assert np.abs(served.simulate(base).outcomes() - fine)[:, carry].max() > 0.5


def test_a_session_without_clubs_is_not_told_to_record_the_unknown_club(ferguson_baseline):
    new = from_shot_set(conceal({}, 40, seed=8).shots)
    slow = replace(
        new,
        launch={**new.launch, "ball_speed_mps": np.full(len(new), 15.0)},
        club=np.full(len(new), UNKNOWN_CLUB, dtype=object),
    )
    info = baseline_info(ferguson_baseline, slow, np.full(len(new), 1.225))
    assert info.outside_shots == len(new) and info.outside_clubs == []
    assert info.needed.startswith("Record baseline shots at ball speed 15–15 m/s, ") and UNKNOWN_CLUB not in info.needed


def test_the_two_readings_of_the_form_agree_in_the_baselines_air_and_part_in_thinner_air(served, ferguson_baseline):
    """Read along the Reynolds number or along the speed, the learned form flies the baseline's own air alike (at one
    air they are one variable); in real air 0.8 x as dense they differ: what the baseline cannot inform."""
    from golfflight.discovery.form import read_along_speed

    formed = formed_model(served, ferguson_baseline)
    other = read_along_speed(formed, ferguson_baseline)
    launches = from_shot_set(conceal({}, 40, seed=5, model=ferguson_world()).shots)
    setup = base_conditions(launches, formed)
    same = formed.simulate(setup).outcomes() - other.simulate(setup).outcomes()
    assert np.nanmax(np.abs(same)) < 1e-9
    thin = setup.copy()
    thin.density_ratio[:] = 0.8
    thin.viscosity_ratio[:] = 1 / 0.8
    apart = formed.simulate(thin).outcomes() - other.simulate(thin).outcomes()
    assert np.sqrt(np.nanmean(apart[:, OBSERVABLES.index("carry_y_m")] ** 2)) > 0.1


def test_a_ball_set_aside_as_the_form_gives_way_to_the_air_fitted_without_it(served):
    """Ferguson's world, real air 0.776 x ICAO against a baseline at three lower venues (seed 1): the best single is
    another ball whose spin decay changes with the launch (set aside as the model's form); the air fitted without it
    holds one value for every shot and is named, within 0.03."""
    from golfflight.discovery.prove import HIGH_VENUE_REAL, run_case

    run = run_case(served, HIGH_VENUE_REAL, ("air_density",), 1, 300, "ferguson", against_baseline=True)
    assert run.systematic and set(run.fitted) <= {"air_density", "air_density_only"}
    (air,) = run.fitted.values()
    assert abs(air["ratio"] - 0.776) < 0.03


def test_the_choices_plus_minus_counts_the_held_forms_own_error(served, ferguson_baseline):
    """The form the baseline taught is held while the wind is fitted; its covariance moves the wind's fit too, so
    the quoted ± is the fit's own widened by it, and a form known exactly would add nothing."""
    hidden = {"wind": {"speed_mps": 4.0, "from_deg": 20.0}}
    new = comparable(from_shot_set(conceal(hidden, 200, seed=4, model=ferguson_world()).shots), ferguson_baseline)
    formed = formed_model(served, ferguson_baseline)
    diagnoser = Diagnoser(new, formed, seed=4, progress=False, baseline=ferguson_baseline)
    start = linear_starts(diagnoser.problem, None, (EFFECTS["wind"],), diagnoser.rows)[0][0]
    wind = fit(diagnoser.problem, (EFFECTS["wind"],), start, diagnoser.rows)
    counted = with_form_uncertainty(diagnoser.problem, wind, ferguson_baseline, diagnoser.rows)
    assert np.all(np.diag(counted.covariance) > np.diag(wind.covariance))
    np.testing.assert_array_equal(counted.theta, wind.theta)
    exact = replace(ferguson_baseline, covariance=np.zeros_like(ferguson_baseline.covariance))
    unchanged = with_form_uncertainty(diagnoser.problem, wind, exact, diagnoser.rows)
    np.testing.assert_allclose(unchanged.covariance, wind.covariance)


@pytest.mark.parametrize(
    ("hidden", "same_air"),
    [({"wind": {"speed_mps": 4.0, "from_deg": 20.0}}, True), ({"air_density": {"ratio": 0.85}}, False)],
)
def test_the_reading_the_baseline_cannot_rule_out_widens_the_plus_minus_in_other_air(
    served, ferguson_baseline, hidden, same_air
):
    """In the baseline's air the two readings of the form fly alike and add nothing; in real air 0.85 x as dense (its
    viscosity, so its Reynolds numbers, moved) they part: refitted against the form read along the speed, the air
    moves (0.866 -> 0.863 here), and half that move is one ± more."""
    formed = formed_model(served, ferguson_baseline)
    (name,) = hidden
    new = comparable(from_shot_set(conceal(hidden, 200, seed=4, model=ferguson_world()).shots), ferguson_baseline)
    diagnoser = Diagnoser(new, formed, seed=4, progress=False, baseline=ferguson_baseline)
    start = linear_starts(diagnoser.problem, None, (EFFECTS[name],), diagnoser.rows)[0][0]
    fitted = fit(diagnoser.problem, (EFFECTS[name],), start, diagnoser.rows)
    result = with_form_uncertainty(diagnoser.problem, fitted, ferguson_baseline, diagnoser.rows)
    other = read_along_speed(formed, ferguson_baseline)
    read = with_reading_uncertainty(diagnoser.problem, result, other, diagnoser.rows)
    added = np.diag(read.covariance) - np.diag(result.covariance)
    if same_air:
        np.testing.assert_allclose(added, 0.0, atol=1e-6 * np.diag(result.covariance).max())
    else:
        refit = fit(replace(diagnoser.problem, model=other), (EFFECTS[name],), fitted.theta, diagnoser.rows)
        assert abs(refit.theta[0] - fitted.theta[0]) > 1e-3
        assert np.sqrt(added[0]) == pytest.approx(abs(refit.theta[0] - fitted.theta[0]) / 2, rel=1e-6)
