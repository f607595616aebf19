"""A Python reduced model built from a CLI database answers as `contactrom online`
on that database; a Python offline stage writes the CLI's database."""
import gc
import re

import numpy as np
import pytest

import contactrom
from conftest import HERTZ_TRAIN, run_cli, run_cli_json


@pytest.fixture(scope="module")
def db(hertz_db_path):
    return contactrom.load_database(str(hertz_db_path))


@pytest.fixture(scope="module")
def rom(db):
    return contactrom.ReducedModel(db, delta=1e-8, method="greedy")


def test_validation_errors_equal_cli(hertz_db_path, rom):
    cli = run_cli_json("online", "--db", str(hertz_db_path), "--method", "greedy", "--delta", "1e-8", "--threads", "2")
    ours = rom.evaluate(threads=2)
    assert ours["validation_size"] == cli["validation_size"] == 119
    for key in ("primal_rank", "dictionary_size", "dual_basis_size", "max_sparsity", "nonconverged", "fom_failures"):
        assert ours[key] == cli[key], key
    for key in ("mean_primal_error", "max_primal_error", "mean_dual_error", "max_dual_error", "mean_sparsity",
                "mean_iterations"):
        assert ours[key] == pytest.approx(cli[key], rel=1e-12, abs=1e-300), key
    assert ours["max_primal_error"] == ours["rows"]["primal_error"].max()
    # One key list (rom::summary_values) for the CLI's JSON and the Python dict.
    assert set(ours) - {"rows"} == set(cli)


def test_near_zero_reference_gives_absolute_errors(rom):
    # d = 1e-9: the FOM displacement is near zero, a relative error would divide
    # round-off by round-off; the row's errors are absolute and left out of the means.
    report = rom.evaluate(params=[1e-9, 0.1], threads=1)
    rows = report["rows"]
    assert list(rows["absolute_errors"]) == [True, False]
    assert report["absolute_error_rows"] == 1
    assert report["max_absolute_primal_error"] == rows["primal_error"][0]
    assert report["max_absolute_dual_error"] == rows["dual_error"][0]
    assert report["max_primal_error"] == report["mean_primal_error"] == rows["primal_error"][1]
    assert report["max_dual_error"] == report["mean_dual_error"] == rows["dual_error"][1]


@pytest.mark.parametrize("mu", [0.0137, 0.2])
def test_single_query_equals_cli(hertz_db_path, rom, mu):
    cli = run_cli_json("online", "--db", str(hertz_db_path), "--param", repr(mu))
    r = rom.solve(mu)
    assert r.status == cli["status"] and r.converged == cli["converged"]
    assert r.iterations == cli["iterations"]
    snapshots = [rom.dictionary_snapshots[c] for c in r.selected]
    assert snapshots == cli["selected"]
    assert np.allclose(r.coefficients, cli["coefficients"], rtol=1e-12, atol=0.0)
    assert rom.problem.contact_force(r.lam) == pytest.approx(cli["contact_force"], rel=1e-12)
    # The full-order contact check: same residuals as the CLI's, within tolerance for a success.
    assert r.penetration == pytest.approx(cli["penetration"], rel=1e-12, abs=1e-300)
    assert r.separation == pytest.approx(cli["separation"], rel=1e-12, abs=1e-300)
    assert r.status != "success" or (r.penetration <= 0.05 and r.separation <= 0.05)
    # The error estimates: the CLI's, and within a factor 3 of the true errors.
    assert r.primal_estimate == pytest.approx(cli["primal_estimate"], rel=1e-9)
    assert r.dual_estimate == pytest.approx(cli["dual_estimate"], rel=1e-9)
    assert cli["primal_error"] <= 3 * r.primal_estimate <= 9 * cli["primal_error"]


