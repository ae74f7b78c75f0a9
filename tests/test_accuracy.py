"""`golfflight accuracy` on small hand-made inputs (a tiny bundle, a few clubs, hand-written TrackMan and pbp exports,
the TOURCAST fixtures): the three flyers, the held-out line range and rounds, the per-shot wind fit, and the report;
the real-data checks run only where the shared data and the committed models exist."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch
from golfflight.evaluation.accuracy import (
    DRIVER_FILE,
    PATH_FIGURE,
    TOURCAST_PBP,
    TOURCAST_TRAJECTORIES,
    ball_types,
    compare_clubs,
    ferguson_flyer,
    model_flyer,
    outcome_errors,
    path_errors,
    per_model,
    run_accuracy,
)
from golfflight.contract.problems import launch_problem
from golfflight.evaluation.accuracy_finetune import finetune_study, round_number
from golfflight.evaluation.accuracy_sets import (
    SONY_TRAJECTORIES,
    TOUR_CHAMPIONSHIP_PBP,
    held_out_driver_shots,
    tee_groups,
    tour_championship_shots,
)
from golfflight.evaluation.accuracy_slow import SLOW_SHOTS, fly_slow
from golfflight.evaluation.accuracy_winds import (
    TRAINING_CONDITIONS_FILE,
    anova,
    compare_training_winds,
    fit_winds,
    group_of,
    group_winds,
    measured_paths,
    training_winds,
)
from golfflight.evaluation.held_out import held_out_results
from golfflight.flight.air import Air
from golfflight.flight.coefficients import FERGUSON_2022, QuadraticSpinRatio
from golfflight.flight.constants import FOOT_M, MPH_TO_MPS, YARD_M
from golfflight.flight.outcomes import Flight
from golfflight.flight.physics import State, initial_state
from golfflight.flight.wind import Wind, wind_vector
from golfflight.model_export.export import export_checkpoint
from golfflight.model_export.finetune import finetune
from golfflight.model_export.training import TrainConfig, train
from golfflight.shots.heldout import HELD_OUT, shot_round
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.pbp import SCORE_TO_PAR, hole_pars
from golfflight.shots.records import ShotRecord, ShotSet
from golfflight.shots.reference_world import TOUR_AVERAGES_FILE, ClubAverage, fly_reference
from golfflight.shots.source_air import PGA_2023_TABLE, TOUR_CHAMPIONSHIP_2020
from golfflight.weights_schema.bundle import load_bundle
from scipy.stats import f_oneway

from golfflight.cli import main

from flights import simulate

torch.set_num_threads(1)
FIXTURES = Path(__file__).parent / "fixtures"
REPO = Path(__file__).resolve().parents[1]
FIRST_HELD_OUT_LINE = HELD_OUT[0].first_line
CLUBS = [
    ClubAverage(
        club="Driver",
        club_speed_mph=113,
        attack_angle_deg=-1,
        ball_speed_mph=168,
        smash_factor=1.49,
        launch_angle_deg=11,
        spin_rpm=2600,
        max_height_yd=34,
        land_angle_deg=38,
        carry_yd=278,
    ),
    ClubAverage(
        club="7-iron",
        club_speed_mph=90,
        attack_angle_deg=-4,
        ball_speed_mph=121,
        smash_factor=1.34,
        launch_angle_deg=16.5,
        spin_rpm=7000,
        max_height_yd=33,
        land_angle_deg=50,
        carry_yd=172,
    ),
]


@pytest.fixture(scope="module")
def bundle(tiny_shots, tmp_path_factory):
    root = tmp_path_factory.mktemp("acc")
    train(
        tiny_shots,
        root / "run",
        TrainConfig(variant="phys-nn+", hidden=(16,), epochs=2, batch_size=32, lr=3e-3),
        progress=False,
    )
    export_checkpoint(root / "run", root / "bundle")
    return root / "bundle"


def _launches(n: int, seed: int = 3) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    return {
        "ball_speed_mps": rng.uniform(55, 75, n),
        "launch_angle_deg": rng.uniform(9, 16, n),
        "launch_direction_deg": rng.uniform(-3, 3, n),
        "spin_rpm": rng.uniform(2000, 4000, n),
        "spin_axis_deg": rng.uniform(-8, 8, n),
    }


def _flight(landing: list[list[float]], apex: list[float], angle_deg: float = 40.0, time_s: float = 6.0) -> Flight:
    n = len(landing)
    down = np.radians(angle_deg)
    velocity = np.tile([0.0, 30.0 * np.cos(down), -30.0 * np.sin(down)], (n, 1))
    position = np.column_stack([np.array(landing), np.zeros(n)])
    return Flight(
        np.ones(n, bool),
        position,
        velocity,
        np.zeros((n, 3)),
        np.full(n, time_s),
        np.array(apex),
        np.full(n, time_s / 2),
    )


def test_outcome_errors_on_hand_made_shots():
    shots = ShotSet(
        [
            ShotRecord(
                ball_speed_mps=70,
                launch_angle_deg=11,
                launch_direction_deg=0,
                spin_rpm=2500,
                spin_axis_deg=0,
                carry_x_m=3.0,
                carry_y_m=200.0,
                apex_m=30.0,
                flight_time_s=6.5,
                landing_angle_deg=38.0,
            ),
            ShotRecord(
                ball_speed_mps=50,
                launch_angle_deg=16,
                launch_direction_deg=0,
                spin_rpm=7000,
                spin_axis_deg=0,
                carry_x_m=0.0,
                carry_y_m=150.0,
            ),
        ]
    )
    errors = outcome_errors(_flight([[0.0, 204.0], [0.0, 150.0]], [31.0, 28.0]), shots)
    assert errors["carry_m"] == pytest.approx([204.0 - np.hypot(3, 200), 0.0])
    assert errors["side_m"] == pytest.approx([-3.0, 0.0]) and errors["landing_m"] == pytest.approx([5.0, 0.0])
    assert errors["apex_m"][0] == pytest.approx(1.0) and np.isnan(errors["apex_m"][1])
    assert errors["landing_angle_deg"][0] == pytest.approx(2.0) and errors["flight_time_s"][0] == pytest.approx(-0.5)


def test_path_errors_compare_positions_at_the_same_time():
    times = np.arange(0.0, 3.01, 0.1)
    states = [State(np.array([[0.0, 10.0 * t, 0.01 + 5.0 * t]]), np.zeros((1, 3)), np.zeros((1, 3))) for t in times]
    flight = Flight(
        np.array([True]),
        np.zeros((1, 3)),
        np.zeros((1, 3)),
        np.zeros((1, 3)),
        np.array([2.55]),
        np.array([10.0]),
        np.array([1.0]),
        times,
        states,
    )
    t = np.arange(0.0, 2.0001, 0.01)
    measured = np.column_stack([t, np.full_like(t, 1.0), 10.0 * t, 5.0 * t])
    paths = path_errors(flight, [measured])
    assert paths.at(1.0) == pytest.approx([1.0]), "1 m to the side, same along and up"
    assert len(paths.at(2.5)) == 0, "the measured flight ended at 2 s"


def test_clubs_are_compared_in_the_stated_air(bundle):
    flyer = model_flyer(bundle)
    standard, thin = compare_clubs(flyer, CLUBS), compare_clubs(flyer, CLUBS, Air.from_conditions(25.0, 2000.0))
    assert standard.density_kg_m3 == pytest.approx(Air.standard().density_kg_m3)
    assert standard.model.shape == (2, 3) and np.all(thin.model[:, 0] > standard.model[:, 0]), (
        "thin air carries further"
    )
    assert standard.mean_absolute_error == pytest.approx(np.mean(np.abs(standard.model - standard.targets), axis=0))


def test_the_ferguson_flyer_is_quadratic_spin_ratio_through_the_same_simulate_call():
    """Hand check: the flyer's carry, apex and land angle are those of `QuadraticSpinRatio(FERGUSON_2022)` flown
    directly by `simulate` in standard air at the bundle's step; in thin air only the density changes."""
    launch = _launches(5)
    flyer = ferguson_flyer(dt_s=0.1, t_sim_s=10.0)
    direct = simulate(initial_state(**launch), QuadraticSpinRatio(FERGUSON_2022), density=1.225, dt=0.1, t_max=10.0)
    flown = flyer.flight(launch_problem(launch))
    assert flyer.density_kg_m3 == 1.225 and flyer.label == "Ferguson 2022"
    assert flown.carry_m == pytest.approx(direct.carry_m, rel=1e-12)
    assert flown.apex_m == pytest.approx(direct.apex_m, rel=1e-12)
    assert flown.landing_angle_deg == pytest.approx(direct.landing_angle_deg, rel=1e-12)
    assert np.all((direct.carry_m > 150) & (direct.carry_m < 300)), "plausible drives"
    thin = Air.from_conditions(25.0, 2000.0)
    in_thin = simulate(initial_state(**launch), QuadraticSpinRatio(), density=thin.density_kg_m3, dt=0.1, t_max=10.0)
    assert flyer.flight(launch_problem(launch, thin)).carry_m == pytest.approx(in_thin.carry_m, rel=1e-12)


