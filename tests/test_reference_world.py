"""The reference world: Reynolds-dependent coefficients, spin decay, step convergence, its calibration on recordings
that may be trained on, and the held-out PGA 2023 check."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import trainable_copy
from golfflight.flight.air import Air
from golfflight.flight.constants import BALL_RADIUS_M, MPH_TO_MPS, YARD_M
from golfflight.flight.physics import initial_state
from golfflight.flight.reference_aero import CALIBRATED, REFERENCE_DT_S, REFERENCE_T_MAX_S, ReferenceAerodynamics
from golfflight.model_export.reference_targets import FITTED_AIR_FACTORS, NORMALIZED_7IRON_FILE, calibration_cells
from golfflight.shots.calibrate_reference import (
    BOUNDS,
    FREE_PARAMETERS,
    MIN_CELL_SHOTS,
    OBSERVABLES,
    RESIDUAL_SCALES,
    TRACKMAN_SPIN_LOSS_PCT,
    FitScaling,
    cells_from_records,
    evaluate,
    evaluate_clubs,
    render_markdown,
    spin_losses,
    table_cells,
    with_air_factors,
)
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import ShotRecord
from golfflight.shots.reference_world import (
    CALIBRATION_AIR,
    ClubAverage,
    default_tour_averages_path,
    fly_reference,
    read_tour_averages,
)
from golfflight.shots.source_air import PGA_2023_TABLE

from flights import simulate

NU = float(CALIBRATION_AIR.kinematic_viscosity_m2_s)
LIFT, DRAG, MOMENT, Q = range(4)

# Launches in the spirit of the tour bag (driver, 5-iron, 8-iron, wedge), not the shared table's rows.
SHOTS = {
    "driver": (76.0, 10.5, 2600.0),
    "5-iron": (60.0, 12.0, 5300.0),
    "8-iron": (52.5, 18.0, 8000.0),
    "wedge": (45.0, 25.0, 9500.0),
}


def coefficients(spin_ratio, reynolds, params=CALIBRATED) -> np.ndarray:
    s, re = np.broadcast_arrays(np.atleast_1d(np.asarray(spin_ratio, float)), np.asarray(reynolds, float))
    return ReferenceAerodynamics(params, NU).coefficients(s, re)


def launch(*rows: tuple[float, float, float]):
    speed, angle, spin = (np.array(column, dtype=float) for column in zip(*rows))
    zeros = np.zeros(len(rows))
    return initial_state(speed, angle, zeros, spin, zeros)


def test_drag_crisis_raises_drag_below_critical_reynolds():
    laminar = CALIBRATED.critical_reynolds - 2.2e4  # 96 % laminar (docs/reference_world.md)
    for s in (0.0, 0.1, 0.3):
        low, high = coefficients(s, laminar)[0, DRAG], coefficients(s, 1.2e5)[0, DRAG]
        assert low > high + 0.15
    assert coefficients(0.0, laminar)[0, DRAG] == pytest.approx(0.5, abs=0.03)
    assert coefficients(0.0, 1.0e5)[0, DRAG] < 0.22


def test_lift_collapses_at_low_reynolds():
    s = np.array([0.1, 0.2, 0.3])
    assert np.all(coefficients(s, 5.0e4)[:, LIFT] < 0.4 * coefficients(s, 1.2e5)[:, LIFT])


def test_lift_grows_with_spin_ratio_and_stays_non_negative():
    s = np.linspace(0.0, 3.0, 301)
    lift = coefficients(s, 1.5e5)[:, LIFT]
    assert np.all(np.diff(lift) > 0)
    grid_s, grid_re = np.meshgrid(np.linspace(0, 10, 101), np.geomspace(1e3, 5e5, 101))
    c = coefficients(grid_s.ravel(), grid_re.ravel())
    assert np.all(np.isfinite(c))
    assert np.all(c[:, LIFT] >= 0) and np.all(c[:, DRAG] > 0) and np.all(c[:, MOMENT] >= 0)
    assert np.all(c[:, Q] == 0.5)


def test_coefficients_are_smooth_in_reynolds_and_spin_ratio():
    re = np.linspace(2e4, 3e5, 20001)
    for s in (0.05, 0.3, 1.0):
        c = coefficients(s, re)
        assert np.max(np.abs(np.diff(c[:, :3], axis=0))) < 1e-3
    c = coefficients(np.linspace(0, 3, 30001), 7.5e4)
    assert np.max(np.abs(np.diff(c[:, :3], axis=0))) < 1e-3


def test_knobs_scale_the_coefficients():
    s, re = np.array([0.05, 0.2, 0.6]), np.array([6e4, 1e5, 2e5])
    base = coefficients(s, re)
    knobs = dataclasses.replace(CALIBRATED, drag_scale=1.2, lift_scale=0.7, spin_decay_scale=1.5)
    scaled = coefficients(s, re, knobs)
    np.testing.assert_allclose(scaled[:, LIFT], 0.7 * base[:, LIFT])
    np.testing.assert_allclose(scaled[:, DRAG], 1.2 * base[:, DRAG])
    np.testing.assert_allclose(scaled[:, MOMENT], 1.5 * base[:, MOMENT])
    np.testing.assert_allclose(scaled[:, Q], base[:, Q])


def test_reynolds_number_uses_the_air_viscosity():
    v = np.array([[0.0, 30.0, 0.0]])
    w = np.array([[300.0, 0.0, 0.0]])
    thin = ReferenceAerodynamics(CALIBRATED, 1.3 * NU)(v, w)
    sea = ReferenceAerodynamics(CALIBRATED, NU)(v, w)
    expected = coefficients(BALL_RADIUS_M * 300.0 / 30.0, 30.0 * 2 * BALL_RADIUS_M / (1.3 * NU))
    np.testing.assert_allclose(thin, expected)
    assert thin[0, DRAG] > sea[0, DRAG]


def test_spin_decays_monotonically():
    flight = fly_reference(launch(*SHOTS.values()), CALIBRATION_AIR, keep_states=True)
    spin = np.stack([np.linalg.norm(s.spin, axis=-1) for s in flight.states])
    assert np.all(np.diff(spin, axis=0) < 0)


def test_spin_loss_matches_trackman_within_two_points():
    """TrackMan's Pro V1x losses at 1/3/5 s, flown with the tour-like launches: each within 2 percentage points."""
    flight = fly_reference(launch(SHOTS["driver"], SHOTS["5-iron"], SHOTS["8-iron"]), CALIBRATION_AIR, keep_states=True)
    spin = np.stack([np.linalg.norm(s.spin, axis=-1) for s in flight.states])
    index = [int(round(t / REFERENCE_DT_S)) for t in (1.0, 3.0, 5.0)]
    loss = 100.0 * (1.0 - spin[index].T / spin[0][:, None])
    target = np.array([TRACKMAN_SPIN_LOSS_PCT[name] for name in ("Driver", "5-iron", "8-iron")])
    assert np.max(np.abs(loss - target)) < 2.0
    assert np.mean(np.abs(loss - target)) < 0.7


