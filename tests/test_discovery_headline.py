"""report.json's headline (issue 54, item 4): the verdict read in ten seconds. Over a small campaign of concealed sets
(clean, a wind, thin air, a spin bias, a drag scale, a pair, an effect outside the library) flown by the reference
model and diagnosed against it, every headline has at most three sentences of at most 35 words, the first naming what
differs and the second the cause with its fitted value; `golfflight diagnose` prints it first; and each phrase, on
hand-made reports, reads as a person says it."""

from __future__ import annotations

import re

import pytest
from golfflight.discovery.conceal import conceal
from golfflight.discovery.diagnose import diagnose
from golfflight.discovery.headline import MAX_SENTENCES, MAX_WORDS, headline, word_count
from golfflight.discovery.model import reference
from golfflight.discovery.recordings import OBSERVABLES, from_shot_set
from golfflight.discovery.schema import (
    AirRival,
    Ambiguity,
    BaselineInfo,
    Candidate,
    CorrectionSettings,
    EffectResult,
    Heldout,
    Located,
    ModelInfo,
    ObservableStat,
    Report,
    Unlisted,
)
from golfflight.shots.records import write_shots

from golfflight.cli import main

NUMBER = r"\d+(?:\.\d+)?"
PLUS_MINUS = rf"{NUMBER} ± {NUMBER}"

CAMPAIGN = {
    "clean": ({}, r"The recordings match the model within noise: .+", None),
    "wind": (
        {"wind": {"speed_mps": 4.0, "from_deg": 30.0}},
        r"Shots carry [\d.]+ m shorter, .+ than the model\.",
        rf"Most likely a {PLUS_MINUS} m/s wind from \d+° \(from the front right\)\.",
    ),
    "thin air": (
        {"air_density": {"ratio": 0.8}},
        r"Shots carry [\d.]+ m longer, peak [\d.]+ m lower .+",
        rf"Most likely thin air: {PLUS_MINUS} × standard density, as at 1,[89]\d0 m\.",
    ),
    "spin bias": (
        {"spin_bias": {"scale": 1.1}},
        r"Shots carry [\d.]+ m shorter, peak [\d.]+ m higher .+",
        rf"Most likely the launch monitor reads spin (9|10|11)(\.\d)? % low \(true = recorded × {PLUS_MINUS}\)\.",
    ),
    "drag scale": (
        {"drag_scale": {"scale": 1.06}},
        r"Shots carry [\d.]+ m shorter, peak [\d.]+ m lower .+",
        rf"Most likely the model's own form, not the venue or the monitor: drag × 1\.0[5-7]\d* ± {NUMBER}\.",
    ),
    "pair": (
        {"wind": {"speed_mps": 4.0, "from_deg": 200.0}, "spin_bias": {"scale": 1.1}},
        r"Shots carry [\d.]+ m longer, .+",
        rf"Most likely a {PLUS_MINUS} m/s wind from \d+° \(a tailwind\) and a monitor reading spin {NUMBER} % low\.",
    ),
    "outside the library": (
        {"low_speed_drag": {"rise": 0.15, "speed_mps": 45.0}},
        r"Shots carry [\d.]+ m shorter, .+",
        r"Most likely the model's own form, not the venue or the monitor: a learned extra acceleration .+, removing "
        r"\d+ % of the error above noise\.",
    ),
}
"""Each concealed set: what is hidden, and the first and second sentences expected of its headline (None: none)."""


@pytest.mark.parametrize("case", list(CAMPAIGN))
def test_a_campaign_of_concealed_sets_reads_in_three_short_sentences(case):
    hidden, differs, cause = CAMPAIGN[case]
    model = reference()
    recordings = from_shot_set(conceal(hidden, 120, seed=4, model=model).shots, source=f"concealed {case}")
    learned = case == "outside the library"
    report = diagnose(recordings, model, seed=0, with_correction=learned, progress=False).report
    sentences = report.headline
    assert sentences == headline(report), "diagnose fills report.json's headline"
    assert 1 <= len(sentences) <= MAX_SENTENCES
    assert all(word_count(s) <= MAX_WORDS for s in sentences), sentences
    assert re.fullmatch(differs, sentences[0]), sentences
    if cause is None:
        assert not report.systematic and not any(s.startswith("Most likely") for s in sentences)
    else:
        assert re.fullmatch(cause, sentences[1]), sentences
        assert len(sentences) < 3 or sentences[2].startswith("Runner-up"), sentences