def test_models_that_fly_alike_are_flown_once(bundle):
    calls = []
    flyers = [model_flyer(bundle, "real"), model_flyer(bundle, "synthetic"), ferguson_flyer()]
    results = per_model(flyers, lambda flyer: calls.append(flyer.label) or len(calls))
    assert calls == ["real", "Ferguson 2022"] and results == {"real": 1, "synthetic": 1, "Ferguson 2022": 2}


def _trackman_rows(launch: dict[str, np.ndarray], balls: list[str]) -> list[str]:
    flight = fly_reference(initial_state(**launch), Air.from_conditions(20.0, 0.0, 50.0))
    rows = []
    for i in range(len(balls)):
        cells = [
            "Driver",
            balls[i],
            launch["ball_speed_mps"][i] / MPH_TO_MPS,
            launch["launch_angle_deg"][i],
            launch["launch_direction_deg"][i],
            launch["spin_rpm"][i],
            launch["spin_axis_deg"][i],
            flight.apex_m[i] / FOOT_M,
            flight.flight_time_s[i] * 0.95,
            flight.carry_m[i] / YARD_M,
            flight.landing_position[i, 0] / YARD_M,
            flight.landing_angle_deg[i],
            flight.flight_time_s[i],
        ]
        rows.append(",".join(c if isinstance(c, str) else f"{c:.6f}" for c in cells))
    return rows


