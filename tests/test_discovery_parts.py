"""Discovery: the learned correction's term selection, the reported conventions, the gust outside the library and
the proof's bookkeeping."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from golfflight.discovery.conceal import conceal
from golfflight.discovery.correction import (
    TERMS,
    correction_effect,
    features,
    knots_for,
    select_terms,
    term_named,
    terms_for,
)
from golfflight.discovery.effects import EFFECTS, Context, equivalent_altitude_m
from golfflight.discovery.diagnose import inside
from golfflight.discovery.fit import Fit, Scored, fold_thetas
from golfflight.discovery.model import reference
from golfflight.discovery.outside import HEIGHT_GUST, OUTSIDE, HeightGust, air_motion
from golfflight.discovery.prove import (
    TRIPLES,
    Run,
    hidden_within_uncertainty,
    cases,
    draw_effect,
    expected_label,
    read_runs,
    relative_error,
    tables,
)
from golfflight.discovery.report import plus_minus, service_settings, share_interval
from golfflight.discovery.schema import EffectResult
from golfflight.flight.air import pressure_at_altitude
from golfflight.flight.wind import Wind, wind_vector
from golfflight.shots.markdown import replace_section

ICAO = Context(1.225, 15.0)


def test_term_selection_keeps_the_terms_that_made_the_data():
    rng = np.random.default_rng(0)
    n, k = 400, len(TERMS)
    jacobian = rng.normal(size=(n, 5, k))
    truth = np.zeros(k)
    truth[[1, 5]] = (0.8, -0.5)
    z = -(jacobian @ truth) + rng.normal(0, 0.3, (n, 5))
    assert select_terms(z, jacobian) == (1, 5)
    assert select_terms(rng.normal(size=(n, 5)), jacobian) == ()


def test_term_selection_fits_the_explanation_beside_the_terms():
    """Selected with the library explanation's parameters free, a term that only copies what the explanation does is
    not kept; with them held at their start it takes the explanation's place (a correction fitted on a wind once
    took up the wind's own error instead of the model's form)."""
    rng = np.random.default_rng(1)
    n, k = 400, len(TERMS)
    explanation = rng.normal(size=(n, 5, 1))
    terms = rng.normal(size=(n, 5, k))
    terms[..., 2] = explanation[..., 0] + rng.normal(0, 0.1, (n, 5))
    z = -0.8 * explanation[..., 0] + rng.normal(0, 0.3, (n, 5))
    assert select_terms(z, terms) == (2,)
    assert select_terms(z, np.concatenate([explanation, terms], axis=-1), free=1) == ()


def test_fold_parameters_are_the_best_within_the_bounds():
    """A fit at its bound with two nearly collinear parameters: each fold's parameters are the bounded linear least
    squares step, never worse on the fold's own shots than an unbounded step clipped afterwards (which once sent a
    held-out error to ten times the fit's own)."""
    rng = np.random.default_rng(2)
    n = 300
    column = rng.normal(size=(n, 5))
    jacobian = np.stack([column, column + rng.normal(0, 0.01, (n, 5))], axis=-1)
    z = -(jacobian @ np.array([2.0, -1.5])) + rng.normal(0, 1.0, (n, 5))
    effects = (EFFECTS["drag_scale"], EFFECTS["lift_scale"])
    theta = np.array([1.4, 1.0])
    result = Fit(effects, theta, z, jacobian, np.eye(2))
    fold = np.arange(n) % 5
    thetas = fold_thetas(result, fold)
    low, high = np.array([0.7, 0.6]), np.array([1.4, 1.5])
    better = []
    for f, fold_theta in thetas.items():
        assert np.all(fold_theta >= low) and np.all(fold_theta <= high)
        J, r = jacobian[fold != f].reshape(-1, 2), z[fold != f].reshape(-1)
        clipped = np.clip(theta + np.linalg.lstsq(J, -r, rcond=None)[0], low, high)
        cost = [float(np.sum((r + J @ (t - theta)) ** 2)) for t in (fold_theta, clipped)]
        assert cost[0] <= cost[1] + 1e-9
        better.append(cost[0] < cost[1] - 1.0)
    assert any(better)


