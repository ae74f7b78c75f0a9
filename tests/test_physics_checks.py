"""`golfflight physics-check`: every formula on a case worked by hand, then the shipped model against the literature
(skipped without the shared data)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from golfflight.evaluation.accuracy_flyers import coefficient_flyer
from golfflight.evaluation.physics_checks import (
    AERO_FILE,
    COEFFICIENTS,
    INSIDE_REQUIRED,
    SPIN_FILE,
    SPIN_TOLERANCE_PCT,
    Neighbourhood,
    SpinDecayMeasurement,
    club_launch,
    effective_coefficients,
    excess,
    flight_points,
    is_fit,
    measured_band,
    measured_set,
    read_aero_literature,
    read_spin_decay,
    reynolds_number,
    run_physics_checks,
    spin_lost,
)
from golfflight.flight.air import Air
from golfflight.flight.constants import (
    BALL_AREA_M2,
    BALL_INERTIA_KG_M2,
    BALL_MASS_KG,
    BALL_RADIUS_M,
    GRAVITY_MPS2,
    RPM_TO_RADPS,
)
from golfflight.flight.physics import aerodynamics
from golfflight.shots.clubs import ClubLaunch
from golfflight.shots.paths import shared_data_dir

from golfflight.cli import main

REPO = Path(__file__).resolve().parents[1]
DEFAULT_MODEL = REPO / "models" / "default"
AIR = Air(1.2, 1.5e-5)
"""Round numbers for hand-worked cases."""

TINY_TABLE = """source,ball,Re,S,CD,CL,method
Alpha 2001 Tab1,ball A,100000,0.20,0.25,0.20,wind tunnel
Alpha 2001 Tab1,ball A,100000,0.22,0.26,0.22,wind tunnel
Alpha 2001 Tab1,ball A,100000,0.21,0.255,0.21,wind tunnel
Beta 2002 Fig3,ball B,110000,0.21,0.28,0.21,indoor range
Beta 2002 Fig3,ball B,200000,0.21,0.22,0.15,indoor range
Gamma 2003 fit,ball C,100000,0.21,0.90,0.90,tunnel 4th-order fit
Delta 2004 Fig2,ball D,100000,,0.30,0.25,radar output along a flight
Epsilon 2005,ball E,100000,0.21,,0.40,spindle tunnel
"""


class ConstantCoefficients:
    """A toy model: the same (C_L, C_D, C_M, C_Q) for every ball."""

    def __init__(self, c_l: float, c_d: float, c_m: float, c_q: float) -> None:
        self.row = np.array([c_l, c_d, c_m, c_q])

    def __call__(self, v_rel: np.ndarray, omega: np.ndarray) -> np.ndarray:
        return np.tile(self.row, (len(v_rel), 1))


def _literature(tmp_path: Path) -> dict:
    path = tmp_path / "aero.csv"
    path.write_text(TINY_TABLE)
    points = read_aero_literature(path)
    return {name: measured_set(points, name) for name in COEFFICIENTS}


# --- formulas, by hand ---------------------------------------------------------------------------------------------


def test_reynolds_number_and_spin_ratio_of_a_state_by_hand(tmp_path):
    # |v| = 5 m/s, d = 0.04267 m, nu = 1.5e-5: Re = 5 * 0.04267 / 1.5e-5 = 14,223.3
    assert reynolds_number(np.array([[3.0, 4.0, 0.0]]), 1.5e-5)[0] == pytest.approx(14223.333, rel=1e-6)
    # a 50 m/s horizontal launch with 3000 rpm back spin: Re = 50 * 0.04267 / 1.5e-5 = 142,233;
    # S = 0.021335 * 314.159 / 50 = 6.70259 / 50 = 0.134052
    flyer = coefficient_flyer(ConstantCoefficients(0.2, 0.25, 0.0, 0.5), "toy")
    points = flight_points(flyer, [ClubLaunch("toy", 50.0, 0.0, 3000.0)], AIR)[0]
    assert points.reynolds[0] == pytest.approx(142233.33, rel=1e-6)
    assert points.spin_ratio[0] == pytest.approx(0.134052, rel=1e-5) and points.time_s[0] == 0.0


def test_effective_coefficients_are_the_literatures_half_rho_v_squared_convention():
    # q = C_Q rho v^2 with C_Q = 0.4 is 0.8 (1/2 rho v^2): C_L 0.2 -> 0.16, C_D 0.25 -> 0.20, C_M 0.01 -> 0.008
    out = effective_coefficients(np.array([[0.2, 0.25, 0.01, 0.4], [0.2, 0.25, 0.01, 0.5]]))
    assert out["C_L"] == pytest.approx([0.16, 0.2]) and out["C_D"] == pytest.approx([0.2, 0.25])
    assert out["C_M"] == pytest.approx([0.008, 0.01]), "C_Q = 0.5 is the usual dynamic pressure"


def test_the_effective_drag_coefficient_gives_the_equations_drag_with_half_rho_v_squared():
    """The bundle's q = C_Q rho v^2 (flight.physics): C_D 0.25 at C_Q 0.4 on a ball at 40 m/s in air of 1.2 kg/m^3
    decelerates it by C_D,eff (1/2 rho v^2) A / m = 0.2 * 960 * A / m, as the literature's C_D of 0.2 would."""
    coefficients = np.array([[0.0, 0.25, 0.0, 0.4]])
    acceleration, _ = aerodynamics(np.array([[0.0, 40.0, 0.0]]), np.array([[100.0, 0.0, 0.0]]), coefficients, 1.2)
    c_d = effective_coefficients(coefficients)["C_D"][0]
    assert c_d == pytest.approx(0.2)
    assert -acceleration[0, 1] == pytest.approx(c_d * 0.5 * 1.2 * 40.0**2 * BALL_AREA_M2 / BALL_MASS_KG, rel=1e-12)
    assert -acceleration[0, 1] == pytest.approx(5.978, abs=1e-3)


