"""The one Flyer: every caller that flies the served bundle flies the same shot to the engine's carry for the same
maximum flight time; the lookup and the card's ball are checked where the bundle is assembled; the step rule and the
record are objects the integrator calls."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from built_wheel import PIP, build_wheel
from golfflight.contract.problems import launch_problem
from golfflight.discovery.model import from_bundle, load_model
from golfflight.discovery.simulator import Setup, setup_flight
from golfflight.evaluation.accuracy_flyers import model_flyer
from golfflight.flight.air import Air
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.environment_variables import MODEL as MODEL_ENV
from golfflight.flight.coefficients import QuadraticSpinRatio
from golfflight.flight.constants import GRAVITY_MPS2
from golfflight.flight.field import BallInAir
from golfflight.flight.flyer import MAX_FLIGHT_TIME_S, FixedCoefficients, Flyer, load_flyer
from golfflight.flight.integrator import (
    FORWARD_EULER,
    RUNGE_KUTTA_4,
    STEP_RULES,
    GroundPlane,
    StatesRecord,
    SummaryRecord,
    integrate,
)
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import FlightProblem, Launch
from golfflight.shots.ground_fit import RestShots, landings
from golfflight.weights_schema.bundle import CARD_FILE, BundleError
from test_readme import venv_with_these_packages

ROOT = Path(__file__).resolve().parents[1]

SKY_BALL = Launch(75.0, 70.0, 0.0, 3000.0, 0.0)
"""In the air longer than the card's t_sim (10 s) and shorter than the engine's limit (20 s): a caller that stopped
at t_sim would not land it."""



def launch_columns(launch: Launch) -> dict[str, np.ndarray]:
    return {name: np.array([value]) for name, value in zip(Launch._fields, launch, strict=True)}


def test_every_caller_flies_the_shot_to_the_engines_carry_for_the_same_time(engine):
    flyer = engine.flyer
    single = engine.fly(FlightProblem.of([SKY_BALL]))[0]
    assert single.flight_time_s > flyer.card.physics.t_sim_s
    calm_air = Air(flyer.density_kg_m3, flyer.kinematic_viscosity_m2_s)
    discovery = from_bundle()
    setup = Setup(launch_columns(SKY_BALL), np.ones(1), np.full(1, discovery.flyer.density_kg_m3), np.zeros((1, 2)),
                  np.zeros(1), np.ones((1, 3)))
    accuracy = model_flyer(None)
    level = RestShots("one", np.array([SKY_BALL]), np.full(1, np.nan), np.zeros(1), np.full(1, np.nan))
    evaluate = pytest.importorskip("golfflight.model_export.evaluate")
    carries = {
        "engine.fly_batch": engine.fly_batch(FlightProblem.of([SKY_BALL])).shots()[0].carry_m,
        "engine.fly_batch, columns (sweep)": engine.fly_batch(FlightProblem.of(np.array([SKY_BALL]))).carry_m[0],
        "discovery from_bundle": setup_flight(setup, discovery.flyer).carry_m[0],
        "accuracy model_flyer": accuracy.flight(launch_problem(launch_columns(SKY_BALL))).carry_m[0],
        "evaluate runtime path": evaluate.runtime_flight(None, launch_columns(SKY_BALL), calm_air).carry_m[0],
        "ground fit landings": landings(level, load_flyer()).carry_m[0],
    }
    for caller, carry in carries.items():
        assert carry == pytest.approx(single.carry_m, abs=1e-9), caller
    longest = max(flyer.card.physics.t_sim_s, MAX_FLIGHT_TIME_S)
    times = {
        "engine": engine.max_steps * engine.dt,
        "flyer": flyer.max_flight_time_s,
        "discovery": discovery.flyer.max_flight_time_s,
        "accuracy": accuracy.max_flight_time_s,
        "ground fit and evaluate (load_flyer)": load_flyer().max_flight_time_s,
    }
    for caller, seconds in times.items():
        assert seconds == pytest.approx(longest, abs=1e-9), caller


def test_the_default_is_found_one_way(tmp_path, monkeypatch):
    copy = shutil.copytree(model_dir(), tmp_path / "bundle")
    monkeypatch.setenv(MODEL_ENV, str(copy))
    assert load_flyer().bundle_dir == copy == load_model(None).flyer.bundle_dir
    monkeypatch.delenv(MODEL_ENV)
    assert load_flyer().bundle_dir == model_dir()


@pytest.mark.parametrize(("field", "value"), [("ball_mass_kg", 0.0459), ("ball_radius_m", 0.0215)])
def test_a_card_with_another_ball_is_refused(tmp_path, field, value):
    bundle = shutil.copytree(model_dir(), tmp_path / "bundle")
    card = json.loads((bundle / CARD_FILE).read_text())
    card["physics"][field] = value
    (bundle / CARD_FILE).write_text(json.dumps(card))
    with pytest.raises(BundleError, match=f"ball is not the one the engine flies: {field} {value:g}"):
        load_flyer(bundle)


def test_step_rules_are_named_objects_and_both_records_give_the_same_flight():
    assert STEP_RULES == {"euler": FORWARD_EULER, "rk4": RUNGE_KUTTA_4}
    state = initial_state(np.array([70.0, 40.0, 60.0]), np.array([11.0, 25.0, 14.0]), np.zeros(3),
                          np.array([2500.0, 8000.0, 4000.0]), np.array([0.0, 10.0, -5.0]))
    field = BallInAir(QuadraticSpinRatio(), 1.225)
    heights = GroundPlane(np.array([0.0, 2.0, -1.0]))
    for rule in (FORWARD_EULER, RUNGE_KUTTA_4):
        summary = integrate(state, field, 0.05, 400, rule, heights, SummaryRecord)
        states = integrate(state, field, 0.05, 400, rule, heights, StatesRecord)
        assert summary.states is None and len(states.states) == len(states.times_s) > 1
        np.testing.assert_array_equal(summary.landing_position, states.landing_position)
        np.testing.assert_array_equal(summary.apex_m, states.apex_m)
        np.testing.assert_array_equal(summary.flight_time_s, states.flight_time_s)
    euler, rk4 = (integrate(state, field, 0.05, 400, rule, heights).carry_m for rule in (FORWARD_EULER, RUNGE_KUTTA_4))
    assert not np.allclose(euler, rk4, atol=1e-6)


def test_the_batch_flight_scales_coefficients_and_adds_an_acceleration_per_ball():
    """`Flyer.flight` takes discovery's per-ball coefficient scales and extra acceleration: ones and a zero term
    change nothing, bit for bit; more drag on one ball shortens that ball's carry alone; a constant 1 m/s^2 push to
    the right moves a flight in a vacuum 0.5 a t^2 right."""
    flyer = Flyer(FixedCoefficients(QuadraticSpinRatio()), 0.01, 15.0, 1.225, 1.5e-5, RUNGE_KUTTA_4)
    state = initial_state(np.full(3, 70.0), np.full(3, 11.0), np.zeros(3), np.full(3, 2500.0), np.zeros(3))
    plain = flyer.flight(FlightProblem(state))
    ones = flyer.flight(FlightProblem(state, coefficient_scale=np.ones((3, 3)),
                                      correction=lambda v, w, r: np.zeros_like(v)))
    np.testing.assert_array_equal(ones.landing_position, plain.landing_position)
    scale = np.array([[1.0, 1.0, 1.0], [1.0, 1.2, 1.0], [1.0, 1.0, 1.0]])
    draggy = flyer.flight(FlightProblem(state, coefficient_scale=scale))
    assert draggy.carry_m[1] < plain.carry_m[1] - 5 and draggy.carry_m[[0, 2]] == pytest.approx(plain.carry_m[[0, 2]])
    vacuum = Flyer(FixedCoefficients(lambda v, w: np.zeros((len(v), 4))), 0.01, 15.0, 1.225, 1.5e-5, RUNGE_KUTTA_4)
    pushed = vacuum.flight(FlightProblem(state, correction=lambda v, w, r: np.tile([1.0, 0.0, 0.0], (len(v), 1))))
    vz, z0 = 70.0 * np.sin(np.radians(11.0)), state.position[0, 2]
    time_s = (vz + np.sqrt(vz**2 + 2 * GRAVITY_MPS2 * z0)) / GRAVITY_MPS2
    assert pushed.flight_time_s == pytest.approx(time_s, abs=1e-4)  # the landing interpolated across a 0.01 s step
    assert pushed.landing_position[:, 0] == pytest.approx(0.5 * time_s**2, abs=1e-3)


def test_a_ball_that_rises_again_below_its_ground_keeps_its_first_landing_and_apex(engine):
    """A low, spinning drive is down through z = 0 within its first step, then its lift carries it up again (-0.10 m
    at 0.1 s, back above the tee by 0.4 s). A batch sets landed balls aside only now and then (`SetAside`), and a
    record of states flies every ball to the batch's last landing, so the ball flies on below its ground meanwhile:
    it must keep the landing and apex of its first crossing, as the single shot (which stops there) does."""
    low, drive = Launch(64.0, -1.0, 0.0, 6500.0, 0.0), Launch(60.0, 12.0, 0.0, 3000.0, 0.0)
    single = engine.fly(FlightProblem.of([low]))[0]
    assert single.flight_time_s < engine.dt
    for keep_states in (False, True):
        flown = engine.fly_batch(FlightProblem.of([low, drive], keep_states=keep_states)).shots()[0]
        for name in ("carry_m", "flight_time_s", "apex_m", "apex_time_s", "landing_speed_mps"):
            assert getattr(flown, name) == pytest.approx(getattr(single, name), abs=1e-9), (keep_states, name)


INSTALLED_DEFAULTS = """
from golfflight.cli import build_parser
from golfflight.discovery.model import load_model
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.flyer import load_flyer
from golfflight.evaluation.accuracy_flyers import model_flyer