def test_a_candidate_pinned_at_a_bound_is_not_eligible():
    """A library parameter at its plausible bound (drag x 1.40, the top of its range) says the effect stands in for
    something outside its range, so `diagnose.inside` refuses the candidate; just inside it is eligible, and the
    learned correction's own weights are not judged (East Lake's apex-only rounds once chose drag x 1.40 beside a
    ball speed x 1.12)."""

    def candidate(effects, theta):
        theta = np.asarray(theta, dtype=float)
        result = Fit(effects, theta, np.zeros((1, 5)), np.zeros((1, 5, len(theta))), np.eye(len(theta)))
        return Scored(result, np.zeros((1, 5)), 1.0, 0.0)

    drag, speed = EFFECTS["drag_scale"], EFFECTS["ball_speed_bias"]
    assert not inside(candidate((drag, speed), [1.4, 1.12]))
    assert not inside(candidate((speed,), [0.85]))
    assert inside(candidate((drag, speed), [1.39, 1.12]))
    term = correction_effect((0,))
    assert inside(candidate((drag, term), [1.05, term.parameters[0].high]))


def test_correction_features_are_accelerations_per_unit_weight():
    v = np.array([[0.0, 40.0, 10.0], [3.0, 25.0, -8.0]])
    w = np.array([[300.0, 0.0, 0.0], [250.0, 0.0, -20.0]])
    r = np.array([[0.0, 50.0, 20.0], [1.0, 80.0, 0.0]])
    f = features(v, w, r)
    assert f.shape == (2, len(TERMS), 3)
    drag = f[:, [t.name for t in TERMS].index("-|v| v")]
    np.testing.assert_allclose(drag, -np.linalg.norm(v, axis=1)[:, None] * v)
    lift = f[:, [t.name for t in TERMS].index("m")]
    np.testing.assert_allclose(np.linalg.norm(lift, axis=1), 1.0)
    assert lift[0, 2] > 0
    across = f[:, [t.name for t in TERMS].index("|v| h x")]
    np.testing.assert_allclose(across[:, 0], np.linalg.norm(v, axis=1) * r[:, 2])
    assert across[1, 0] == 0.0 and not across[:, 1:].any(), "nothing at the ground, and only sideways"


def test_hinge_terms_push_only_above_their_knot():
    """By hand: v = (0, 40, 10) m/s, |v| = sqrt(1700) = 41.2311 m/s; at h = 20 m a hinge at 9.5 m gives
    41.2311 x (20 - 9.5) = 432.93 along its axis, at h = 5 m (below the knot) nothing; the shear from the ground is
    41.2311 x 20 = 824.62 at 20 m."""
    v = np.array([[0.0, 40.0, 10.0], [0.0, 40.0, 10.0]])
    w = np.array([[300.0, 0.0, 0.0], [300.0, 0.0, 0.0]])
    r = np.array([[0.0, 50.0, 20.0], [0.0, 10.0, 5.0]])
    names = [t.name for t in terms_for((9.5,))]
    assert names[len(TERMS) :] == ["|v| (h-9.5)+ x", "|v| (h-9.5)+ y"]
    f = features(v, w, r, (9.5,))
    assert f.shape == (2, len(TERMS) + 2, 3)
    np.testing.assert_allclose(f[0, names.index("|v| (h-9.5)+ x")], [432.93, 0.0, 0.0], atol=0.01)
    np.testing.assert_allclose(f[0, names.index("|v| (h-9.5)+ y")], [0.0, 432.93, 0.0], atol=0.01)
    np.testing.assert_allclose(f[0, names.index("|v| h y")], [0.0, 824.62, 0.0], atol=0.01)
    assert not f[1, len(TERMS) :].any(), "nothing below the knot"
    np.testing.assert_array_equal(features(v, w, r), f[:, : len(TERMS)])
    assert (
        term_named("|v| (h-9.5)+ y").meaning.startswith("a push down the line")
        and "9.5 m" in term_named("|v| (h-9.5)+ y").meaning
    )
    assert term_named("-|v| v") is TERMS[0]
    effect = correction_effect((len(TERMS) + 1,), (9.5,))
    assert [p.name for p in effect.parameters] == ["|v| (h-9.5)+ y"]
    np.testing.assert_allclose(
        effect.correction(v, w, r, np.array([[0.002], [0.002]])), [[0, 0.86586, 0], [0, 0, 0]], atol=1e-5
    )