def test_fits_and_rows_without_re_or_s_or_a_value_are_not_measurements(tmp_path):
    measured = _literature(tmp_path)
    assert is_fit("Naruo2004 TransJSME-B 70:2371 fit", "wind tunnel") and is_fit("Ferguson2022 ISEA", "same fit")
    assert not is_fit("Acushnet US6729976 Tab3 PP", "indoor test range")
    assert list(measured["C_D"].value) == [0.25, 0.26, 0.255, 0.28, 0.22], "no fit, no row without S, no blank C_D"
    assert list(measured["C_L"].value) == [0.20, 0.22, 0.21, 0.21, 0.15, 0.40]
    assert set(measured["C_D"].publication) == {"Alpha 2001", "Beta 2002"}


def test_band_lookup_on_a_hand_made_table(tmp_path):
    measured = _literature(tmp_path)
    # at (1e5, 0.21): the three Alpha points (dS <= 0.01 -> <= 0.0625 of the window) and Beta's at 1.1e5
    # ((ln 1.1 / ln 1.25)^2 = 0.18) are inside; Beta's at 2e5 is not (ln 2 > ln 1.25): 4 points, 2 publications
    band = measured_band(np.array([1e5]), np.array([0.21]), measured["C_D"])
    assert band.covered[0] and band.low[0] == pytest.approx(0.25 - 0.02) and band.high[0] == pytest.approx(0.28 + 0.02)
    lift = measured_band(np.array([1e5]), np.array([0.21]), measured["C_L"])
    assert lift.low[0] == pytest.approx(0.20 - 0.01) and lift.high[0] == pytest.approx(0.40 + 0.01)
    # why a point is not covered
    re = np.array([1e5, 1e5, 3e4, 3e5, 2e5])
    s = np.array([0.30, 0.15, 0.21, 0.21, 0.21])
    band = measured_band(re, s, measured["C_D"])
    assert not band.covered.any() and np.isnan(band.low).all()
    assert list(band.reason) == ["high S", "low S", "low Re", "high Re", "sparse"]
    # at (8.2e4, 0.21) only Alpha's three points are near ((ln(1e5 / 8.2e4) / ln 1.25)^2 = 0.63; Beta's ln(1.1e5 /
    # 8.2e4) > ln 1.25): enough points, one publication, so no band unless one publication is allowed
    alone = measured_band(np.array([8.2e4]), np.array([0.21]), measured["C_D"])
    assert not alone.covered[0] and alone.reason[0] == "sparse"
    one_source = Neighbourhood(min_publications=1)
    assert measured_band(np.array([8.2e4]), np.array([0.21]), measured["C_D"], one_source).covered[0]
    five_points = Neighbourhood(min_points=5)
    assert not measured_band(np.array([1e5]), np.array([0.21]), measured["C_D"], five_points).covered[0]