def test_inaccurate_answers_are_counted_and_reported_per_row(rom):
    # Every row carries its contact residuals; a row is 'inaccurate' exactly when
    # the method converged but they exceed the tolerance: 0.05 U by default, times
    # the answer's own largest surface displacement when that is below U.
    report = rom.evaluate(threads=2)
    rows = report["rows"]
    problem = rom.problem
    surface = np.asarray(problem.surface_dofs)
    scales = []
    for mu in rows["mu"]:
        own = np.abs(rom.solve(mu).u[surface]).max() / problem.displacement_scale
        scales.append(min(1.0, max(own, 1e-6)))
    bad = [(p > 0.05 * k or s > 0.05 * k) for p, s, k in zip(rows["penetration"], rows["separation"], scales)]
    assert sum(bad) >= 1  # the query far below the training loads (d = 0.00375 against 0.01)
    flagged = [st == "inaccurate" for st in rows["status"]]
    assert report["inaccurate"] == sum(flagged)
    for b, f, c in zip(bad, flagged, rows["converged"]):
        assert f == (b and c)


def test_solution_is_the_dictionary_combination(rom):
    r = rom.solve(0.17)
    assert r.u_hat.shape == (rom.primal_rank,)
    assert len(r.selected) == len(r.coefficients) > 0
    assert np.all(r.coefficients >= 0.0)
    D = rom.dictionary
    assert D.shape == (rom.problem.num_constraints, rom.dictionary_size)
    assert np.allclose(r.lam, D[:, r.selected] @ r.coefficients, rtol=1e-13, atol=1e-14 * abs(D).max())
    # Python that reads like the FOM's: selected is an int array like coefficients, and
    # the total force is the problem's, as FomSolution.contact_force.
    assert isinstance(r.selected, np.ndarray) and r.selected.dtype.kind == "i"
    assert r.contact_force == pytest.approx(rom.problem.contact_force(r.lam), rel=1e-14)
    fom = contactrom.FullOrderSolver(rom.problem).solve(0.17)
    assert r.contact_force == pytest.approx(fom.contact_force, rel=0.05)
    # u = Phi u_hat + offset(mu): the offset does not depend on u_hat.
    other = rom.solve(0.17)
    assert np.array_equal(r.u, other.u)


def test_python_offline_writes_the_cli_database(tmp_path, db):
    problem = contactrom.problem("hertz")
    ours = contactrom.offline(problem, HERTZ_TRAIN, threads=2)
    assert ours.num_snapshots == HERTZ_TRAIN
    assert np.array_equal(ours.parameters, db.parameters)
    assert np.array_equal(ours.primal, db.primal)
    assert np.array_equal(ours.dual, db.dual)
    path = tmp_path / "py.h5"
    ours.save(str(path))
    back = contactrom.load_database(str(path))
    assert np.array_equal(back.primal, db.primal)
    cli = run_cli_json("online", "--db", str(path), "--param", "0.2")
    r = contactrom.ReducedModel(back).solve(0.2)
    assert r.coefficients.tolist() == pytest.approx(cli["coefficients"], rel=1e-12)


def test_offline_at_given_parameters():
    problem = contactrom.problem("hertz")
    params = np.array([[0.05], [0.1], [0.25]])
    db = contactrom.offline(problem, params, threads=1)
    assert np.array_equal(db.parameters, params)
    fom = contactrom.FullOrderSolver(problem)
    # The first parameter is solved from scratch, the others from their predecessor
    # (continuation): the same answers to the pairing tolerance.
    assert np.array_equal(db.dual[0], fom.solve(params[0]).lam)
    for j, mu in enumerate(params):
        lam = fom.solve(mu).lam
        assert np.max(np.abs(db.dual[j] - lam)) <= 1e-10 * np.max(np.abs(lam))


def test_model_owns_problem_and_database(hertz_db_path):
    rom = contactrom.ReducedModel(contactrom.load_database(str(hertz_db_path)), method="greedy")
    gc.collect()
    r = rom.solve(0.1)
    assert r.status == "success"
    assert rom.database.num_snapshots == HERTZ_TRAIN
    basis = rom.basis
    del rom
    gc.collect()
    assert np.isfinite(basis).all()  # the view keeps the model alive


