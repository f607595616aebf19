"""Bad input raises ValueError carrying the CLI's one-line message."""
import contactrom
import numpy as np
import pytest

from conftest import cli_error, run_cli


def message_of(excinfo):
    return str(excinfo.value)


def test_unknown_problem():
    expected = cli_error("fom", "--problem", "no-such-problem", "--param", "0.1")
    with pytest.raises(ValueError) as e:
        contactrom.problem("no-such-problem")
    assert message_of(e) == expected


@pytest.mark.parametrize("mu,text", [(0.5, "0.5"), (-0.1, "-0.1"), ([0.1, 0.2], "0.1,0.2"),
                                     (float("nan"), "nan")])
def test_parameter_out_of_range(mu, text):
    expected = cli_error("fom", "--problem", "hertz", "--param", text)
    hertz = contactrom.problem("hertz")
    with pytest.raises(ValueError) as e:
        contactrom.FullOrderSolver(hertz).solve(mu)
    assert message_of(e) == expected
    with pytest.raises(ValueError) as e:
        hertz.K(mu)
    assert message_of(e) == expected


def test_parameter_forms_are_equivalent():
    hertz = contactrom.problem("hertz")
    for mu in (0.2, np.float64(0.2), np.array(0.2), [0.2], np.array([0.2])):
        assert hertz.check_param(mu).tolist() == [0.2]
    with pytest.raises(ValueError, match="is a number or a sequence"):
        hertz.check_param("0.2")


def test_missing_database(tmp_path):
    path = str(tmp_path / "missing.h5")
    expected = cli_error("online", "--db", path)
    with pytest.raises(ValueError) as e:
        contactrom.load_database(path)
    assert message_of(e) == expected


def test_unknown_method_and_option(hertz_db_path):
    db = contactrom.load_database(str(hertz_db_path))
    expected = cli_error("online", "--db", str(hertz_db_path), "--method", "nope")
    with pytest.raises(ValueError) as e:
        contactrom.ReducedModel(db, method="nope")
    assert message_of(e) == expected
    expected = cli_error("online", "--db", str(hertz_db_path), "--method", "cpg", "--option", "nonsense=1")
    with pytest.raises(ValueError) as e:
        contactrom.ReducedModel(db, method="cpg", options={"nonsense": 1})
    assert message_of(e) == expected
    for delta in (-1e-8, 1.5, float("nan")):
        with pytest.raises(ValueError, match=r"delta = \S+ is outside \[0, 1\]; expected a POD tolerance such as 1e-8"):
            contactrom.ReducedModel(db, delta=delta)


def test_shape_errors_name_the_argument():
    hertz = contactrom.problem("hertz")
    with pytest.raises(ValueError, match="u has 3 entries"):
        hertz.C(np.zeros(3))
    with pytest.raises(ValueError, match="b has 2 entries; expected 3"):
        contactrom.nnls(np.eye(3), np.ones(2))
    with pytest.raises(ValueError, match="non-finite"):
        contactrom.omp(np.array([[1.0, np.inf]]), np.ones(1))


def test_missing_reduced_model(tmp_path):
    path = str(tmp_path / "missing_rom.h5")
    expected = cli_error("query", "--rom", path, "--param", "0.1")
    with pytest.raises(ValueError) as e:
        contactrom.ReducedModel.load(path)
    assert message_of(e) == expected


def test_database_is_not_a_reduced_model(hertz_db_path):
    expected = cli_error("query", "--rom", str(hertz_db_path), "--param", "0.1")
    with pytest.raises(ValueError) as e:
        contactrom.ReducedModel.load(str(hertz_db_path))
    assert message_of(e) == expected


def test_arrays_are_checked_at_the_boundary():
    hertz = contactrom.problem("hertz")
    u = np.zeros(hertz.num_dofs)
    lam = np.zeros(hertz.num_constraints)
    for bad in (np.nan, np.inf, -np.inf):
        v = u.copy()
        v[3] = bad
        for call in (hertz.C, hertz.g, hertz.normal_gaps):
            with pytest.raises(ValueError, match=r"u\[3\] is .*expected finite numbers"):
                call(v)
        with pytest.raises(ValueError, match="expected finite numbers"):
            hertz.kkt_residuals(0.1, v, lam)
        m = lam.copy()
        m[0] = bad
        with pytest.raises(ValueError, match=r"lam\[0\]"):
            hertz.kkt_residuals(0.1, u, m)
        with pytest.raises(ValueError, match=r"lam\[0\]"):
            hertz.contact_force(m)
    with pytest.raises(ValueError, match="entries; expected"):
        hertz.C(u[:-1])


