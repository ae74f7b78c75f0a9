"""A baseline's form is estimated first and then held: its own error moves every later fit, and the fit's covariance
counts that (Murphy & Topel 1985), in cases worked by hand."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.discovery.fit import held_nuisance_covariance


def test_a_nuisance_that_moves_the_fit_adds_its_variance_through_the_move() -> None:
    """Two shots, one observable, J = (1, 1), J_n = (2, 2): the fit moves by G = -(J'J)^-1 J'J_n = -4 / 2 = -2 per
    unit of the nuisance, so a nuisance variance of 0.01 adds 4 x 0.01."""
    z = np.zeros((2, 1))
    added = held_nuisance_covariance(z, np.ones((2, 1, 1)), np.full((2, 1, 1), 2.0), np.array([[0.01]]))
    assert added[0, 0] == pytest.approx(0.04)


def test_a_nuisance_the_fit_cannot_see_adds_nothing() -> None:
    """J = (1, 1) and J_n = (1, -1) are orthogonal: the nuisance's error leaves the fit where it is."""
    z = np.zeros((2, 1))
    nuisance = np.array([1.0, -1.0]).reshape(2, 1, 1)
    assert held_nuisance_covariance(z, np.ones((2, 1, 1)), nuisance, np.array([[1.0]]))[0, 0] == pytest.approx(0.0)


def test_unused_entries_do_not_move_the_fit() -> None:
    """A third shot whose outcome is not compared (NaN) and whose nuisance derivative is large changes nothing."""
    z = np.array([[0.0], [0.0], [np.nan]])
    jacobian = np.ones((3, 1, 1))
    nuisance = np.array([2.0, 2.0, 50.0]).reshape(3, 1, 1)
    assert held_nuisance_covariance(z, jacobian, nuisance, np.array([[0.01]]))[0, 0] == pytest.approx(0.04)


def test_two_parameters_two_nuisance_weights_by_hand() -> None:
    """Shots (J rows, J_n rows): (1, 0 | 1, 0), (0, 1 | 0, 3): each parameter follows its own weight, G = -diag(1, 3);
    with Cov_n = [[0.01, 0.005], [0.005, 0.04]], G Cov_n G' = [[0.01, 0.015], [0.015, 0.36]]."""
    z = np.zeros((2, 1))
    jacobian = np.array([[[1.0, 0.0]], [[0.0, 1.0]]])
    nuisance = np.array([[[1.0, 0.0]], [[0.0, 3.0]]])
    added = held_nuisance_covariance(z, jacobian, nuisance, np.array([[0.01, 0.005], [0.005, 0.04]]))
    np.testing.assert_allclose(added, [[0.01, 0.015], [0.015, 0.36]], atol=1e-12)