def test_excess_is_signed_distance_outside_the_band(tmp_path):
    measured = _literature(tmp_path)
    band = measured_band(np.array([1e5, 1e5, 1e5, 1e5]), np.array([0.21, 0.21, 0.21, 0.40]), measured["C_D"])
    out = excess(np.array([0.25, 0.32, 0.20, 0.25]), band)  # band [0.23, 0.30]; the last point is not covered
    assert out[:3] == pytest.approx([0.0, 0.02, -0.03]) and np.isnan(out[3])


def test_spin_loss_of_a_constant_moment_coefficient_against_the_closed_form():
    """No lift, no drag: the ball launched level keeps v = (0, v0, -g t), so |v|^2 = v0^2 + g^2 t^2, and with a
    constant C_M, d|w|/dt = -C_M C_Q rho d A |v|^2 / I integrates to |w0| - K (v0^2 t + g^2 t^3 / 3),
    K = C_M C_Q rho d A / I. Forward Euler sums the same at the steps' starts: K dt sum_n (v0^2 + g^2 n^2 dt^2)."""
    c_m, c_q, v0, rpm, dt = 4e-4, 0.5, 50.0, 3000.0, 0.1
    flyer = coefficient_flyer(ConstantCoefficients(0.0, 0.0, c_m, c_q), "toy", dt_s=dt, density_kg_m3=AIR.density_kg_m3)
    times = (1.0, 3.0, 5.0)
    lost = spin_lost(flyer, [ClubLaunch("toy", v0, 0.0, rpm)], AIR, times)[0]
    k = c_m * c_q * AIR.density_kg_m3 * 2 * BALL_RADIUS_M * BALL_AREA_M2 / BALL_INERTIA_KG_M2
    w0 = rpm * RPM_TO_RADPS
    for t, share in zip(times, lost):
        closed_form = k * (v0**2 * t + GRAVITY_MPS2**2 * t**3 / 3) / w0
        n = round(t / dt)
        euler = k * dt * (n * v0**2 + GRAVITY_MPS2**2 * dt**2 * (n - 1) * n * (2 * n - 1) / 6) / w0
        assert share == pytest.approx(euler, rel=1e-9)
        assert share == pytest.approx(closed_form, rel=1e-2), "Euler's O(dt) lag: g^2 t^2 dt / 2 of v0^2 t, < 1 %"
    assert lost[-1] == pytest.approx(0.1, abs=0.02), "a case of TrackMan's size: about 10 % at 5 s"


def test_spin_decay_rows_are_read_and_the_others_left(tmp_path):
    path = tmp_path / "spin.csv"
    path.write_text(
        "source,ball,club_or_S,quantity,value,method\n"
        "Acushnet US8016695 Tab6B,Pro V1x,driver (launch ~3400 rpm),spin lost at 1/3/5 s (% of launch),"
        "3.1/8.8/12.8,TrackMan radar\n"
        "tmelevation derived,Pro V1x,driver/5-iron/8-iron,mean decay rate over 5 s (rpm/s),87/198/226,derived\n"
        "Naruo2004 eq14,SD432,S=0.05,torque coeff Cm,0.00148,fit\n"
    )
    assert read_spin_decay(path) == [SpinDecayMeasurement("driver", 3400.0, (1.0, 3.0, 5.0), (3.1, 8.8, 12.8))]
    assert club_launch("driver", 3400.0) == ClubLaunch("Driver", 76.5, 10.5, 3400.0)
    with pytest.raises(ValueError, match="no club"):
        club_launch("putter")