@pytest.mark.parametrize("method,options", [("cpg", {"cpg_tolerance": 1e-2}), ("full-dictionary", {}),
                                            ("greedy", {"max_iterations": 20, "tau": 1e-8})])
def test_other_methods_and_options(db, method, options):
    rom = contactrom.ReducedModel(db, method=method, options=options)
    assert rom.method == method
    r = rom.solve(0.2)
    assert r.status == "success"
    report = contactrom.verify(rom.problem, 0.2, r.u, r.lam)
    assert report["kkt"]["stationarity"] < 1e-2


def test_solve_all_equals_single_solves(rom):
    params = np.linspace(0.01, 0.3, 5)
    results = rom.solve_all(params)
    for mu, r in zip(params, results):
        assert np.array_equal(r.selected, rom.solve(mu).selected)


QUERY_PARAMS = [0.0137, 0.1, 0.2999]


def query_cli(tmp_path, rom_path):
    csv = tmp_path / "params.csv"
    csv.write_text("d\n" + "\n".join(repr(p) for p in QUERY_PARAMS) + "\n")
    return run_cli_json("query", "--rom", str(rom_path), "--params", str(csv))["queries"]


def assert_same_answers(model, queries):
    assert len(queries) == len(QUERY_PARAMS)
    for q, mu in zip(queries, QUERY_PARAMS):
        r = model.solve(mu)
        assert r.status == q["status"] and r.iterations == q["iterations"]
        assert [model.dictionary_snapshots[c] for c in r.selected] == q["selected"]
        assert np.allclose(r.coefficients, q["coefficients"], rtol=1e-12, atol=0.0)
        assert model.problem.contact_force(r.lam) == pytest.approx(q["contact_force"], rel=1e-12)


def test_saved_model_answers_as_cli_query(tmp_path, rom):
    path = tmp_path / "rom.h5"
    rom.save(str(path))
    queries = query_cli(tmp_path, path)
    assert_same_answers(rom, queries)
    loaded = contactrom.ReducedModel.load(str(path))
    assert loaded.database is None
    assert (loaded.method, loaded.primal_rank, loaded.dictionary_size) == (rom.method, rom.primal_rank,
                                                                          rom.dictionary_size)
    assert_same_answers(loaded, queries)


def test_cli_reduced_model_loads_in_python(tmp_path, hertz_db_path):
    path = tmp_path / "cpg.h5"
    run_cli("reduce", "--db", str(hertz_db_path), "--method", "cpg", "--option", "cpg_tolerance=0.01",
            "--out", str(path))
    loaded = contactrom.ReducedModel.load(str(path))
    assert loaded.method == "cpg"
    assert loaded.options["cpg_tolerance"] == 0.01
    assert_same_answers(loaded, query_cli(tmp_path, path))
    with pytest.raises(ValueError, match="needs params"):
        loaded.evaluate()
    report = loaded.evaluate(QUERY_PARAMS, threads=1)
    assert report["validation_size"] == len(QUERY_PARAMS)


def test_delta_one_gives_the_empty_basis_and_no_success(db):
    # delta = 1 keeps no POD mode: the answer is the offset alone (no contact
    # enforced), never a success at a pressing load; the convex hull refuses.
    with pytest.warns(RuntimeWarning, match="keeps no POD mode"):
        empty = contactrom.ReducedModel(db, delta=1.0, method="greedy")
    assert empty.primal_rank == 0
    r = empty.solve(0.1)
    assert r.u_hat.shape == (0,)
    assert np.all(np.isfinite(r.u)) and np.all(np.isfinite(r.lam))
    assert r.status != "success" and r.penetration > 0.05
    with pytest.raises(ValueError, match="keeps no mode at delta 1"):
        contactrom.ReducedModel(db, delta=1.0, method="convex-hull")