def test_hinge_knots_split_the_median_apex_in_thirds():
    """Median apex 30 m (NaN ignored) -> knots 10 and 20 m; median 2 m -> 0.67 m is below MIN_KNOT_M (1 m), so only
    1.33 m, to 0.1 m; nothing flown -> none."""
    assert knots_for(np.array([27.0, 30.0, 33.0, np.nan])) == (10.0, 20.0)
    assert knots_for(np.array([2.0])) == (1.3,)
    assert knots_for(np.array([np.nan])) == ()


def test_an_explained_share_interval_without_a_bound_above_is_not_written_as_a_number():
    assert share_interval(0.42, 2.78) == "42–278 %"
    assert share_interval(0.07, 28253586.64) == "7 % to over 500 %"
    assert share_interval(0.07, float("inf")) == "7 % to over 500 %"


def test_equivalent_altitude_of_a_density_ratio():
    assert equivalent_altitude_m(1.0, ICAO) == pytest.approx(0.0, abs=1.0)
    at_2377_m = float(pressure_at_altitude(2377.0) / pressure_at_altitude(0.0))
    assert equivalent_altitude_m(at_2377_m, ICAO) == pytest.approx(2377.0, abs=1.0)


def test_service_settings_from_effects():
    effects = [
        EffectResult(name="wind", parameters={"speed_mps": 4.8, "from_deg": 5.0}, uncertainty={}),
        EffectResult(
            name="air_density",
            parameters={"ratio": 0.9, "equivalent_altitude_m": 880.0, "density_kg_m3": 1.1025},
            uncertainty={},
        ),
        EffectResult(name="ball_speed_bias", parameters={"scale": 1.02}, uncertainty={}),
        EffectResult(name="drag_scale", parameters={"scale": 0.95}, uncertainty={}),
        EffectResult(name="landing_elevation", parameters={"height_m": -4.0}, uncertainty={}),
    ]
    settings = service_settings(effects, ICAO).model_dump(exclude_none=True)
    assert settings["wind"] == {"speed_mps": 4.8, "from_deg": 5.0, "profile": "uniform"}
    assert settings["air"] == {"density_kg_m3": 1.1025}
    assert settings["air_as_altitude"] == {"altitude_m": 880.0, "temperature_c": 15.0}
    assert settings["launch_corrections"] == {"ball_speed_scale": 1.02}
    assert settings["coefficient_scales"] == {"drag_scale": 0.95}
    assert settings["ground_height_m"] == -4.0
    assert "wind_at_station" not in settings


def test_a_fitted_wind_as_a_station_reading_is_a_wind_the_service_accepts():
    """With the log profile's mean factor along the flights (1.2 here), the uniform 4.8 m/s is a 4.0 m/s 10 m
    reading; both validate as the service's wind option."""
    from golfflight.contract.requests import WindRequest

    wind = EffectResult(name="wind", parameters={"speed_mps": 4.8, "from_deg": 5.0}, uncertainty={})
    settings = service_settings([wind], ICAO, wind_factor=1.2)
    station = settings.wind_at_station.model_dump(exclude_none=True)
    assert station == {"speed_mps": pytest.approx(4.0), "from_deg": 5.0, "profile": "log", "reference_height_m": 10.0}
    assert WindRequest.model_validate(station).profile == "log"
    assert WindRequest.model_validate(settings.wind.model_dump(exclude_none=True)).profile == "uniform"


def test_plus_minus_uses_the_uncertainty_digits():
    assert plus_minus(4.8123, 0.41, " m/s") == "4.81 ± 0.41 m/s"
    assert plus_minus(0.97483, 0.00087) == "0.97483 ± 0.00087"


def test_every_case_draws_a_size_and_scores_its_error():
    rng = np.random.default_rng(1)
    for case, effects in cases("model") + cases("reference"):
        for name in effects:
            hidden = draw_effect(name, rng)
            if name in EFFECTS:
                assert relative_error(name, hidden, hidden) == 0.0
    assert expected_label(()) == "none" and expected_label(("wind", "ball_speed_bias")) == "ball_speed_bias+wind"
    wind = {"speed_mps": 5.0, "from_deg": 0.0}
    assert relative_error("wind", {"speed_mps": 5.5, "from_deg": 0.0}, wind) == pytest.approx(0.1)


