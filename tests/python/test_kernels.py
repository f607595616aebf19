"""The sparse kernels on numpy arrays recover planted sparse signals and agree with
SciPy's NNLS."""
import numpy as np
import pytest
import scipy.optimize

import contactrom


@pytest.fixture
def planted():
    rng = np.random.default_rng(7)
    D = rng.standard_normal((40, 120))
    support = [3, 17, 58, 101]
    coefficients = np.array([1.5, 0.4, 2.0, 0.9])
    alpha = np.zeros(120)
    alpha[support] = coefficients
    return D, alpha, D @ alpha


def test_omp_recovers_planted_signal(planted):
    D, alpha, x = planted
    r = contactrom.omp(D, x, tolerance=1e-12)
    assert r.status == "success"
    assert r.support == sorted(np.flatnonzero(alpha).tolist())
    assert np.allclose(r.x, alpha, atol=1e-10)


@pytest.mark.parametrize("kernel", [contactrom.focuss, contactrom.nnfocuss])
def test_focuss_recovers_planted_signal(planted, kernel):
    D, alpha, x = planted
    r = kernel(D, x)
    assert r.support == sorted(np.flatnonzero(alpha).tolist())
    assert np.allclose(r.x, alpha, atol=1e-8)


def test_nnls_recovers_planted_nonnegative_solution():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((60, 25))
    x_true = np.zeros(25)
    x_true[[2, 9, 20]] = [1.0, 0.3, 2.5]
    r = contactrom.nnls(A, A @ x_true)
    assert r.status == "success"
    assert r.support == [2, 9, 20]
    assert np.allclose(r.x, x_true, atol=1e-12)


def test_nnls_agrees_with_scipy():
    rng = np.random.default_rng(11)
    A = rng.standard_normal((30, 12))
    b = rng.standard_normal(30)
    r = contactrom.nnls(A, b)
    ref, _ = scipy.optimize.nnls(A, b)
    assert r.status == "success"
    assert np.all(r.x >= 0.0)
    assert np.allclose(r.x, ref, atol=1e-10)
    w = A.T @ (b - A @ r.x)  # KKT: w <= 0 where x = 0, w = 0 where x > 0
    assert np.all(w[r.x == 0.0] <= 1e-10)
    assert np.allclose(w[r.x > 0.0], 0.0, atol=1e-10)
