"""Adaptive training from Python builds the database `contactrom offline --adaptive`
builds with the same settings, continues one, and refuses bad settings as the CLI."""
import numpy as np
import pytest

import contactrom
from conftest import cli_error, run_cli

SETTINGS = dict(tolerance=1e-3, candidates=40, batch=2, threads=1)


def test_python_run_equals_cli_run(tmp_path):
    path = tmp_path / "cli.h5"
    run_cli("offline", "--problem", "hertz", "--adaptive", "--tolerance", "0.001", "--candidates", "40", "--batch", "2",
            "--max-snapshots", "6", "--threads", "2", "--out", str(path))
    cli = contactrom.load_database(str(path))
    ours = contactrom.offline_adaptive(contactrom.problem("hertz"), max_snapshots=6, **SETTINGS)
    assert ours.training_kind == cli.training_kind == "adaptive"
    np.testing.assert_array_equal(ours.parameters, cli.parameters)
    np.testing.assert_array_equal(ours.dual, cli.dual)
    a, b = ours.adaptive, cli.adaptive
    np.testing.assert_array_equal(a["round_snapshots"], [2, 4, 6])
    np.testing.assert_array_equal(a["round_added"], [2, 2, 0])
    np.testing.assert_array_equal(a["round_max_indicator"], b["round_max_indicator"])
    assert a["round_max_indicator"][-1] < a["round_max_indicator"][0]


def test_resume_and_checkpoint(tmp_path):
    problem = contactrom.problem("hertz")
    whole = contactrom.offline_adaptive(problem, max_snapshots=6, **SETTINGS)
    path = tmp_path / "part.h5"
    part = contactrom.offline_adaptive(problem, max_snapshots=4, path=str(path), **SETTINGS)
    on_disk = contactrom.load_database(str(path))  # written after every round
    np.testing.assert_array_equal(on_disk.parameters, part.parameters)
    rest = contactrom.offline_adaptive(problem, max_snapshots=6, resume=on_disk, **SETTINGS)
    np.testing.assert_array_equal(rest.parameters, whole.parameters)
    np.testing.assert_array_equal(rest.adaptive["round_mean_indicator"], whole.adaptive["round_mean_indicator"])
    with pytest.raises(ValueError, match="seed"):
        contactrom.offline_adaptive(problem, max_snapshots=6, resume=on_disk, seed=7,
                                    **{k: v for k, v in SETTINGS.items()})


def test_bad_settings_raise_the_cli_message():
    problem = contactrom.problem("hertz")
    with pytest.raises(ValueError, match="tolerance"):
        contactrom.offline_adaptive(problem, tolerance=0.0)
    with pytest.raises(ValueError, match="indicator"):
        contactrom.offline_adaptive(problem, tolerance=0.1, indicator="both")
    assert "batch" in cli_error("offline", "--problem", "hertz", "--adaptive", "--tolerance", "0.1", "--batch", "0",
                                "--out", "x.h5")


def test_settings_and_defaults_are_the_clis():
    # One declaration: Python's keywords and defaults are the flags and defaults of
    # `offline --help`, and a run records every setting with its value.
    import re
    defaults = contactrom.adaptive_options()
    assert defaults["tolerance"] == 0.05 and defaults["initial"] == 0
    help_text = run_cli("offline", "--help").stdout
    # CLI11 prints each option's name, then its help on the next line.
    flags = dict(re.findall(r"^\s+--([a-z-]+) .*\n\s+adaptive: .*; default ([^)\n]*)\)$", help_text, re.MULTILINE))
    assert len(flags) == 7, flags
    for flag, text in flags.items():
        value = defaults[flag.replace("-", "_")]
        assert (float(text) == value) if isinstance(value, (int, float)) else (text == value), (flag, text, value)
    db = contactrom.offline_adaptive(contactrom.problem("hertz"), tolerance=0.5, candidates=20, threads=1)
    expected = dict(defaults, tolerance=0.5, candidates=20)
    for key in defaults:
        if key != "initial":  # recorded as the database's training size
            assert db.adaptive[key] == expected[key] and type(db.adaptive[key]) is type(expected[key]), key
    with pytest.raises(ValueError, match="unknown; expected one of: tolerance, max_snapshots"):
        contactrom.offline_adaptive(contactrom.problem("hertz"), tolerance=0.5, max_snapshot=3)
    with pytest.raises(ValueError, match="needs tolerance"):
        contactrom.offline_adaptive(contactrom.problem("hertz"))