def test_thinner_air_carries_farther_and_flies_lower():
    """At 1,500 m (4,900 ft) the rule of thumb (+8.5 % at 7,800 ft, about 1.1 % per 1,000 ft) gives a drive
    about 5 % more carry; slower, spinning shots gain less (the apex falls with the lift), but every one gains."""
    shots = launch(*SHOTS.values())
    sea = fly_reference(shots, Air.from_conditions(25.0, 0.0, 50.0))
    high = fly_reference(shots, Air.from_conditions(25.0, 1500.0, 50.0))
    assert 1.04 < high.carry_m[0] / sea.carry_m[0] < 1.09
    assert np.all(high.carry_m > sea.carry_m * 1.02)
    assert np.all(high.landing_angle_deg < sea.landing_angle_deg)


def test_per_shot_air_matches_shot_by_shot():
    rows = [SHOTS["driver"], SHOTS["wedge"]]
    air = Air.from_conditions(np.array([5.0, 35.0]), np.array([0.0, 2500.0]), np.array([20.0, 80.0]))
    batch = fly_reference(launch(*rows), air)
    for i, row in enumerate(rows):
        single = fly_reference(launch(row), Air(air.density_kg_m3[i], air.kinematic_viscosity_m2_s[i]))
        assert batch.carry_m[i] == pytest.approx(single.carry_m[0], abs=1e-9)


