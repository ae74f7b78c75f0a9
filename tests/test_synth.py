"""Synthetic sessions: valid canonical records, time-ordered validation split, hidden conditions, reproducible."""

import numpy as np
import pytest
from golfflight.flight.air import Air
from golfflight.shots.records import read_shots
from golfflight.shots.synth import MIN_APEX_M, SynthConfig, draw_sessions, generate, sessions_path, validation_sessions

from golfflight.cli import main

N = 400


@pytest.fixture(scope="module")
def synthetic():
    return generate(SynthConfig(n_shots=N, seed=11))


def test_every_shot_is_accounted_for(synthetic):
    assert len(synthetic.records) + sum(synthetic.dropped.values()) == N
    assert sum(s.n_shots for s in synthetic.sessions) == N
    assert all(r.apex_m is None or r.apex_m > MIN_APEX_M - 2.0 for r in synthetic.records)


def test_validation_split_is_the_most_recent_sessions(synthetic):
    sessions = [s.session for s in synthetic.sessions]
    val = {r.session for r in synthetic.records if r.split == "val"}
    first_val = min(sessions.index(s) for s in val)
    assert val == set(sessions[first_val:]) & {r.session for r in synthetic.records}
    share = sum(r.split == "val" for r in synthetic.records) / len(synthetic.records)
    assert 0.08 <= share <= 0.45
    assert max(r.timestamp for r in synthetic.records if r.split == "train") < min(r.timestamp for r in synthetic.records if r.split == "val")


def test_conditions_are_hidden_but_vary_between_sessions(synthetic):
    assert all(r.wind_speed_mps is None and r.temperature_c is None and r.altitude_m is None for r in synthetic.records)
    assert len({round(s.temperature_c, 3) for s in synthetic.sessions}) == len(synthetic.sessions)
    assert np.ptp([s.wind_from_deg for s in synthetic.sessions]) > 30


def test_hidden_air_is_centred_on_the_density_training_assumes():
    """Training flies shots without recorded air at ICAO standard density, so the hidden air must average to it."""
    sessions = draw_sessions(np.random.default_rng(3), 60_000, SynthConfig())
    shots = np.array([s.n_shots for s in sessions], dtype=float)
    air = Air.from_conditions(*(np.array([getattr(s, k) for s in sessions]) for k in ("temperature_c", "altitude_m", "humidity_pct")))
    mean_density = np.average(air.density_kg_m3, weights=shots)
    assert mean_density == pytest.approx(Air.standard().density_kg_m3, rel=0.01)
    assert np.ptp(air.density_kg_m3) > 0.1


def test_flights_are_realistic_per_club(synthetic):
    carry = {}
    for r in synthetic.records:
        carry.setdefault(r.club, []).append(r.carry_y_m)
    if "Driver" in carry and "PW" in carry:
        assert np.median(carry["Driver"]) > np.median(carry["PW"]) + 60
    for r in synthetic.records:
        assert 20.0 < r.carry_y_m < 330.0 and 0.0 < r.landing_angle_deg < 75.0


def test_same_seed_same_set_and_another_seed_another(synthetic):
    again = generate(SynthConfig(n_shots=N, seed=11))
    other = generate(SynthConfig(n_shots=N, seed=12))
    assert again.records == synthetic.records
    assert other.records != synthetic.records


def test_validation_sessions_take_at_least_the_fraction_from_the_end(synthetic):
    chosen = validation_sessions(synthetic.sessions, 0.1)
    assert synthetic.sessions[-1].session in chosen
    assert sum(s.n_shots for s in synthetic.sessions if s.session in chosen) >= 0.1 * N


def test_synth_command_writes_a_valid_canonical_file(tmp_path, capsys):
    out = tmp_path / "set.csv"
    assert main(["synth", "--shots", "120", "--seed", "3", "--out", str(out)]) == 0
    shots = read_shots(out)
    assert 100 <= len(shots) <= 120
    assert sessions_path(out).exists()
    assert "wrote" in capsys.readouterr().out


def test_fly_command_prints_a_drive(capsys):
    assert main(["fly", "--club", "Driver", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"carry_yd"' in out and '"landing_angle_deg"' in out