def test_diagnose_prints_the_headline_first(tmp_path, capsys):
    recorded = tmp_path / "thin air.csv"
    write_shots(recorded, conceal({"air_density": {"ratio": 0.85}}, 60, seed=9).shots.records)
    assert main(["diagnose", str(recorded), "--model", "reference", "--quiet", "--out", str(tmp_path)]) == 0
    report = Report.model_validate_json((tmp_path / "report.json").read_text())
    printed = capsys.readouterr().out.splitlines()
    assert printed[: len(report.headline) + 1] == [*report.headline, ""], "the headline, then a blank line"
    assert report.headline[1].startswith("Most likely thin air: 0.8")


def _stat(name: str, bias: float, se: float, flagged: bool) -> ObservableStat:
    return ObservableStat(
        name=name,
        n=120,
        bias=bias,
        bias_se=se,
        bias_p=1e-12 if flagged else 0.5,
        spread=1.0,
        rms=1.0,
        expected=1.0,
        rms_ratio=3.0 if flagged else 1.0,
        excess_p=0.5,
        significant=flagged,
    )


CARRY_SHORTER_APEX_LOWER = {"carry_y_m": (-12.34, 0.4), "apex_m": (-2.13, 0.07)}
"""Mean differences (recorded − model) and their standard errors the test flags; every other outcome is clean."""


def _effect(name: str, kind: str = "venue", **values: tuple[float, float]) -> EffectResult:
    """A fitted effect: each parameter as (value, sd)."""
    return EffectResult(
        name=name,
        kind=kind,
        parameters={k: v for k, (v, _) in values.items()},
        uncertainty={k: sd for k, (_, sd) in values.items()},
    )


def _candidate(effects: list[EffectResult], error: float) -> Candidate:
    return Candidate(
        name="+".join(e.name for e in effects),
        effects=effects,
        n_parameters=len(effects),
        heldout_error=error,
        penalty=0.01,
        score=error + 0.01,
    )


def _report(
    effects: list[EffectResult],
    differs: dict[str, tuple[float, float]] = CARRY_SHORTER_APEX_LOWER,
    others: tuple[Candidate, ...] = (),
    ambiguities: tuple[Ambiguity, ...] = (),
    observables: tuple[str, ...] = OBSERVABLES,
    unlisted: Unlisted | None = None,
) -> Report:
    """A report by hand: these outcomes differ, these effects explain them (none: nothing systematic)."""
    stats = [_stat(o, *differs.get(o, (0.01, 0.1)), o in differs) for o in observables]
    systematic = bool(effects)
    zeros = dict.fromkeys(OBSERVABLES, 0.1)
    return Report(
        recordings="by hand",
        n_shots=120,
        n_sessions=6,
        fit_shots=120,
        scored_shots=120,
        observables=list(observables),
        trajectories=0,
        model=ModelInfo(
            name="reference",
            dt_s=0.1,
            integrator="rk4",
            density_kg_m3=1.225,
            model_error=zeros,
            model_error_source={},
            outcome_noise=zeros,
            launch_noise={},
        ),
        systematic=systematic,
        systematic_test={},
        located=Located(
            observables=stats, covariates=[], groups=[], trajectory=[], outliers={}, alpha=0.01, summary=[]
        ),
        effects=effects,
        unlisted=unlisted,
        candidates=([_candidate(effects, 0.9)] if effects else []) + list(others),
        ambiguities=list(ambiguities),
        heldout=Heldout(
            grouping="session",
            n_folds=5,
            before=zeros,
            after=zeros,
            expected=zeros,
            before_error=4.0,
            after_error=0.9,
            improvement=3.1,
            improvement_ci=(2.5, 3.6),
            improvement_by_observable={},
            noise_floor=0.85,
            explained_fraction=0.97 if systematic else None,
            explained_fraction_ci=(0.9, 1.02) if systematic else None,
            absorbs_noise=False,
        ),
        statement="",
        service_settings=CorrectionSettings(),
        seconds=1.0,
    )


WIND = _effect("wind", speed_mps=(4.2, 0.3), from_deg=(30.0, 4.0))
THIN_AIR = _effect("air_density", ratio=(0.79, 0.012), equivalent_altitude_m=(1932.0, 60.0))
SPIN_LOW = _effect("spin_bias", "monitor", scale=(1.09, 0.02))
DRAG = _effect("drag_scale", "form", scale=(1.04, 0.01))
GROUND = _effect("landing_elevation", height_m=(-6.1, 0.4))


def test_the_first_sentence_says_what_differs_in_metres_with_its_direction():
    assert headline(_report([THIN_AIR]))[0] == "Shots carry 12.3 m shorter and peak 2.1 m lower than the model."
    small = {"apex_m": (0.034, 0.004), "flight_time_s": (-0.0712, 0.006)}
    assert headline(_report([THIN_AIR], small))[0] == (
        "Shots peak 0.03 m higher and stay up 0.07 s shorter than the model."
    ), "a small difference is not rounded to nothing"
    side = {**CARRY_SHORTER_APEX_LOWER, "carry_x_m": (5.24, 0.3), "landing_angle_deg": (3.0, 0.1)}
    assert headline(_report([WIND], side))[0] == (
        "Shots carry 12.3 m shorter, peak 2.1 m lower and land 5.2 m further right than the model."
    ), "carry, apex and side first, three at most"