def test_the_gust_blows_only_above_its_height_and_grows_with_it():
    base = Wind.from_components(np.array([1.0, -2.0]), np.array([0.5, 0.0]))
    gust = air_motion({HEIGHT_GUST: {"rate_mps_per_m": 0.2, "height_m": 10.0, "from_deg": 90.0}}, base)
    assert isinstance(gust, HeightGust) and not gust.is_calm and HEIGHT_GUST in OUTSIDE
    heights = np.array([5.0, 30.0])
    extra = gust.velocity(heights) - base.velocity(heights)
    np.testing.assert_allclose(extra, [[0.0, 0.0, 0.0], wind_vector(0.2 * 20.0, 90.0)], atol=1e-12)
    np.testing.assert_allclose(gust.take(np.array([1])).velocity(np.array([30.0])), gust.velocity(heights)[1:])
    assert air_motion({}, base) is base
    calm_below = HeightGust(rate_mps_per_m=0.2, threshold_m=10.0)
    assert not calm_below.is_calm and not calm_below.velocity(np.array([9.0])).any()


def test_a_crosswind_gust_moves_the_model_flights_sideways_and_the_high_ones_more():
    """Hidden in the model's own flights (here the reference world as the model): from the right, so every shot
    lands left of its clean twin, and the higher its apex the more."""
    gust = {HEIGHT_GUST: {"rate_mps_per_m": 0.25, "height_m": 10.0, "from_deg": 90.0}}
    clean, gusty = (conceal(hidden, 60, seed=3, model=reference()).shots.records for hidden in ({}, gust))
    assert [r.shot_id for r in clean] == [r.shot_id for r in gusty]
    drift = np.array([g.carry_x_m - c.carry_x_m for c, g in zip(clean, gusty)])
    apex = np.array([c.apex_m for c in clean])
    assert np.all(drift < 0) and np.median(drift) < -1.0
    assert np.corrcoef(apex, drift)[0, 1] < -0.5


def test_tables_and_section_replacement():
    run = Run(
        "wind",
        0,
        {"wind": {"speed_mps": 4.0, "from_deg": 10.0}},
        300,
        4,
        True,
        "wind",
        True,
        {"wind": {"speed_mps": 4.1, "from_deg": 11.0}},
        {"wind": {"speed_mps": 0.1, "from_deg": 1.0}},
        {"wind": 0.03},
        12.0,
        1.0,
        1.0,
        False,
        {"carry_y_m": 9.0},
        {"carry_y_m": 1.0},
        [],
        3.0,
    )
    clean = Run("clean", 0, {}, 300, 4, False, "none", True, {}, {}, {}, 1.0, 1.0, None, False, {}, {}, [], 3.0)
    text = tables([clean, run], "test model")
    assert "| false alarms on clean sets | 0 of 1 | 0 |" in text and "| wind | 1/1 | 1/1 |" in text
    doc = replace_section("# Title\n\nhand text\n", text, "<!-- BEGIN x -->")
    again = replace_section(doc, "new\n", "<!-- BEGIN x -->")
    assert "hand text" in again and "new" in again and text not in again


def test_prove_runs_only_the_cases_asked_for_into_their_own_section(tmp_path):
    """`prove --cases '^clean$'` (a false-alarm campaign) writes a section of its own, with the false-alarm row and
    none of the rows about hidden effects; a filter that matches nothing is an error naming the cases."""
    from golfflight.cli import main

    out = tmp_path / "discovery.md"
    out.write_text("# Discovery\n\nhand-written\n")
    args = ["prove", "--model", "reference", "--cases", "^clean$", "--clean-sets", "1", "--shots", "40"]
    assert main([*args, "--out", str(out)]) == 0
    page = out.read_text()
    assert "hand-written" in page and "--truth model --cases '^clean$'" in page
    assert "| false alarms on clean sets | 0 of 1 | 0 |" in page and "detection" not in page and "nan" not in page
    dump, again = tmp_path / "runs.json", tmp_path / "again.md"
    assert main([*args, "--out", str(again), "--json", str(dump)]) == 0
    written = again.read_text()
    again.unlink()
    assert main([*args, "--out", str(again), "--tables-from", str(dump)]) == 0
    assert again.read_text() == written, "the tables of a dump are the tables of its run"
    assert main(["prove", "--cases", "^nothing$", "--out", str(out)]) == 2
    assert main(["prove", "--cases", "clean(", "--out", str(out)]) == 2


