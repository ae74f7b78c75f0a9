"""Discovery: the locate statistics on crafted residuals, the folds and the session bootstrap."""

from __future__ import annotations

import numpy as np
from golfflight.discovery.fit import cluster_bootstrap, folds
from golfflight.discovery.locate import group_test, holm, locate, mean_test, slope_test
from golfflight.discovery.recordings import OBSERVABLES, Recordings


def crafted(n: int = 600, seed: int = 0) -> tuple[Recordings, np.ndarray, np.ndarray]:
    """Recordings with random launches in 12 sessions, unit-sigma noise residuals on every observable."""
    rng = np.random.default_rng(seed)
    launch = {
        "ball_speed_mps": rng.uniform(35, 75, n),
        "launch_angle_deg": rng.uniform(8, 30, n),
        "launch_direction_deg": rng.normal(0, 2, n),
        "spin_rpm": rng.uniform(2000, 9000, n),
        "spin_axis_deg": rng.normal(0, 4, n),
    }
    session = np.array([f"S{i % 12:02d}" for i in range(n)], dtype=object)
    club = np.array(["Driver", "7-iron", "PW"], dtype=object)[rng.integers(0, 3, n)]
    order = np.arange(n) // 12
    recordings = Recordings(
        launch, np.zeros((n, 5)), session, club, order, np.array([str(i) for i in range(n)], dtype=object)
    )
    return recordings, rng.normal(0, 1, (n, 5)), np.ones((n, 5))


def test_mean_test_bias_and_clustering():
    rng = np.random.default_rng(1)
    groups = np.repeat(np.arange(20), 30)
    noise = rng.normal(0, 1, 600)
    assert mean_test(noise, groups)[2] > 0.01
    assert mean_test(noise + 0.3, groups)[2] < 1e-4
    shared = noise + rng.normal(0, 1, 20)[groups]
    assert mean_test(shared, groups)[1] > 2 * noise.std() / np.sqrt(600)


def test_slope_and_group_tests():
    rng = np.random.default_rng(2)
    x = rng.uniform(0, 10, 400)
    groups = np.repeat(np.arange(10), 40)
    y = rng.normal(0, 1, 400)
    assert slope_test(y, x, groups)[2] > 0.01
    slope, _, p = slope_test(y + 0.2 * x, x, groups)
    assert p < 1e-6 and slope > 0
    labels = np.array(["a", "b", "c", "d"])[rng.integers(0, 4, 400)]
    assert group_test(y, labels)[1] > 0.01
    assert group_test(y + (labels == "c") * 1.0, labels)[1] < 1e-6


def test_holm():
    assert holm([0.001, 0.003, 0.03, 0.5], alpha=0.01) == [True, True, False, False]
    assert holm([0.02, 0.5], alpha=0.01) == [False, False]


def test_locate_finds_a_bias_only_where_it_is():
    recordings, noise, sigma = crafted()
    residual = noise.copy()
    residual[:, OBSERVABLES.index("apex_m")] += 0.8
    located = locate(recordings, residual, sigma, np.ones_like(residual, dtype=bool), [], {})
    flags = {o.name: o.significant for o in located.observables}
    assert flags["apex_m"] and sum(flags.values()) == 1
    assert not any(c.significant for c in located.covariates)
    assert located.summary[0].startswith("apex_m")


def test_locate_finds_the_covariate_and_club_behind_a_residual():
    recordings, noise, sigma = crafted(seed=3)
    residual = noise.copy()
    speed = recordings.launch["ball_speed_mps"]
    j = OBSERVABLES.index("carry_y_m")
    residual[:, j] += 0.08 * (speed - speed.mean())
    residual[:, OBSERVABLES.index("landing_angle_deg")] += 1.5 * (recordings.club == "PW")
    located = locate(recordings, residual, sigma, np.ones_like(residual, dtype=bool), [], {})
    strongest = max((c for c in located.covariates if c.observable == "carry_y_m"), key=lambda c: abs(c.t))
    assert strongest.covariate == "ball_speed_mps" and strongest.significant
    club = next(g for g in located.groups if g.observable == "landing_angle_deg" and g.grouping == "club")
    assert club.significant and "PW" in club.extremes


def test_clean_residuals_raise_no_flag():
    for seed in range(3):
        recordings, noise, sigma = crafted(seed=10 + seed)
        located = locate(recordings, noise, sigma, np.ones_like(noise, dtype=bool), [], {})
        assert not any(o.significant for o in located.observables)
        assert not any(c.significant for c in located.covariates)
        assert not any(g.significant for g in located.groups)


def test_folds_keep_sessions_whole():
    sessions = np.array([f"S{i % 7}" for i in range(70)], dtype=object)
    fold, how = folds(sessions)
    assert "session" in how and fold.max() + 1 == 5
    for s in np.unique(sessions):
        assert len(set(fold[sessions == s])) == 1
    fold, how = folds(np.array(["all"] * 12, dtype=object))
    assert how == "leave one shot out" and len(set(fold)) == 12


def test_cluster_bootstrap_centres_on_the_ratio():
    rng = np.random.default_rng(4)
    groups = np.repeat(np.arange(30), 10)
    values = rng.normal(2.0, 1.0, 300)
    draws = cluster_bootstrap(values, np.ones(300), groups, rng)
    assert abs(np.median(draws) - values.mean()) < 0.05
    low, high = np.quantile(draws, [0.025, 0.975])
    assert low < values.mean() < high and high - low < 0.5