def test_a_baseline_session_is_what_the_new_shots_are_compared_with():
    report = _report([THIN_AIR])
    baseline = BaselineInfo(
        source="last week.csv",
        n_shots=412,
        heldout_error_before=1.8,
        heldout_error_after=1.05,
        form={},
        discrepancy_sd={},
        baseline_density_kg_m3=[1.2, 1.23],
        new_density_kg_m3=[1.2, 1.23],
        baseline_launch={},
        outside_shots=0,
        outside_launch={},
        outside_clubs=[],
        needed="",
        cannot_inform=[],
    )
    against = report.model_copy(update={"baseline": baseline})
    assert headline(against)[0] == (
        "Against the baseline session (412 shots), the new shots carry 12.3 m shorter and peak 2.1 m lower."
    )


def test_clean_recordings_match_the_model_within_noise():
    assert headline(_report([], {})) == [
        "The recordings match the model within noise: nothing departs beyond the expected error.",
        "No cause is needed: no candidate explanation improves held-out shots clearly.",
    ]


def test_a_difference_nothing_explains_says_so_and_names_the_closest_candidate():
    report = _report([], others=(_candidate([WIND], 3.1),))
    assert headline(report)[1].startswith("No single cause explains it on held-out shots")
    assert headline(report)[2] == "Closest: a 4.2 m/s wind from 30°, too small a gain on held-out shots to claim."


def test_a_candidate_that_removes_nothing_is_not_the_closest():
    """A candidate fitted at its null (the ground 0.0 m below the tee) scores no better than the model as is: it is
    not offered as the closest explanation."""
    report = _report([], others=(_candidate([_effect("landing_elevation", height_m=(0.0, 0.4))], 4.2),))
    assert len(headline(report)) == 2


def test_a_candidate_set_aside_for_slower_and_faster_shots_says_why():
    """The best fit, set aside because the slower and the faster half of the shots fit it differently (a form
    difference), is not called too small a gain: the headline says why nothing is claimed."""
    report = _report([], others=(_candidate([WIND], 1.1),))
    halves = {"varies_with_ball_speed": "wind: slower half 4.1, 30, faster half 2.0, 31 (60% of its size apart)"}
    lines = headline(report.model_copy(update={"systematic_test": halves}))
    assert lines[1].startswith("No single cause is claimed: the best fit differs between slower and faster shots")
    assert lines[2] == "Closest: a 4.2 m/s wind from 30°, set aside: slower and faster shots fit it differently."
    assert all(word_count(line) <= MAX_WORDS for line in lines)


@pytest.mark.parametrize(
    ("effect", "cause"),
    [
        (THIN_AIR, "Most likely thin air: 0.79 ± 0.01 × standard density, as at 1,930 m."),
        (
            _effect("air_density", ratio=(1.05, 0.01), equivalent_altitude_m=(-430.0, 90.0)),
            "Most likely dense air: 1.05 ± 0.01 × standard density, as in 1 °C air at sea level.",
        ),
        (WIND, "Most likely a 4.2 ± 0.3 m/s wind from 30° (from the front right)."),
        (
            _effect("wind", speed_mps=(3.0, 0.2), from_deg=(182.0, 5.0)),
            "Most likely a 3.0 ± 0.2 m/s wind from 182° (a tailwind).",
        ),
        (SPIN_LOW, "Most likely the launch monitor reads spin 9 % low (true = recorded × 1.09 ± 0.02)."),
        (
            _effect("ball_speed_bias", "monitor", scale=(0.98, 0.002)),
            "Most likely the launch monitor reads ball speed 2.0 % high (true = recorded × 0.980 ± 0.002).",
        ),
        (
            _effect("launch_angle_bias", "monitor", offset_deg=(1.2, 0.1)),
            "Most likely the launch monitor reads launch angle 1.2 ± 0.1° low.",
        ),
        (
            _effect("launch_direction_bias", "monitor", offset_deg=(-1.5, 0.2)),
            "Most likely the launch monitor reads launch direction 1.5 ± 0.2° too far right.",
        ),
        (GROUND, "Most likely the landing ground lies 6.1 ± 0.4 m below the tee."),
        (DRAG, "Most likely the model's own form, not the venue or the monitor: drag × 1.04 ± 0.01."),
        (
            _effect("spin_decay", "form", scale=(1.31, 0.05)),
            "Most likely the model's own form, not the venue or the monitor: spin decay × 1.31 ± 0.05.",
        ),
        (
            _effect("reynolds_scale", "form", scale=(1.2, 0.1)),
            "Most likely the model's own form, not the venue or the monitor: Reynolds number × 1.2 ± 0.1.",
        ),
        (
            _effect("ball", "ball", drag_scale=(1.04, 0.01), lift_scale=(1.0, 0.01), spin_decay_scale=(0.9, 0.02)),
            "Most likely another ball: it carries 12.3 m shorter (drag × 1.04 ± 0.01).",
        ),
    ],
)
def test_each_cause_reads_with_its_value_in_a_persons_terms(effect, cause):
    assert headline(_report([effect]))[1] == cause