def _trackman_export(path: Path, n_held_out: int = 24) -> None:
    """A TrackMan-style export (imperial units, units row) whose measured driver shots sit on both sides of the
    held-out boundary: lines 3 to 2942 repeat one shot (trainable), lines 2943 on are `n_held_out` shots flown
    through the reference world, every other one a Premium ball."""
    header = [
        "Club",
        "Ball",
        "Ball Speed",
        "Launch Angle",
        "Launch Direction",
        "Spin Rate",
        "Spin Axis",
        "Max Height - Height",
        "Last data Point - Time",
        "Carry Flat - Length",
        "Carry Flat - Side",
        "Carry Flat - Land. Angle",
        "Carry Flat - Time",
    ]
    units = ["", "", "[mph]", "[deg]", "[deg]", "[rpm]", "[deg]", "[ft]", "[s]", "[yds]", "[yds]", "[deg]", "[s]"]
    trainable = _trackman_rows({k: v[:1] for k, v in _launches(1, seed=9).items()}, ["Premium"])[0]
    balls = ["Premium" if i % 2 else "Range" for i in range(n_held_out)]
    held_out = _trackman_rows(_launches(n_held_out, seed=5), balls)
    lines = [",".join(header), ",".join(units)] + [trainable] * (FIRST_HELD_OUT_LINE - 3) + held_out
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def test_only_the_held_out_lines_of_the_trackman_file_are_evaluated(tmp_path):
    export = tmp_path / "data.csv"
    _trackman_export(export, n_held_out=6)
    shots, note = held_out_driver_shots(export)
    lines = [int(s) for s in shots.column("shot_id")]
    assert lines == list(range(FIRST_HELD_OUT_LINE, FIRST_HELD_OUT_LINE + 6)), "the 2940 lines before are not read"
    assert f"lines {FIRST_HELD_OUT_LINE} onward" in note and "6 rows" in note
    assert [r.ball for r in shots.records] == ["Range", "Premium"] * 3


