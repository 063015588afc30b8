"""Fréchet distance: identical sets, a pure shift, and the diagonal closed form."""

import numpy as np
import pytest

from gesturecast.models.evaluation.frechet import frechet_distance, frechet_distance_from_statistics

RNG = np.random.default_rng(1)


def test_identical_feature_sets_are_at_distance_zero():
    features = RNG.normal(size=(500, 8)) @ RNG.normal(size=(8, 8))
    assert frechet_distance(features, features) == pytest.approx(0.0, abs=1e-6)


def test_shifted_gaussian_is_at_the_squared_shift():
    features = RNG.normal(size=(400, 6)) @ RNG.normal(size=(6, 6))
    shift = np.array([0.5, -1.0, 2.0, 0.0, 0.25, 1.0])
    assert frechet_distance(features, features + shift) == pytest.approx(shift @ shift, rel=1e-6)


def test_diagonal_gaussians_match_the_closed_form():
    var_a, var_b = np.array([1.0, 4.0, 0.25]), np.array([9.0, 1.0, 0.25])
    mu_a, mu_b = np.zeros(3), np.array([1.0, 0.0, -2.0])
    expected = 5.0 + np.sum((np.sqrt(var_a) - np.sqrt(var_b)) ** 2)  # ‖Δμ‖² + Σ (σ_a − σ_b)²
    got = frechet_distance_from_statistics(mu_a, np.diag(var_a), mu_b, np.diag(var_b))
    assert got == pytest.approx(expected, rel=1e-9)


def test_rank_deficient_covariances_still_give_a_finite_distance():
    low_rank = RNG.normal(size=(50, 2)) @ RNG.normal(size=(2, 10))  # covariance of rank 2 in 10-D
    assert np.isfinite(frechet_distance(low_rank, low_rank + 1.0))
    with pytest.raises(ValueError, match="N >= 2"):
        frechet_distance(low_rank[:1], low_rank)


def test_trace_of_the_product_square_root_agrees_with_scipy_sqrtm():
    from scipy import linalg

    from gesturecast.models.evaluation.frechet import trace_sqrt_product

    a, b = RNG.normal(size=(2, 5, 5))
    cov_a, cov_b = a @ a.T + 0.1 * np.eye(5), b @ b.T + 0.1 * np.eye(5)
    assert trace_sqrt_product(cov_a, cov_b) == pytest.approx(np.trace(linalg.sqrtm(cov_a @ cov_b)).real, rel=1e-8)