def test_prove_triples_conceals_three_effects_and_scores_them(tmp_path):
    """`prove --campaign triples` hides three library effects at once beside clean sets and scores whether all three
    are named and fitted within tolerance, in a section of its own."""
    from golfflight.cli import main

    out, dump = tmp_path / "discovery.md", tmp_path / "runs.json"
    args = ["prove", "--model", "reference", "--campaign", "triples", "--cases", "^clean$|^wind", "--seeds", "1"]
    assert main([*args, "--clean-sets", "1", "--shots", "40", "--out", str(out), "--json", str(dump)]) == 0
    runs = read_runs(dump)
    assert [(r.case, len(r.hidden)) for r in runs] == [("clean", 0), ("+".join(TRIPLES[0]), 3)]
    assert set(runs[1].hidden) == set(TRIPLES[0])
    page = out.read_text()
    assert "--campaign triples --cases '^clean$|^wind' --seeds 1" in page
    assert "| false alarms on clean sets | 0 of 1 | 0 |" in page and "| three effects: all three among" in page
    hidden = {name: {} for name in TRIPLES[0]}
    errors = {name: 0.05 for name in TRIPLES[0]}
    label = "+".join(sorted(TRIPLES[0]))
    named = Run("x", 0, hidden, 300, 4, True, label, True, hidden, {}, errors, 2.0, 1.0, 1.0, False, {}, {}, [], 1.0)
    missed = replace(named, fitted={"wind": {}, "unlisted": {}}, parameter_error={"wind": 0.05}, correct=False)
    text = tables([named, missed], "test model", campaign="triples")
    assert "| three effects: all three among those named | 1 of 2 (50%) | ≥ 80 % |" in text
    assert "| three effects: all three fitted within 10 % of their sizes | 1 of 2 (50%) | ≥ 60 % |" in text


def test_the_campaign_counts_hidden_values_within_two_of_their_reported_uncertainty():
    """Each fitted parameter of a hidden effect counts once: within 2 ± of the hidden value or not (air named in its
    other variant is the same air); an effect not named counts nothing."""
    hidden = {"wind": {"speed_mps": 4.0, "from_deg": 10.0}}
    fitted = {"wind": {"speed_mps": 4.3, "from_deg": 11.0}}
    sure = {"wind": {"speed_mps": 0.1, "from_deg": 1.0}}
    run = Run("wind", 0, hidden, 300, 4, True, "wind", True, fitted, sure, {}, 2.0, 1.0, 1.0, False, {}, {}, [], 1.0)
    assert hidden_within_uncertainty(run) == [False, True]  # 0.3 m/s off at +-0.1; 1 deg off at +-1
    air = {"air_density": {"ratio": 0.85}}
    named = {"air_density_only": {"ratio": 0.86, "equivalent_altitude_m": 1300.0}}
    sd = {"air_density_only": {"ratio": 0.006, "equivalent_altitude_m": 50.0}}
    as_other = Run("air", 0, air, 300, 4, True, "air_density_only", False, named, sd, {}, 2.0, 1.0, 1.0, False, {}, {},
                   [], 1.0)
    assert hidden_within_uncertainty(as_other) == [True]
    missed = Run("air", 0, air, 300, 4, False, "none", False, {}, {}, {}, 2.0, 2.0, None, False, {}, {}, [], 1.0)
    assert hidden_within_uncertainty(missed) == []


def test_a_campaign_of_another_session_size_writes_its_own_section():
    """The section's command names the shots per set where they are not the default 300."""
    from golfflight.discovery.prove import command

    base = "prove --model models/default --truth model --campaign baseline --cases '^ball$' --seeds 6"
    assert command("models/default", "model", "^ball$", 6, "baseline") == base
    assert command("models/default", "model", "^ball$", 6, "baseline", 3000) == base + " --shots 3000"