parser = build_parser()
found = {
    "diagnose": load_model(parser.parse_args(["diagnose", "shots.csv", "--out", "x"]).model).flyer.bundle_dir,
    "accuracy": model_flyer(parser.parse_args(["accuracy"]).model).bundle_dir,
    "physics-check": model_flyer(parser.parse_args(["physics-check"]).model).bundle_dir,
    "evaluate": model_dir(parser.parse_args(["evaluate", "--data", "d", "--runs", "r", "--out", "o"]).bundle),
    "ground-fit": load_flyer(parser.parse_args(["ground-fit"]).model).bundle_dir,
}
for command, bundle in found.items():
    print(command, bundle)
"""


def test_an_installed_wheel_finds_its_bundle_for_every_command_without_model(tmp_path):
    """Built and installed into a fresh environment's prefix (which sees this interpreter's dependencies, whether it
    runs from a venv or the system Python), run outside the checkout: every command that flies the default bundle
    finds <prefix>/share/golfflight/models/default."""
    wheel = build_wheel(tmp_path)
    prefix = tmp_path / "env"
    python = venv_with_these_packages(prefix)
    # --ignore-installed: with --prefix, pip would otherwise uninstall the golfflight this interpreter has installed
    install = ["install", "--no-deps", "--ignore-installed", "--prefix", str(prefix)]
    subprocess.run([str(python), *PIP[1:], *install, str(wheel)], check=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = subprocess.run([str(python), "-c", INSTALLED_DEFAULTS], cwd=elsewhere, check=False,
                         env={"PATH": "/usr/bin:/bin"}, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    shipped = prefix / "share" / "golfflight" / "models" / "default"
    found = dict(line.split(" ", 1) for line in run.stdout.splitlines())
    assert found == dict.fromkeys(("diagnose", "accuracy", "physics-check", "evaluate", "ground-fit"), str(shipped))