def test_scalars_are_checked_at_the_boundary():
    hertz = contactrom.problem("hertz")
    with pytest.raises(ValueError, match="is a number or a sequence") as e:
        hertz.check_param(None)
    assert "nan" not in str(e.value)
    with pytest.raises(ValueError, match="is not a finite number"):
        hertz.check_param(10**400)
    with pytest.raises(ValueError, match="is not a finite number"):
        hertz.check_param(-(10**400))


def test_paths_may_be_path_like(tmp_path):
    import pathlib
    source = pathlib.Path(__file__).resolve().parents[2]  # the source tree
    problem = contactrom.problem("rope")
    db = contactrom.offline(problem, 9)
    path = tmp_path / "rope.h5"
    db.save(path)
    assert contactrom.load_database(path).problem.name == "rope"
    rom = contactrom.ReducedModel(db)
    rom.save(tmp_path / "rom.h5")
    assert contactrom.ReducedModel.load(tmp_path / "rom.h5").problem.name == "rope"
    assert contactrom.Problem.from_file(source / "problems" / "hertz.toml").name == "hertz"


def test_threads_take_the_clis_values(tmp_path):
    # 0 means all cores in both; values outside [0, 1024] are refused by both, each
    # message naming the value and the accepted range.
    hertz = contactrom.problem("hertz")
    db = contactrom.offline(hertz, 2, threads=0)
    cli_db = tmp_path / "hertz2.h5"
    run_cli("offline", "--problem", "hertz", "--train", "2", "--threads", "0", "--out", str(cli_db))
    assert np.array_equal(db.dual, contactrom.load_database(cli_db).dual)
    fom = contactrom.FullOrderSolver(hertz)
    for bad in (-1, 1025):
        expected = cli_error("offline", "--problem", "hertz", "--train", "2", "--threads", str(bad),
                             "--out", str(tmp_path / "bad.h5"))
        assert f"'{bad}'" in expected and "[0, 1024]" in expected
        for call in (lambda: contactrom.offline(hertz, 2, threads=bad),
                     lambda: fom.solve_all([0.1], threads=bad),
                     lambda: contactrom.offline_adaptive(hertz, tolerance=0.1, threads=bad)):
            with pytest.raises(ValueError) as e:
                call()
            assert message_of(e) == f"threads = {bad} invalid; expected an integer in [0, 1024] (0: all cores)"
    assert not (tmp_path / "bad.h5").exists()


def test_none_for_a_problem_is_a_type_error_not_a_crash():
    for call in (lambda: contactrom.FullOrderSolver(None), lambda: contactrom.offline(None, 3),
                 lambda: contactrom.offline_adaptive(None, tolerance=0.1),
                 lambda: contactrom.verify(None, 0.1, [0.0], [0.0])):
        with pytest.raises(TypeError):
            call()


def test_offline_counts_and_explicit_parameters(tmp_path):
    hertz = contactrom.problem("hertz")
    # numpy's integers are counts; a float is refused, naming it.
    assert contactrom.offline(hertz, np.int64(3)).training_size == 3
    with pytest.raises(ValueError, match=r"params 3.0 is a number but not an int"):
        contactrom.offline(hertz, 3.0)
    # A problem trained on a list takes no other count (the CLI refuses --train).
    with pytest.raises(ValueError, match="trains on its 9 listed points"):
        contactrom.offline(contactrom.problem("rope"), 5)
    # Snapshots at given parameters say so and are not written as a training set.
    explicit = contactrom.offline(hertz, [[0.1], [0.2]])
    assert explicit.training_kind == "explicit"
    with pytest.raises(ValueError, match="not a training set"):
        explicit.save(tmp_path / "never_written.h5")
    assert not (tmp_path / "never_written.h5").exists()
    with pytest.raises(ValueError, match="training size 0 is invalid"):
        hertz.validation_set(0)