def test_step_is_converged_to_a_centimetre():
    extremes = [(85.0, 12.0, 2000.0), (35.0, 40.0, 11000.0), (22.0, 30.0, 3000.0), (80.0, 30.0, 9000.0)]
    shots = launch(*SHOTS.values(), *extremes)
    model = ReferenceAerodynamics(CALIBRATED, NU)
    rho = CALIBRATION_AIR.density_kg_m3
    coarse = simulate(shots, model, rho, dt=REFERENCE_DT_S, t_max=REFERENCE_T_MAX_S, method="rk4")
    fine = simulate(shots, model, rho, dt=REFERENCE_DT_S / 4, t_max=REFERENCE_T_MAX_S, method="rk4")
    assert np.all(coarse.landed)
    assert np.max(np.linalg.norm(coarse.landing_position - fine.landing_position, axis=1)) < 0.01
    assert np.max(np.abs(coarse.apex_m - fine.apex_m)) < 0.01


def test_reader_converts_units(tmp_path):
    path = tmp_path / "averages.csv"
    header = ",".join(ClubAverage.model_fields)
    path.write_text(header + "\nTest,100,-1,150,1.5,12,3000,30,40,250\n")
    (club,) = read_tour_averages(path)
    assert isinstance(club, ClubAverage) and club.club == "Test"
    assert club.ball_speed_mps == pytest.approx(150 * MPH_TO_MPS)
    assert club.carry_m == pytest.approx(250 * YARD_M)
    assert club.max_height_m == pytest.approx(30 * YARD_M)
    path.write_text(header + "\nTest,100,-1,fast,1.5,12,3000,30,40,250\n")
    with pytest.raises(ValueError, match="line 2"):
        read_tour_averages(path)


def test_shared_data_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("GOLFFLIGHT_SHARED_DATA", str(tmp_path))
    assert shared_data_dir() == tmp_path
    assert default_tour_averages_path().is_relative_to(tmp_path)


def _records(speeds: list[float], carry_m: float | None = 200.0, apex_m: float | None = None) -> list[ShotRecord]:
    return [ShotRecord(shot_id=str(i), ball_speed_mps=v, launch_angle_deg=12.0, launch_direction_deg=0.0,
                       spin_rpm=4000.0, spin_axis_deg=0.0, carry_x_m=0.0 if carry_m else None, carry_y_m=carry_m,
                       apex_m=apex_m)
            for i, v in enumerate(speeds)]


def test_cells_split_a_source_by_ball_speed_and_keep_what_is_recorded_often_enough():
    slow, fast = [45.0] * MIN_CELL_SHOTS, [75.0] * (MIN_CELL_SHOTS - 1)
    (cell,) = cells_from_records("src", _records(slow + fast), CALIBRATION_AIR)
    assert cell.name == "src 0-52 m/s" and cell.n_shots == MIN_CELL_SHOTS
    assert cell.used().tolist() == [True, False, False]
    assert np.all(np.isnan(cell.recorded[:, OBSERVABLES.index("apex_m")]))


def test_a_cell_of_the_worlds_own_flights_has_no_error():
    records = _records([50.0 + i for i in range(MIN_CELL_SHOTS)], carry_m=1.0, apex_m=1.0)
    (cell,) = cells_from_records("own", records, CALIBRATION_AIR, bands=(0.0, 200.0))
    flight = fly_reference(initial_state(**cell.launch), CALIBRATION_AIR)
    own = dataclasses.replace(cell, recorded=np.stack([flight.landing_position[:, 1], flight.apex_m,
                                                       flight.landing_angle_deg], 1))
    result = evaluate([own])
    assert np.allclose(result.scaled_errors(), 0.0, atol=1e-12)
    shorter = dataclasses.replace(own, recorded=own.recorded - np.array([RESIDUAL_SCALES["carry_y_m"], 0.0, 0.0]))
    assert evaluate([shorter]).scaled_errors()[0] == pytest.approx([1.0, 0.0, 0.0])


def test_spin_losses_match_trackmans_pro_v1x_figures():
    for name, target in TRACKMAN_SPIN_LOSS_PCT.items():
        assert np.max(np.abs(spin_losses()[name] - np.array(target))) < 2.0, name


