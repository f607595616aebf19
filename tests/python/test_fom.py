"""The Python FOM is the CLI's FOM: same contact force, KKT residuals at the
solver's tolerance, and operators K, C, g that satisfy the optimality conditions
when assembled in Python."""
import numpy as np
import pytest
import scipy.sparse

import contactrom
from conftest import run_cli_json

CASES = [("hertz", 0.15), ("hertz", 0.3), ("ironing", 1.3)]


@pytest.fixture(scope="module")
def problems():
    return {name: contactrom.problem(name) for name in ("hertz", "ironing")}


@pytest.fixture(scope="module")
def solvers(problems):
    return {name: contactrom.FullOrderSolver(p) for name, p in problems.items()}


@pytest.mark.parametrize("name,mu", CASES)
def test_contact_force_equals_cli(solvers, name, mu):
    sol = solvers[name].solve(mu)
    cli = run_cli_json("fom", "--problem", name, "--param", repr(mu))
    assert sol.status == cli["status"] == "success"
    assert sol.contact_force > 0.0
    assert abs(sol.contact_force - cli["contact_force"]) <= 1e-12 * abs(cli["contact_force"])
    assert sol.iterations == cli["iterations"]
    assert sol.active == cli["active"]
    for key in ("stationarity", "penetration", "negative_pressure", "complementarity"):
        assert sol.kkt[key] == pytest.approx(cli["kkt"][key], rel=1e-6, abs=1e-15)


@pytest.mark.parametrize("name,mu", CASES)
def test_kkt_residuals_are_small(problems, solvers, name, mu):
    sol = solvers[name].solve(mu)
    assert sol.kkt["max"] <= 1e-10, sol.kkt
    recomputed = problems[name].kkt_residuals(mu, sol.u, sol.lam)
    assert recomputed == sol.kkt


@pytest.mark.parametrize("name,mu", CASES)
def test_operators_satisfy_kkt_conditions(problems, solvers, name, mu):
    """K, rhs, C and g from Python: stationarity on the free dofs, no penetration,
    non-negative pressure, complementarity."""
    p = problems[name]
    sol = solvers[name].solve(mu)
    K = p.K(mu)
    C = p.C(sol.u)
    g = p.g(sol.u)
    assert scipy.sparse.issparse(K) and K.shape == (p.num_dofs, p.num_dofs)
    assert scipy.sparse.issparse(C) and C.shape == (p.num_constraints, p.num_dofs)
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()
    free = np.asarray(p.free_dofs)
    f = p.rhs(mu)
    u0 = sol.u - p.lifting(mu)
    residual = (K @ u0 - f + C.T @ sol.lam)[free]
    assert np.linalg.norm(residual) <= 1e-9 * np.linalg.norm(f[free])
    gap = C @ sol.u - g
    scale = p.displacement_scale * np.asarray(p.contact_weights)
    assert np.all(gap <= 1e-10 * scale)
    assert np.all(sol.lam >= 0.0)
    assert abs(sol.lam @ gap) <= 1e-10 * p.displacement_scale * (np.asarray(p.contact_weights) @ sol.lam)
    assert sol.contact_force == pytest.approx(np.asarray(p.contact_weights) @ sol.lam, rel=1e-14)


def test_arrays_are_read_only_views(solvers):
    sol = solvers["hertz"].solve(0.2)
    assert not sol.u.flags.writeable and not sol.u.flags.owndata
    with pytest.raises(ValueError):
        sol.u[0] = 1.0


def test_solve_all_in_threads_equals_serial_solves(problems, solvers):
    params = problems["hertz"].validation_set(30)[::20]
    results = solvers["hertz"].solve_all(params, threads=2)
    assert len(results) == len(params)
    for mu, r in zip(params, results):
        single = solvers["hertz"].solve(mu)
        assert np.array_equal(r.u, single.u) and np.array_equal(r.lam, single.lam)


def test_parameter_space(problems):
    p = problems["ironing"]
    assert p.param_names == ["d_x"]
    assert p.param_ranges == {"d_x": (0.0, 4.0)}
    assert problems["hertz"].range_text == "d in (0, 0.3]"
    train = problems["hertz"].training_set(30)
    assert train.shape == (30, 1)
    assert np.allclose(train[:, 0], 0.3 * np.arange(1, 31) / 30)


def test_problem_from_file_equals_shipped(problems):
    import os
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    p = contactrom.Problem.from_file(os.path.join(root, "problems", "hertz.toml"))
    assert p.fingerprint == problems["hertz"].fingerprint


def test_ipopt_reference_agrees(problems, solvers):
    ipopt = contactrom.FullOrderSolver(problems["hertz"], solver="ipopt")
    ref = ipopt.solve(0.2)
    sol = solvers["hertz"].solve(0.2)
    report = contactrom.verify(problems["hertz"], 0.2, sol.u, sol.lam, reference=ref)
    assert report["status"] == "success"
    assert report["kkt"]["max"] <= 1e-10
    assert report["errors"]["primal_error"] <= 1e-8
    assert report["errors"]["dual_error"] <= 1e-6
    assert report["errors"]["active_set_differences"] == 0
    assert report["errors"]["errors"] == "relative"


def test_verify_errors_are_absolute_against_a_near_zero_reference(problems, solvers):
    # d = 1e-9: the reference displacement is near zero; errors relative to it would
    # divide round-off by round-off, so they are absolute, as in `contactrom online`.
    ref = solvers["hertz"].solve(1e-9)
    other = solvers["hertz"].solve(2e-9)
    report = contactrom.verify(problems["hertz"], 1e-9, other.u, other.lam, reference=ref)
    assert report["errors"]["errors"] == "absolute"
    # The solution at 2e-9 is about twice the one at 1e-9: a relative error would be
    # about 1; the absolute one is of the size of the displacement, about 1e-9.
    assert 0.0 < report["errors"]["primal_error"] < 1e-6


def test_rope_node_coordinates_are_its_uniform_abscissae():
    # The 1D rope has no mesh: its nodes are x_i = i / 200 on [0, 1], one dof each.
    rope = contactrom.problem("rope")
    x = rope.node_coordinates
    assert x.shape == (rope.num_dofs,) and rope.num_dofs == 201
    assert np.allclose(x, np.arange(201) / 200.0, rtol=0.0, atol=1e-15)
    assert x[0] == 0.0 and x[-1] == 1.0