def test_numpy_scalars_are_option_values_and_kernel_settings_are_checked():
    db = contactrom.offline(contactrom.problem("hertz"), 4)
    rom = contactrom.ReducedModel(db, options={"max_iterations": np.int64(3), "tau": np.float32(1e-6)})
    assert rom.solve(0.1).iterations <= 3
    with pytest.raises(ValueError, match="tolerance = nan; expected a finite number >= 0"):
        contactrom.omp(np.eye(2), np.ones(2), tolerance=float("nan"))
    with pytest.raises(ValueError, match="tolerance = -1"):
        contactrom.nnls(np.eye(2), np.ones(2), tolerance=-1)
    with pytest.raises(ValueError, match="max_iterations = 0"):
        contactrom.focuss(np.eye(2), np.ones(2), max_iterations=0)


def test_verify_refuses_a_reference_of_another_parameter():
    hertz = contactrom.problem("hertz")
    fom = contactrom.FullOrderSolver(hertz)
    a, b = fom.solve(0.1), fom.solve(0.2)
    with pytest.raises(ValueError, match="another parameter"):
        contactrom.verify(hertz, 0.1, a.u, a.lam, reference=b)


def test_ctrl_c_stops_long_calls():
    # SIGINT (what Ctrl-C sends) during offline and adaptive training raises
    # KeyboardInterrupt within a snapshot or a candidate, not at the end of the run.
    import os
    import signal
    import threading
    import time
    hertz = contactrom.problem("hertz")
    start = time.time()
    contactrom.offline(hertz, 40, threads=1)
    per_snapshot = (time.time() - start) / 40
    for run in (lambda: contactrom.offline(hertz, 5000, threads=1),
                lambda: contactrom.offline_adaptive(hertz, tolerance=1e-12, max_snapshots=5000, threads=1)):
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        start = time.time()
        with pytest.raises(KeyboardInterrupt):
            run()
        timer.join()
        # 5000 snapshots would take 5000 * per_snapshot; the interrupt comes at 0.3 s.
        assert time.time() - start < 0.3 + 0.5 * 5000 * per_snapshot
    assert contactrom.offline(hertz, 3).training_size == 3  # the module still works


def test_parameters_are_numbers_and_settings_agree():
    hertz = contactrom.problem("hertz")
    fom = contactrom.FullOrderSolver(hertz)
    for value in (True, ["0.2"], [b"0.1"], np.array(["0.1"]), [None], [True]):
        with pytest.raises(ValueError, match="is a number or a sequence of 1 numbers"):
            fom.solve(value)
    db = contactrom.offline(hertz, 4)
    with pytest.raises(ValueError, match="disagree"):
        contactrom.ReducedModel(db, lifting="dirichlet", offset="harmonic")
    assert contactrom.ReducedModel(db, lifting="dirichlet").solve(0.1).status == "success"
    with pytest.raises(TypeError, match="resume is a SnapshotDatabase"):
        contactrom.offline_adaptive(hertz, tolerance=0.1, resume="x.h5")
    assert "FallbackModel" in contactrom.__all__


def test_empty_parameter_lists_are_refused(hertz_db_path, tmp_path):
    # No rows would give errors of 0.0 over nothing, an empty database or no
    # solutions; the CLI refuses an empty parameter file the same way.
    hertz = contactrom.problem("hertz")
    rom = contactrom.ReducedModel(contactrom.load_database(hertz_db_path))
    fom = contactrom.FullOrderSolver(hertz)
    calls = {"evaluate": rom.evaluate, "offline": lambda p: contactrom.offline(hertz, p),
             "FullOrderSolver.solve_all": fom.solve_all, "ReducedModel.solve_all": rom.solve_all}
    for name, call in calls.items():
        for empty in (np.zeros((0, 1)), np.zeros(0), []):
            with pytest.raises(ValueError) as excinfo:
                call(empty)
            assert message_of(excinfo).startswith("params of 'hertz' has no rows (shape (0"), name
            assert message_of(excinfo).endswith("expected at least one parameter, an array of shape (n, 1) with n >= 1")
            assert "\n" not in message_of(excinfo)
    with pytest.raises(ValueError, match=r"has no rows \(shape \(0, 1\)\)"):
        rom.evaluate(np.zeros((0, 1)))
    (tmp_path / "empty.csv").write_text("d\n")
    assert "expected at least one row" in cli_error("online", "--db", str(hertz_db_path), "--params",
                                                    str(tmp_path / "empty.csv"))
    assert len(rom.solve_all([0.1])) == 1  # one row is a list
