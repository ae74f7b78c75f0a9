"""Properties of the flight engine over the whole valid input range (hypothesis): every flight is finite and
lands, single and batch agree, carry grows with ball speed for a fixed launch in calm air, the simulation is
mirror-symmetric (exactly: the shipped network sees the speed and spin magnitudes only), and spin only decays."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import torch
from golfflight.flight import limits
from golfflight.flight.air import Air
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.conditions import Conditions
from golfflight.flight.engine import MAX_FLIGHT_TIME_S, Launch, ShotFlight
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.flight.problem import FlightProblem
from golfflight.flight.wind import CALM, Wind
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

torch.set_num_threads(1)

BALLOON_SPIN_RPM = 10_000.0
"""Above this spin a fast ball balloons: a scan of the shipped model (0.5-100 m/s in 200 steps) found carry falling
as speed rises at 12,000 rpm and 30 deg (0.47 m, at 100 m/s) and at 15,000 rpm from 25 deg (1.6 m; 7.6 m at 30 deg),
none at 10,000 rpm and below up to 30 deg; hypothesis once drew 77 and 90 m/s at 30 deg and 13,784 rpm (5.2 cm)."""
PLATEAU_M = 0.05
"""How much shorter a faster ball may land where the carry has levelled off (5 cm: far below any reversal a player
could see; hypothesis found plateaus of 0.1 mm, 76 and 96 m/s, and 1.0 cm, 81 and 87 m/s at 160.38 m)."""

PROPERTY = settings(
    max_examples=150,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
"""The same examples on every run, so CI is never red by chance; a new property finding comes from a run with
`--hypothesis-seed` or a changed test, not from a landing."""


def bounded(r: limits.Range) -> st.SearchStrategy[float]:
    return st.floats(r.low, r.high, allow_nan=False, allow_infinity=False)


launches = st.builds(
    Launch,
    bounded(limits.BALL_SPEED_MPS),
    bounded(limits.LAUNCH_ANGLE_DEG),
    bounded(limits.LAUNCH_DIRECTION_DEG),
    bounded(limits.SPIN_RPM),
    bounded(limits.SPIN_AXIS_DEG),
)
airs = st.one_of(
    st.builds(
        Air.from_conditions,
        temperature_c=bounded(limits.TEMPERATURE_C),
        altitude_m=bounded(limits.ALTITUDE_M),
        humidity_pct=bounded(limits.HUMIDITY_PCT),
    ),
    st.builds(
        Air.from_conditions,
        temperature_c=bounded(limits.TEMPERATURE_C),
        pressure_pa=bounded(limits.PRESSURE_HPA).map(lambda hpa: hpa * 100.0),
        humidity_pct=bounded(limits.HUMIDITY_PCT),
    ),
    st.builds(Air.from_density, bounded(limits.AIR_DENSITY_KG_M3)),
)
winds = st.one_of(
    st.just(CALM),
    st.builds(
        Wind,
        bounded(limits.WIND_SPEED_MPS),
        bounded(limits.WIND_FROM_DEG),
        st.sampled_from(["uniform", "log"]),
        bounded(limits.WIND_REFERENCE_HEIGHT_M),
    ),
)
conditions = st.builds(Conditions, airs, winds)


@pytest.fixture(autouse=True)
def no_flush_to_zero():
    """Training (here, or in an earlier test module) turns on flushing of denormal floats for the whole process,
    which breaks hypothesis' float generation; properties run with IEEE floats, as the service does."""
    torch.set_flush_denormal(False)



def assert_sound(flight: ShotFlight) -> None:
    values = [getattr(flight, name) for name in ShotFlight.__dataclass_fields__ if name not in ("states", "rest")]
    assert all(math.isfinite(v) for v in values), flight
    assert 0.0 <= flight.flight_time_s <= MAX_FLIGHT_TIME_S and 0.0 <= flight.apex_time_s <= flight.flight_time_s
    assert flight.carry_m >= 0.0 and flight.apex_m >= 0.0 and flight.landing_speed_mps >= 0.0
    assert flight.carry_m == pytest.approx(math.hypot(flight.landing_x_m, flight.landing_y_m))


@PROPERTY
@given(launch=launches, where=conditions)
def test_every_valid_shot_lands_with_finite_numbers(engine, launch, where):
    flight = engine.fly(FlightProblem.of([launch], conditions=where, keep_states=True))[0]
    assert_sound(flight)
    assert flight.states.positions[-1][2] == pytest.approx(0.0, abs=1e-9)


