"""The sparse kernels on numpy arrays recover planted sparse signals and agree with
SciPy's NNLS."""
import numpy as np
import pytest
import scipy.optimize

import contactrom
from conftest import run_cli_json


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


@pytest.mark.parametrize("scale", [2.0 ** -1000, 2.0 ** 1000])
def test_extreme_magnitudes_give_the_same_answer(planted, scale, tmp_path):
    # Scaled by a power of two, a problem has the same solution (D scaled alone:
    # coefficients divided by the scale); Gram matrices of such data would under- or
    # overflow, and the kernels answered 0 with status success.
    D, alpha, x = planted
    Dn = np.abs(D)
    for kernel, (A, b) in {"nnls": (Dn, Dn @ np.abs(alpha)), "omp": (D, x), "nnfocuss": (Dn, Dn @ np.abs(alpha))}.items():
        plain = getattr(contactrom, kernel)(A, b)
        both = getattr(contactrom, kernel)(A * scale, b * scale)
        alone = getattr(contactrom, kernel)(A * scale, b)
        assert both.status == plain.status == "success"
        assert np.array_equal(both.x, plain.x), kernel
        # (a coefficient near zero may fall into the subnormal range: absolute tolerance)
        assert np.allclose(alone.x * scale, plain.x, rtol=1e-12, atol=1e-12 * np.abs(plain.x).max()), kernel
    # The CLI: the same coefficients, and a residual that does not underflow.
    np.savetxt(tmp_path / "D.csv", np.eye(2) * scale, delimiter=",")
    np.savetxt(tmp_path / "x.csv", np.array([scale, 2 * scale]))
    out = run_cli_json("sparse", "--method", "nnls", "--dictionary", str(tmp_path / "D.csv"), "--signal",
                       str(tmp_path / "x.csv"))
    assert out["status"] == "success" and out["coefficients"] == [1.0, 2.0]
    assert out["relative_residual"] == 0.0


def test_results_carry_the_residual_and_omp_s_stop_reason(planted, tmp_path):
    # The keys of `contactrom sparse --json`: an atom limit is a success with a large
    # residual, told apart from convergence by stop_reason.
    D, alpha, x = planted
    capped = contactrom.omp(D, x, max_atoms=2)
    assert capped.status == "success" and capped.stop_reason == "atom_limit"
    assert capped.residual == pytest.approx(np.linalg.norm(D @ capped.x - x), rel=1e-12)
    assert capped.relative_residual == pytest.approx(capped.residual / np.linalg.norm(x), rel=1e-12)
    assert capped.relative_residual > 0.1
    full = contactrom.omp(D, x, tolerance=1e-12)
    assert full.stop_reason == "residual_tolerance" and full.relative_residual <= 1e-12
    nothing = contactrom.omp(np.zeros((3, 0)), np.array([1.0, 2.0, 3.0]))
    assert nothing.stop_reason == "no_progress" and nothing.relative_residual == 1.0
    for kernel in (contactrom.nnls, contactrom.focuss, contactrom.nnfocuss):
        r = kernel(np.abs(D), np.abs(D) @ np.abs(alpha))
        assert r.stop_reason is None
        assert r.relative_residual < 1e-8, kernel
    zero = contactrom.nnls(np.eye(2), np.zeros(2))
    assert zero.residual == zero.relative_residual == 0.0
    np.savetxt(tmp_path / "D.csv", D, delimiter=",")
    np.savetxt(tmp_path / "x.csv", x)
    out = run_cli_json("sparse", "--method", "omp", "--atoms", "2", "--dictionary", str(tmp_path / "D.csv"),
                       "--signal", str(tmp_path / "x.csv"))
    assert out["stop_reason"] == capped.stop_reason
    assert out["relative_residual"] == pytest.approx(capped.relative_residual, rel=1e-9)