def test_fallback_answers_from_the_fom_when_the_tolerances_are_not_met(rom):
    strict = rom.with_fallback(primal_tolerance=1e-12, dual_tolerance=1e-12)
    a = strict.solve(0.1)
    assert a["source"] == "fom" and a["fom_time_s"] > 0 and a["fallback_reason"]
    assert a["solution"].status == "success"
    lenient = rom.with_fallback(primal_tolerance=10.0, dual_tolerance=10.0)
    b = lenient.solve(0.1)
    assert b["source"] == "rom" and b["fom_time_s"] == 0
    assert b["solution"].primal_estimate == pytest.approx(rom.solve(0.1).primal_estimate, rel=1e-12)


def test_every_class_and_constructor_has_a_docstring():
    classes = [getattr(contactrom, n) for n in dir(contactrom) if isinstance(getattr(contactrom, n), type)]
    assert len(classes) >= 6
    for cls in classes:
        assert (cls.__doc__ or "").strip(), cls.__name__
        init_doc = cls.__init__.__doc__ or ""
        if "No constructor defined" in init_doc or "Initialize self" in init_doc:
            continue  # made by a function or a method (contactrom.problem, ReducedModel.solve), not constructed
        # pybind11 puts the signature on the first line; a description must follow it.
        described = [line for line in init_doc.splitlines()[1:] if line.strip()]
        assert described, f"{cls.__name__}.__init__ has no description"


def documented_defaults():
    """{method: {key: default text}} as `contactrom online --help` prints them."""
    methods, current = {}, None
    for line in run_cli("online", "--help").stdout.splitlines():
        head = re.match(r"^  ([a-z-]+): ", line)
        option = re.match(r"^    ([a-z_]+): .*; default (.*)\]$", line)
        if head:
            current = methods.setdefault(head.group(1), {})
        elif option and current is not None:
            current[option.group(1)] = option.group(2)
    return methods


def test_every_option_reports_its_documented_default_typed(db):
    methods = documented_defaults()
    assert set(methods) >= {"greedy", "greedy-nested", "convex-hull", "cpg", "full-dictionary"}
    for method, defaults in methods.items():
        options = contactrom.ReducedModel(db, method=method).options
        assert set(options) == set(defaults), method
        for key, text in defaults.items():
            value = options[key]
            if text in ("true", "false"):
                assert value is (text == "true"), (method, key, value)
            elif re.fullmatch(r"-?\d+", text) and isinstance(value, int):
                assert value == int(text), (method, key, value)
            elif re.fullmatch(r"[-+0-9.e]+", text):
                assert isinstance(value, float) and value == float(text), (method, key, value)
            else:
                assert value == text, (method, key, value)
            # typed back in, the documented default is accepted and kept
            again = contactrom.ReducedModel(db, method=method, options={key: value}).options
            assert again[key] == value, (method, key)


def test_offset_and_its_other_name_lifting_build_the_same_model(hertz_db_path, db):
    # As the CLI's --offset dirichlet (whose other name is --lifting), at one query.
    cli = run_cli_json("online", "--db", str(hertz_db_path), "--param", "0.17", "--offset", "dirichlet")
    answers = []
    for kwargs in ({"offset": "dirichlet"}, {"lifting": "dirichlet"}):
        model = contactrom.ReducedModel(db, **kwargs)
        r = model.solve(0.17)
        assert model.primal_rank == cli["primal_rank"], kwargs
        assert [model.dictionary_snapshots[c] for c in r.selected] == cli["selected"], kwargs
        answers.append(r.u)
    assert np.array_equal(answers[0], answers[1])
    assert not np.array_equal(answers[0], contactrom.ReducedModel(db).solve(0.17).u)  # the default: harmonic
    with pytest.raises(ValueError, match="offset 'zero' unknown"):
        contactrom.ReducedModel(db, offset="zero")
    with pytest.raises(ValueError, match="disagree"):
        contactrom.ReducedModel(db, offset="dirichlet", lifting="harmonic")