def test_the_held_out_range_of_the_shared_driver_file():
    path = shared_data_dir() / DRIVER_FILE
    if not path.is_file():
        pytest.skip("needs the shared TrackMan driver sessions")
    shots, _ = held_out_driver_shots(path)
    lines = np.array([int(s) for s in shots.column("shot_id")])
    assert len(lines) > 100 and lines.min() >= FIRST_HELD_OUT_LINE


FIXTURE_PARS = {1: 4, 2: 3, 3: 4}
"""The pars `_tour_championship_pbp` gives the holes of the TOURCAST pbp fixture."""


def _tour_championship_pbp(path: Path) -> Path:
    """The TOURCAST pbp fixture (rounds 1-2) played again as rounds 3-4, its radar row without a spin given one, and
    each player's hole scored (`textScore`) so that its par is FIXTURE_PARS's (a hole whose strokes no score name
    fits is scored 'Double Bogey+')."""
    with (FIXTURES / "tourcast_pbp.csv").open(newline="") as handle:
        rows = [{**row, "radarData.launchSpin": "5200" if row["radarData.launchSpin"] == "0" else
                 row["radarData.launchSpin"]} for row in csv.DictReader(handle)]
    rows += [{**row, "roundNumber": str(int(row["roundNumber"]) + 2)} for row in rows]
    strokes: dict[tuple[str, str, str], int] = {}
    for row in rows:
        key = (row["roundNumber"], row["holeNumber"], row["playerId"])
        strokes[key] = max(strokes.get(key, 0), int(row["shotNumber"]))
    names = {over: name for name, over in SCORE_TO_PAR.items()}
    for row in rows:
        over = strokes[(row["roundNumber"], row["holeNumber"], row["playerId"])] - FIXTURE_PARS[int(row["holeNumber"])]
        row["textScore"] = names.get(over, "Double Bogey+")
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return path


def test_only_rounds_3_4_of_the_tour_championship_are_evaluated_grouped_by_par(tmp_path):
    path = _tour_championship_pbp(tmp_path / TOUR_CHAMPIONSHIP_PBP)
    shots, note = tour_championship_shots(path)
    ids = list(shots.column("shot_id"))
    assert ids and {shot_round(i) for i in ids} == {3, 4}, "rounds 1-2 may be trained on: not evaluated"
    assert "rounds 3-4 (held out" in note
    assert hole_pars(path) == FIXTURE_PARS
    groups = tee_groups(shots, hole_pars(path))
    assert [i for i, par3 in zip(ids, groups["par3"]) if par3] == ["901-R3-H2-P22222-S1"]
    assert not np.any(groups["par3"] & groups["par4_5"]) and np.all(groups["par3"] | groups["par4_5"])


def test_hole_pars_come_from_strokes_and_scores_of_the_trainable_rounds_only(tmp_path):
    """Par = strokes less the score's strokes over par, the most common answer per hole; in the TOUR Championship
    the rounds 3-4 rows are not read (here three players of round 3 would outvote round 1's one)."""
    rows = ["roundNumber,holeNumber,playerId,shotNumber,textScore"]
    rows += [f"1,1,1,{shot},Par" for shot in range(1, 5)] + [f"1,2,1,{shot},Birdie" for shot in (1, 2)]
    rows += [f"3,1,{player},{shot},Par" for player in (1, 2, 3) for shot in (1, 2, 3)]
    for path in (tmp_path / "other.csv", tmp_path / TOUR_CHAMPIONSHIP_PBP):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("\n".join(rows) + "\n")
    assert hole_pars(tmp_path / TOUR_CHAMPIONSHIP_PBP) == {1: 4, 2: 3}
    assert hole_pars(tmp_path / "other.csv") == {1: 3, 2: 3}, "a file not split by rounds is read whole"


def _fly_with_wind(flyer, launch: dict[str, np.ndarray], x: np.ndarray, y: np.ndarray):
    """Trajectories [T, 4] (t, x, y, z relative to the start) of launches flown in a known uniform wind per shot,
    and a radar-tracked time of 90 % of each flight."""
    flight = flyer.flight(launch_problem(launch, keep_states=True, wind=Wind.from_components(x, y)))
    start = flight.states[0].position
    positions = np.stack([s.position for s in flight.states]) - start[None]
    ids = [f"901-R1-H{1 + i % 2}-P{i}-S1" for i in range(len(x))]
    trajectories, tracked = {}, {}
    for j, shot_id in enumerate(ids):
        aloft = flight.times_s <= flight.flight_time_s[j]
        trajectories[shot_id] = np.column_stack([flight.times_s[aloft], positions[aloft, j]])
        tracked[shot_id] = 0.9 * flight.flight_time_s[j]
    return ids, trajectories, tracked