def test_the_baseline_campaign_scores_another_balls_drag_and_lift_beside_its_whole_size():
    """The drag-and-lift row reads the ball's drag and lift against their part of its size, the whole-size row all
    three scales against the whole: one ball passes each, and a ball read as air neither."""
    hidden = {"ball": {"drag_scale": 0.94, "lift_scale": 1.08, "spin_decay_scale": 1.2}}
    # sizes: drag and lift |(-0.06, 0.08)| = 0.1; all three |(-0.06, 0.08, 0.2)| = 0.224
    spin_decay_off = {"ball": {"drag_scale": 0.945, "lift_scale": 1.073, "spin_decay_scale": 0.9}}  # 0.0086 of 0.1
    drag_off = {"ball": {"drag_scale": 0.9505, "lift_scale": 1.08, "spin_decay_scale": 1.2}}  # 0.0105: 10.5 %, 4.7 %
    as_air = {"air_density_only": {"ratio": 0.95, "equivalent_altitude_m": 430.0}}

    def run(fitted: dict, named: str) -> Run:
        errors = {"ball": relative_error("ball", fitted["ball"], hidden["ball"])} if "ball" in fitted else {}
        return Run("ball", 0, hidden, 300, 4, True, named, named == "ball", fitted, {}, errors, 8.0, 1.1, 0.97, False,
                   {}, {}, [], 1.0)

    runs = [run(spin_decay_off, "ball"), run(drag_off, "ball"), run(as_air, "air_density_only")]
    text = tables(runs, "test model", campaign="baseline")
    assert "| the change named (beside others or not), within 10 % of its size | 1 of 3 (33%) | ≥ 90 % |" in text
    assert ("| another ball: named, its drag and lift within 10 % of their size (spin decay left to its ±) | "
            "1 of 3 (33%) | - |") in text


def test_a_baseline_at_three_lower_venues_keeps_the_players_and_records_each_venues_air():
    """The real-air venue case's baseline: the ICAO baseline's sessions (the same players and clubs), one in three at
    each lower venue, flown and recorded in that venue's real air; the two-ball case's new session records the
    baseline's air, the density-only world's its venue's."""
    from golfflight.discovery.prove import (
        BALL_AT_VENUE,
        HIGH_VENUE_REAL,
        HIGH_VENUES,
        LOWER_VENUES,
        baseline_cases,
        recorded_air,
        venue_baseline,
    )
    from golfflight.discovery.recordings import from_shot_set
    from golfflight.flight.air import Air

    assert (HIGH_VENUE_REAL, (HIGH_VENUES[HIGH_VENUE_REAL][0],)) in baseline_cases("reference")
    assert not any(case in HIGH_VENUES for case, _ in baseline_cases("density-only"))
    assert (BALL_AT_VENUE, ("ball",)) in baseline_cases("ferguson")
    assert BALL_AT_VENUE not in dict(baseline_cases("density-only"))  # its air is recorded in every case there
    assert recorded_air(BALL_AT_VENUE, {}) == 1.0 and recorded_air("ball", {}) is None
    assert recorded_air("ball", {"air_density_only": {"ratio": 0.8}}) == 0.8
    icao = venue_baseline(None, 60, 3, (1.0,))
    venues = venue_baseline(None, 60, 3, LOWER_VENUES)
    assert sorted(r.session for r in venues.records) == sorted(r.session for r in icao.records)
    recordings = from_shot_set(venues)
    sessions = sorted(set(recordings.session))
    for k, session in enumerate(sessions):
        density = recordings.density_kg_m3[recordings.session == session]
        assert np.allclose(density, LOWER_VENUES[k % 3] * Air.standard().density_kg_m3, rtol=2e-3)


def test_the_density_only_world_flown_finely_is_the_model_by_rk4_at_a_hundredth_of_a_second():
    """`density-only-rk4` is the density-only world without the service's forward-Euler step: the model's own
    coefficients and air, flown by RK4 at 0.01 s; its cases are the density-only world's."""
    from golfflight.discovery.model import load_model
    from golfflight.discovery.prove import baseline_cases, cases, truth_world
    from golfflight.flight.integrator import RUNGE_KUTTA_4

    served = load_model(None)
    fine = truth_world("density-only-rk4", served)
    assert fine.flyer.rule is RUNGE_KUTTA_4 and fine.flyer.dt_s == 0.01
    assert fine.flyer.model is served.flyer.model and fine.flyer.density_kg_m3 == served.flyer.density_kg_m3
    assert truth_world("density-only", served) is served
    assert baseline_cases("density-only-rk4") == baseline_cases("density-only")
    assert cases("density-only-rk4") == cases("density-only")