def test_a_missing_or_malformed_literature_table_is_one_error_line(tmp_path, capsys):
    assert main(["physics-check", "--data-dir", str(tmp_path), "--out", str(tmp_path / "r.md")]) == 2
    assert "aero_coefficients_curated.csv not found" in capsys.readouterr().err
    (tmp_path / "bad.csv").write_text("source,Re\nx,1\n")
    with pytest.raises(ValueError, match="missing"):
        read_aero_literature(tmp_path / "bad.csv")


# --- the shipped model against the literature ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report():
    data = shared_data_dir()
    if not (data / AERO_FILE).is_file() or not (data / SPIN_FILE).is_file():
        pytest.skip("needs the shared data's literature folder")
    if not (DEFAULT_MODEL / "model_card.json").is_file():
        pytest.skip("needs the committed models/default bundle")
    return run_physics_checks(DEFAULT_MODEL, data)


def test_the_shipped_model_loses_spin_like_trackmans_measurements(report):
    assert [c.launch.name for c in report.spin] == ["Driver", "5-iron", "8-iron"]
    for check in report.spin:
        assert abs(check.difference_at_check_pct) <= SPIN_TOLERANCE_PCT, (check.launch.name, check.model_lost_pct)
        assert np.all(np.diff(check.model_lost_pct) > 0), "spin only ever decays"


KNOWN_LIFT_MISS = {
    "b8bf638df1808902aa40536d7a8f2ffdbc8c1f0978b16314b0c163c5f413740b":
        "the 3-wood's descent (Re 7-9e4, S 0.23-0.29): lift 0.01 below Acushnet's indoor range and the TopFlite "
        "radar fit (docs/physics_checks.md)",
    "2b3db399b93aa761898031608ae1fe42c14ddaa754880826dea1a74254a116d4":
        "the 3-wood's descent (Re 7-8e4, S 0.25): lift up to 0.006 below the band on 49 % of its covered points; "
        "the issue-22 default (docs/physics_checks.md)",
}
"""Models known to miss the lift band, by ONNX hash: a retrained model is held to the band again."""


def _shipped_hash() -> str:
    card = DEFAULT_MODEL / "model_card.json"
    return json.loads(card.read_text())["onnx"]["sha256"] if card.is_file() else ""


@pytest.mark.parametrize("name", [
    "C_D",
    pytest.param("C_L", marks=pytest.mark.xfail(_shipped_hash() in KNOWN_LIFT_MISS, strict=True,
                                                 reason=KNOWN_LIFT_MISS.get(_shipped_hash(), ""))),
])
def test_the_shipped_models_coefficients_lie_in_the_measured_band_where_measurements_cover_the_flight(report, name):
    """On every club's flight, at least INSIDE_REQUIRED of the points with a measured band lie inside it (flights
    with fewer than 5 covered points are too short a stretch to judge). The driver's flight, where the measurements
    are densest, must be covered for a quarter of its points at least, so the check is never empty."""
    driver = next(c for c in report.clubs if c.points.club == "Driver")
    assert driver.checks[name].covered_share >= 0.25
    judged = [c for c in report.clubs if c.checks[name].band.covered.sum() >= 5]
    outside = {c.points.club: round(c.checks[name].inside_share, 2) for c in judged
               if c.checks[name].inside_share < INSIDE_REQUIRED}
    assert not outside, outside


def test_the_command_writes_its_report_into_the_docs_section(report, tmp_path, capsys):
    out = tmp_path / "physics.md"
    out.write_text("# kept\n")
    assert main(["physics-check", "--model", str(DEFAULT_MODEL), "--out", str(out)]) == 0
    text = out.read_text()
    assert text.startswith("# kept\n") and "<!-- BEGIN generated by `golfflight physics-check` -->" in text
    assert "| Driver |" in text and "| LW |" in text and "| 8-iron |" in text and "**Spin decay:" in text
    assert all(f"**{name}:" in text for name in COEFFICIENTS)
    assert "wrote" in capsys.readouterr().out
    assert math.isclose(float(report.air.density_kg_m3), 1.225, rel_tol=1e-3), "ICAO standard air"
