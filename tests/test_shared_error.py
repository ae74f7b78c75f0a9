"""A baseline's discrepancy is an error shots at nearby launches share: the parameters' covariance counts it once for
the shots that share it, not once per shot (cases worked by hand)."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.discovery import discrepancy as discrepancy_module
from golfflight.discovery.discrepancy import INPUTS, Discrepancy, Process
from golfflight.discovery.fit import covariance

AMPLITUDE = 0.5


def far_conditioned_process() -> Process:
    """A process conditioned on one point far from every shot below: its posterior there is its prior."""
    far = np.full((1, len(INPUTS)), 100.0)
    return Process(far, np.zeros(1), np.linalg.cholesky(np.array([[AMPLITUDE**2 + 1.0]])), 1.0, AMPLITUDE)


def test_two_shots_at_one_launch_share_the_whole_prior_variance() -> None:
    """Two shots at the same launch, weights 1 and 1: the pair (0,1) and (1,0) each add amplitude^2."""
    shared = far_conditioned_process().shared(np.zeros((2, len(INPUTS))), np.ones((2, 1)))
    assert shared[0, 0] == pytest.approx(2 * AMPLITUDE**2)


def test_shots_far_apart_share_nothing() -> None:
    z = np.array([[0.0] * len(INPUTS), [20.0] * len(INPUTS)])
    assert far_conditioned_process().shared(z, np.ones((2, 1)))[0, 0] == pytest.approx(0.0, abs=1e-12)


def test_near_the_conditioning_points_the_shared_error_shrinks() -> None:
    """At a point the baseline recorded (noise 0.1 there), the posterior covariance is nearly gone."""
    at = np.zeros((1, len(INPUTS)))
    process = Process(at, np.zeros(1), np.linalg.cholesky(np.array([[AMPLITUDE**2 + 0.01]])), 1.0, AMPLITUDE)
    shared = process.shared(np.zeros((2, len(INPUTS))), np.ones((2, 1)))[0, 0]
    # posterior covariance = a^2 - a^4 / (a^2 + 0.01) = 0.25 - 0.0625 / 0.26
    assert shared == pytest.approx(2 * (AMPLITUDE**2 - AMPLITUDE**4 / (AMPLITUDE**2 + 0.01)))


def test_two_shots_sharing_all_their_error_tell_as_much_as_one() -> None:
    """One parameter, one observable, J = (1, 1), residuals (1, 0) so s^2 = 1: independent, var = 1 / 2; the whole
    error shared (weights_0 C_01 weights_1 = 1 each way), var = (1/2)(2 + 2)(1/2) = 1, one shot's."""
    z = np.array([[1.0], [0.0]])
    jacobian = np.ones((2, 1, 1))
    groups = np.array(["a", "a"])
    assert covariance(z, jacobian, groups)[0, 0] == pytest.approx(0.5)
    assert covariance(z, jacobian, groups, shared=np.array([[2.0]]))[0, 0] == pytest.approx(1.0)


def test_a_large_set_is_estimated_from_a_share_of_its_pairs(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every shot at one launch, every weight 1: the pairs' sum is n (n - 1) a^2 with all shots or a share of them."""
    processes = tuple(far_conditioned_process() for _ in range(5))
    discrepancy = Discrepancy(np.zeros(len(INPUTS)), np.ones(len(INPUTS)), processes)
    n = 50
    launch = {name: np.zeros(n) for name in INPUTS}
    weights = np.zeros((n, 5, 1))
    weights[:, 0, 0] = 1.0
    rng = np.random.default_rng(0)
    whole = discrepancy.shared_information(launch, weights, rng)[0, 0]
    monkeypatch.setattr(discrepancy_module, "SHARED_POINTS", 10)
    share = discrepancy.shared_information(launch, weights, rng)[0, 0]
    assert whole == pytest.approx(n * (n - 1) * AMPLITUDE**2)
    assert share == pytest.approx(whole)