@pytest.mark.parametrize("which", ["ferguson", "bundle"])
def test_the_wind_fit_recovers_a_known_wind(bundle, which):
    """Flown in a known uniform wind per shot (cross, head and tail), the fit with the same model finds it again;
    through a bundle too, whose float32 graph inputs would hide scipy's default finite-difference step."""
    flyer = ferguson_flyer() if which == "ferguson" else model_flyer(bundle)
    launch = _launches(4, seed=11)
    x, y = np.array([2.0, -3.0, 0.5, 0.0]), np.array([-4.0, 1.5, 3.0, 0.0])
    ids, trajectories, tracked = _fly_with_wind(flyer, launch, x, y)
    paths = measured_paths(ids, launch, trajectories, tracked, flyer.dt_s)
    assert np.all(paths.counts >= 30), "positions up to the tracked time, at every step"
    fit = fit_winds(flyer, paths)
    assert fit.x_mps == pytest.approx(x, abs=0.02) and fit.y_mps == pytest.approx(y, abs=0.02)
    assert np.all(fit.rms_fit_m < 0.01) and np.all(fit.rms_calm_m[:3] > 1.0)


def test_wind_components_round_trip_through_the_wind_object():
    """x right, y down the line (m/s) -> speed and from-direction -> the same air velocity, as discovery reads it."""
    from golfflight.discovery.effects import wind_from_components

    x, y = np.array([2.0, -1.0, 0.0]), np.array([-3.0, 0.0, 4.0])
    wind = Wind.from_components(x, y)
    assert wind_vector(wind.speed_mps, wind.from_deg)[:, :2] == pytest.approx(np.column_stack([x, y]))
    assert wind.from_deg[1] == pytest.approx(90.0), "air moving left blows from the right"
    assert (wind.speed_mps[0], wind.from_deg[0]) == pytest.approx(wind_from_components(2.0, -3.0))


def test_groups_and_the_anova_of_fitted_winds():
    assert group_of("016-R2-H15-P48822-S1") == "016-R2-H15" and group_of("016-R3-H3-P1-S1-f2") == "016-R3-H3"
    assert group_of("2943") is None
    values = np.array([1.0, 1.5, 0.5, 3.0, 3.4, 2.6, 2.9, -1.0])
    groups = np.array(["a", "a", "a", "b", "b", "b", "b", "c"], dtype=object)
    result = anova(values, groups)
    expected = f_oneway(values[:3], values[3:7])
    assert (result.n_groups, result.n_shots) == (2, 7), "a group of one shot tells nothing about the spread"
    assert result.f == pytest.approx(expected.statistic) and result.p == pytest.approx(expected.pvalue)
    assert result.between_sd == pytest.approx(np.std([1.0, 2.975], ddof=1))
    kept = values[:7]
    total = np.sum((kept - kept.mean()) ** 2)
    within = np.sum((values[:3] - 1.0) ** 2) + np.sum((values[3:7] - 2.975) ** 2)
    assert result.between_fraction == pytest.approx(1 - within / total)
    assert result.within_sd == pytest.approx(np.sqrt(within / 5))