def _calibration_root(tmp_path):
    """The shared data folder without a held-out row (`conftest.trainable_copy`: the driver file's lines before 2943,
    the TOUR Championship's rounds 1-2)."""
    root = shared_data_dir()
    if not (root / NORMALIZED_7IRON_FILE).exists():
        pytest.skip(f"shared data not found at {root}")
    return trainable_copy(root, tmp_path)


def _same_cells(a: list, b: list) -> None:
    assert [c.name for c in a] == [c.name for c in b]
    for one, other in zip(a, b):
        np.testing.assert_array_equal(one.recorded, other.recorded, err_msg=one.name)
        for key, values in one.launch.items():
            np.testing.assert_array_equal(values, other.launch[key], err_msg=f"{one.name} {key}")
        assert one.air.density_kg_m3 == other.air.density_kg_m3, one.name


def test_held_out_rows_change_nothing_in_the_calibration(tmp_path):
    """The reference world's cells from the shared folder and from a copy without a single held-out row are the
    same: no TrackMan line from 2943 and no TOUR Championship round 3-4 shot reaches the teacher's fit."""
    root = _calibration_root(tmp_path)
    _same_cells(calibration_cells(shared_data_dir()), calibration_cells(root))


def test_calibration_needs_no_held_out_file_and_fits_its_cells(tmp_path):
    root = _calibration_root(tmp_path)
    cells = with_air_factors(calibration_cells(root), FITTED_AIR_FACTORS)
    assert {c.source for c in cells} == {
        "trackman-outdoor", "trackman-model", "sentry-2022", "players-2020", "tour-championship-2020",
        "trackman-normalized-7iron", "pga-2023-table"}
    assert {c.name for c in cells if c.source == "pga-2023-table"} == {
        f"pga-2023-table {club}" for club in ("Driver", "5-wood", "Hybrid", "4-iron", "5-iron", "7-iron", "8-iron", "PW")}
    errors = evaluate(cells).scaled_errors()
    used = np.isfinite(errors)
    assert np.sqrt(np.mean(errors[used] ** 2)) < 1.5, "the committed CALIBRATED values are not a fit to these cells"


def test_the_pga_table_is_rendered_per_club_beside_the_cells():
    path = default_tour_averages_path()
    if not path.exists():
        pytest.skip(f"shared data not found at {path}")
    clubs = read_tour_averages(path)
    check = evaluate_clubs(clubs, air=PGA_2023_TABLE.air())
    assert check.outcomes().shape == (12, 3) and np.all(np.isfinite(check.outcomes()))
    records = _records([45.0] * MIN_CELL_SHOTS)
    text = render_markdown(evaluate(cells_from_records("src", records, CALIBRATION_AIR)), CALIBRATED, check,
                           air_factors={"src": 1.05})
    fit, per_club = text.split("### PGA TOUR 2023 averages per club")
    assert "| src 0-52 m/s | 15 |" in fit and "| air density factor of `src`" in fit
    assert "| Driver |" in per_club and "**MAE (bias)**" in per_club


def test_a_table_club_is_one_cell_of_double_weight():
    clubs = read_tour_averages(default_tour_averages_path()) if default_tour_averages_path().exists() else None
    if clubs is None:
        pytest.skip("shared data not found")
    (cell,) = table_cells("t", clubs[:1], CALIBRATION_AIR)
    assert cell.name == "t Driver" and cell.n_shots == 1 and cell.used().all() and cell.weight == 2.0
    assert cell.recorded[0] == pytest.approx([282 * YARD_M, 35 * YARD_M, 39.0])


def test_the_fit_sees_each_parameter_divided_by_its_start_value():
    scaling = FitScaling(CALIBRATED)
    x0 = scaling.start_values()
    low, high = scaling.bounds()
    k = FREE_PARAMETERS.index("drag_base")
    assert x0[k] == pytest.approx(1.0)
    assert low[k] == pytest.approx(BOUNDS["drag_base"][0] / CALIBRATED.drag_base)
    assert np.all(low <= x0) and np.all(x0 <= high)  # critical_reynolds sits on its lower bound: x0 = low there
    assert scaling.parameters(x0) == CALIBRATED
    doubled = scaling.parameters(np.where(np.arange(len(x0)) == k, 2.0, x0))
    assert doubled.drag_base == pytest.approx(2 * CALIBRATED.drag_base) and doubled.lift_max == CALIBRATED.lift_max