def test_a_learned_correction_is_the_models_own_form():
    learned = Unlisted(
        expression="a = -0.0012 |v| v",
        terms={"drag_v": -0.0012},
        uncertainty={"drag_v": 0.0001},
        meaning={"drag_v": "drag proportional to |v|"},
        heldout_error=1.02,
        library_heldout_error=1.6,
    )
    effect = _effect("unlisted", "form", drag_v=(-0.0012, 0.0001))
    assert headline(_report([effect], unlisted=learned))[1] == (
        "Most likely the model's own form, not the venue or the monitor: a learned extra acceleration no library "
        "effect matches, removing 97 % of the error above noise."
    )


def test_two_and_three_effects_are_named_together_within_the_word_limit():
    assert headline(_report([WIND, SPIN_LOW]))[1] == (
        "Most likely a 4.2 ± 0.3 m/s wind from 30° (from the front right) and a monitor reading spin 9 % low."
    )
    ball = _effect("ball", "ball", drag_scale=(1.04, 0.01), lift_scale=(0.94, 0.01), spin_decay_scale=(0.9, 0.02))
    offset = _effect("spin_axis_bias", "monitor", offset_deg=(3.1, 0.4))
    triple = headline(_report([ball, offset, THIN_AIR]))[1]
    assert triple.startswith("Most likely another ball (lift × 0.94 ± 0.01, drag × 1.04), ")
    assert triple.endswith("a monitor reading spin axis 3.1° too far left and thin air (0.79 × standard).")
    assert word_count(triple) <= MAX_WORDS


def test_the_runner_up_is_the_rival_the_data_cannot_yet_tell_apart():
    rival = _effect("wind", speed_mps=(3.0, 0.2), from_deg=(180.0, 5.0))
    ambiguity = Ambiguity(
        effects=("air_density", "wind"),
        score_difference=0.02,
        difference_ci=(-0.05, 0.08),
        separating_measurement="carry_y_m",
        note="carry is not recorded",
    )
    apex_only = ("apex_m",)
    report = _report([THIN_AIR], others=(_candidate([rival], 0.92),), ambiguities=(ambiguity,), observables=apex_only)
    assert headline(report)[2] == (
        "Runner-up, fitting about as well: a 3.0 m/s wind from 180°; recording carry would tell them apart."
    )


def test_the_venue_air_rival_reads_with_its_fitted_density():
    rival = AirRival(
        explanation="spin_bias+air_density",
        named=False,
        ratio=0.92,
        ratio_sd=0.01,
        equivalent_altitude_m=700.0,
        heldout_error=0.95,
        difference_ci=(-0.02, 0.06),
        separable=False,
        separating_measurement="landing_angle_deg",
        note="landing angle is not recorded",
    )
    ambiguity = Ambiguity(
        effects=("wind+spin_bias", rival.explanation),
        score_difference=0.03,
        difference_ci=rival.difference_ci,
        separating_measurement="landing_angle_deg",
        note=rival.note,
    )
    carry_and_apex = ("carry_y_m", "apex_m")
    report = _report([WIND, SPIN_LOW], ambiguities=(ambiguity,), observables=carry_and_apex)
    assert headline(report.model_copy(update={"air_rival": rival}))[2] == (
        "Runner-up, fitting about as well: spin reading and thin air (0.92 × standard); recording landing angle would "
        "tell them apart."
    )


def test_the_runner_up_is_otherwise_the_closest_explanation_ruled_out():
    ruled_out = (_candidate([SPIN_LOW], 2.76), _candidate([_effect("lift_scale", "form", scale=(1.03, 0.01))], 1.4))
    assert headline(_report([DRAG], others=ruled_out))[2] == (
        "Runner-up, ruled out on held-out shots (error 1.40 against 0.90): the model's own form (lift × 1.03)."
    )
    assert headline(_report([GROUND], others=ruled_out[:1]))[2] == (
        "Runner-up, ruled out on held-out shots (error 2.76 against 0.90): a monitor reading spin 9 % low."
    )
    assert len(headline(_report([GROUND]))) == 2, "no rival tried: no third sentence"