def test_training_winds_are_compared_with_the_fitted_group_means(tmp_path):
    from golfflight.evaluation.accuracy_winds import WindFit

    ids = [f"016-R1-H{h}-P{p}-S1" for h in (1, 2, 3) for p in (1, 2)]
    x = np.array([1.0, 1.2, -2.0, -2.2, 0.4, 0.6])
    fit = WindFit(ids, x, -x, np.zeros(6), np.zeros(6), 1)
    fitted = group_winds(fit)
    assert [g.group for g in fitted] == ["016-R1-H1", "016-R1-H2", "016-R1-H3"]
    assert fitted[0].x_mps == pytest.approx(1.1) and fitted[0].sd_x_mps == pytest.approx(np.std([1.0, 1.2], ddof=1))
    assert training_winds(tmp_path) is None, "no file: skipped"
    entries = [{"group": f"016-R1-H{h}", "source": "sentry", "n_shots": 2, "x_mps": 2 * v, "y_mps": -2 * v + 0.1,
                "speed_mps": 0.0, "from_deg": 0.0} for h, v in ((1, 1.1), (2, -2.1), (3, 0.5))]
    entries.append({"group": "006-R1-H1", "x_mps": 0.0, "y_mps": 0.0})
    (tmp_path / TRAINING_CONDITIONS_FILE).write_text(json.dumps({"wind": entries, "air": [], "ball": []}))
    comparison = compare_training_winds(training_winds(tmp_path), fitted)
    assert (comparison.n_groups, comparison.n_training_groups) == (3, 4)
    assert comparison.correlation_x == pytest.approx(1.0) and comparison.correlation_y == pytest.approx(1.0)
    assert comparison.mean_difference_y == pytest.approx(np.mean([-2.2 + 0.1 + 1.1, 4.2 + 0.1 - 2.1, -1.0 + 0.1 + 0.5]))


def test_slow_shots_have_a_source_and_fly():
    flown = fly_slow(ferguson_flyer())
    assert all(shot.source and "http" in shot.source for shot in SLOW_SHOTS)
    assert [s.ball_speed_mph for s in SLOW_SHOTS] == [60.0, 90.0, 130.0]
    assert np.all(np.diff(flown["carry"]) > 0) and np.all(flown["apex"] > 5)


def test_the_finetune_study_tunes_early_rounds_and_measures_later_ones(bundle, tiny_shots):
    from golfflight.shots.records import read_shots

    records = read_shots(tiny_shots).records[:120]
    shots = ShotSet([r.model_copy(update={"split": None, "session": f"901-R{1 + i * 4 // len(records)}",
                                          "shot_id": f"901-R{1 + i * 4 // len(records)}-H1-P{i}-S1"})
                     for i, r in enumerate(records)])
    assert round_number("006-R3", None) == 3 and round_number(None, "006-R12-H1-P1-S1") == 12
    study = finetune_study(model_flyer(bundle), shots, CLUBS, finetune, epochs=2, lrs=(3e-3,), batch_size=32)
    assert study.n_measured == 60 and study.n_train + study.n_val <= 60
    assert len(study.before["carry_m"]) == 60 and set(study.validation) == {3e-3}
    assert study.improved == (study.validation[3e-3][0] < study.base_validation_m)


def _data_dir(root: Path) -> Path:
    (root / TOUR_AVERAGES_FILE).parent.mkdir(parents=True)
    fields = list(ClubAverage.model_fields)
    rows = [",".join(fields)] + [",".join(str(getattr(c, f)) for f in fields) for c in CLUBS]
    (root / TOUR_AVERAGES_FILE).write_text("\n".join(rows) + "\n")
    _trackman_export(root / DRIVER_FILE)
    copies = (
        ("tourcast_shot_trajectory.csv", TOURCAST_TRAJECTORIES),
        ("tourcast_pbp.csv", TOURCAST_PBP),
        ("tourcast_shot_trajectory.csv", SONY_TRAJECTORIES),
    )
    for source, target in copies:
        (root / target).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(FIXTURES / source, root / target)
    _tour_championship_pbp(root / TOUR_CHAMPIONSHIP_PBP)
    return root