@PROPERTY
@given(shots=st.lists(st.tuples(launches, conditions), min_size=1, max_size=12))
def test_batch_flights_are_the_single_shot_flights(engine, shots):
    batch = engine.fly_batch(FlightProblem.of([launch for launch, _ in shots], [where for _, where in shots])).shots()
    for (launch, where), flight in zip(shots, batch, strict=True):
        assert_sound(flight)
        single = engine.fly(FlightProblem.of([launch], conditions=where))[0]
        assert flight.carry_m == pytest.approx(single.carry_m, abs=1e-6)
        assert flight.apex_m == pytest.approx(single.apex_m, abs=1e-6)


@PROPERTY
@given(
    speeds=st.lists(bounded(limits.BALL_SPEED_MPS), min_size=2, max_size=6, unique=True),
    angle=st.floats(limits.LAUNCH_ANGLE_DEG.low, 30.0),
    spin=st.floats(limits.SPIN_RPM.low, BALLOON_SPIN_RPM),
)
def test_carry_grows_with_ball_speed_for_a_fixed_launch_in_calm_air(engine, speeds, angle, spin):
    """Up to 30 deg of launch and BALLOON_SPIN_RPM: steeper, faster high-spin shots balloon and may land shorter
    (docs/reliability.md).
    Near the top of the speed range the carry can plateau: hypothesis found 76 and 96 m/s both carrying 159.935 m,
    the faster 0.1 mm shorter (and 81 and 87 m/s 1 cm apart at 160.38 m), so the carry may stay level within PLATEAU_M
    but never fall further."""
    speeds = sorted(speeds)
    problem = FlightProblem.of([Launch(v, angle, 0.0, spin, 0.0) for v in speeds])
    carries = [f.carry_m for f in engine.fly_batch(problem).shots()]
    assert all(b >= a - PLATEAU_M for a, b in zip(carries, carries[1:])), list(zip(speeds, carries))


def mirrored(launch: Launch) -> Launch:
    return launch._replace(launch_direction_deg=-launch.launch_direction_deg, spin_axis_deg=-launch.spin_axis_deg)


@PROPERTY
@given(launch=launches, where=conditions)
def test_mirrored_launch_and_wind_land_mirrored(engine, launch, where):
    wind = dataclasses.replace(where.wind, from_deg=(360.0 - where.wind.from_deg) % 360.0)
    flight = engine.fly(FlightProblem.of([launch], conditions=where))[0]
    mirror = engine.fly(FlightProblem.of([mirrored(launch)], conditions=Conditions(where.air, wind)))[0]
    assert mirror.landing_x_m == pytest.approx(-flight.landing_x_m, abs=1e-6)
    for name in ("landing_y_m", "carry_m", "apex_m", "flight_time_s", "landing_angle_deg", "landing_spin_rpm"):
        assert getattr(mirror, name) == pytest.approx(getattr(flight, name), abs=1e-6), name


def test_the_shipped_network_only_slows_the_spin_and_always_drags():
    """C_M >= 0 (dω/dt = −C_M q d A ω̂ / I: spin never grows) and C_D > 0 over every air speed and spin a flight
    meets, from a rolling ball to the fastest launch plus the strongest wind, at Reynolds scales 0.8-1.25 (thin
    hot air to cold dense air)."""
    speeds = np.linspace(1.0, limits.BALL_SPEED_MPS.high + limits.WIND_SPEED_MPS.high, 60)
    spins = np.linspace(0.0, limits.SPIN_RPM.high, 60) * 2 * math.pi / 60
    v, w = (grid.ravel() for grid in np.meshgrid(speeds, spins))
    v_rel = np.column_stack([np.zeros_like(v), v, np.zeros_like(v)])
    omega = np.column_stack([w, np.zeros_like(w), np.zeros_like(w)])
    model = OnnxCoefficients(model_dir())
    for scale in (0.8, 1.0, 1.25):
        coefficients = model.in_air(model.card.physics.kinematic_viscosity_m2_s / scale)(v_rel, omega)
        assert coefficients[:, 2].min() >= 0.0, "C_M < 0: the spin would grow"
        assert coefficients[:, 1].min() > 0.0, "C_D <= 0: the air would push the ball"
