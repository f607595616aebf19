"""Bad input raises ValueError carrying the CLI's one-line message."""
import contactrom
import numpy as np
import pytest

from conftest import cli_error


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