def test_accuracy_report_on_hand_made_data(bundle, tmp_path):
    data = _data_dir(tmp_path / "shared")
    out = tmp_path / "docs" / "accuracy.md"
    report = run_accuracy(bundle, out, tmp_path / "docs" / "figures", data, finetune_epochs=2, synthetic=bundle,
                          finetune=finetune)
    labels = ["real-data model", "synthetic model", "Ferguson 2022"]
    assert report.labels == labels and set(report.driver) == set(labels)
    assert len(report.driver_shots) == 24 and min(int(s) for s in report.driver_shots.column("shot_id")) >= 2943
    assert report.pga["real-data model"].model.shape == (2, 3)
    assert len(report.tourcast["Ferguson 2022"]["carry_m"]) == 3 and len(report.paths["real-data model"].at(1.0)) == 3
    assert (tmp_path / "docs" / "figures" / PATH_FIGURE).is_file()
    assert set(report.winds) == set(labels) and len(report.winds["real-data model"].shot_ids) == 3
    assert report.study is None, "the fixture has rounds 1-2 only: nothing to measure"
    text = out.read_text()
    for heading in ("TrackMan outdoor drivers", "Premium balls", "All balls", "TOUR Championship 2020",
                    "PGA TOUR 2023", "The paper's figures", "Slow shots", "TRAINING set", "Latent winds",
                    "Fine-tuning"):
        assert heading in text, heading
    assert "| landing error, yd |" in text and "| real-data model | synthetic model | Ferguson 2022 | target |" in text
    assert "4.75" in text and "met**" in text
    assert "same ONNX graph" in text and "needs shots in rounds [1, 2] and [3, 4]" in text
    assert "No `training_conditions.json`" in text and f"](figures/{PATH_FIGURE})" in text
    assert len(report.tour_championship["real-data model"]["apex_m"]) == 4
    shots, _ = tour_championship_shots(data / TOUR_CHAMPIONSHIP_PBP)
    ferguson = ferguson_flyer(model_flyer(bundle).dt_s, model_flyer(bundle).max_flight_time_s)
    in_event_air = outcome_errors(ferguson.flight(launch_problem(shots.launch(), TOUR_CHAMPIONSHIP_2020.air())), shots)
    assert report.tour_championship["Ferguson 2022"]["apex_m"] == pytest.approx(in_event_air["apex_m"], rel=1e-12)
    assert {c.density_kg_m3 for c in report.pga.values()} == {PGA_2023_TABLE.air().density_kg_m3}
    assert "(held out: rounds 3-4)" in text and "| all tee shots: apex MAE, ft |" in text
    assert "| par 3 tee shots: apex bias, ft |" in text and "below Ferguson 2022's" in text
    held_out, training = text.split("## Training data and studies")
    assert "PGA TOUR 2023" not in held_out and "(a TRAINING set: a fit, not a check)" in training
    assert "| **MAE** |" in training and "| **bias** |" in training


def test_missing_data_is_announced(bundle, tmp_path, capsys):
    out = tmp_path / "accuracy.md"
    args = ["accuracy", "--model", str(bundle), "--synthetic", str(bundle), "--out", str(out), "--data-dir",
            str(tmp_path / "none")]
    assert main(args) == 0
    text = out.read_text()
    assert text.count("_Skipped") == 5 and "Skipped" in capsys.readouterr().out
    assert "Slow shots" in text and "4.75" in text, "the context needs no data"


def test_default_models_card_tells_its_held_out_errors_as_the_runtime_flies_them():
    """The shipped card's held-out errors are what the runtime path measures now, on the held-out rows of
    shots.heldout (TrackMan lines 2943 on, TOUR Championship rounds 3-4): a stale or flattering card fails."""
    model, data = REPO / "models" / "default", shared_data_dir()
    if not (data / DRIVER_FILE).is_file() or not (model / "model_card.json").is_file():
        pytest.skip("needs the shared data and the committed models/default bundle")
    card, _ = load_bundle(model)
    recorded = {h.name: h for h in card.held_out or []}
    measured = {h.name: h for h in held_out_results(model, data)}
    assert set(recorded) == set(measured) == {h.name for h in HELD_OUT}
    for held in HELD_OUT:
        assert recorded[held.name].rows == measured[held.name].rows == held.rows(), held.name
    for name, result in measured.items():
        assert result.errors == pytest.approx(recorded[name].errors, rel=1e-6), name


@pytest.mark.parametrize("first_line", ["", "sep=,\n"])
def test_ball_types_are_keyed_like_the_loaders_shot_ids(tmp_path, first_line):
    """Each shot's ball, by the shot_id the TrackMan loader gives it (its file line), also after Excel's optional
    'sep=,' line (which once hid the header, so every ball read as blank)."""
    from golfflight.shots.trackman import load_trackman

    export = tmp_path / "export.csv"
    export.write_text(first_line + (FIXTURES / "trackman_export.csv").read_text())
    balls = ball_types(export)
    shot_ids = [record.shot_id for record in load_trackman(export, skip_bad_rows=True).records]
    assert shot_ids and all(balls[shot_id] for shot_id in shot_ids)
    assert balls[shot_ids[0]] == "Premium"
