"""Shared fixtures of the Python tests: the contactrom CLI of the same build and a
small hertz database written by it.

ctest sets CONTACTROM_EXE (the CLI) and PYTHONPATH (the package in the build
tree); run by hand as
    CONTACTROM_EXE=build/tools/contactrom PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
A missing variable or package is an error, never a skipped test.
"""
import json
import os
import subprocess

import pytest

import contactrom  # noqa: F401  (an ImportError here fails every test, loudly)

# Training size of the hertz database shared by the tests (d_i = 0.3 i / N).
HERTZ_TRAIN = 10


def cli_path():
    path = os.environ.get("CONTACTROM_EXE")
    if not path or not os.path.isfile(path):
        raise RuntimeError(f"CONTACTROM_EXE={path!r} does not name the contactrom executable")
    return path


def run_cli(*args, expect_ok=True):
    """Runs the CLI; returns the CompletedProcess (text mode)."""
    proc = subprocess.run([cli_path(), *args], capture_output=True, text=True, timeout=600)
    if expect_ok and proc.returncode != 0:
        raise AssertionError(f"contactrom {' '.join(args)} failed ({proc.returncode}): {proc.stderr}")
    return proc


def run_cli_json(*args):
    return json.loads(run_cli(*args, "--json").stdout)


def cli_error(*args):
    """The one-line message of a refused CLI run (exit code 2), without the prefix."""
    proc = run_cli(*args, expect_ok=False)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    prefix = "contactrom: error: "
    assert lines[0].startswith(prefix), lines[0]
    return lines[0][len(prefix):]


@pytest.fixture(scope="session")
def hertz_db_path(tmp_path_factory):
    """A hertz database of HERTZ_TRAIN snapshots written by `contactrom offline`."""
    path = tmp_path_factory.mktemp("db") / "hertz.h5"
    run_cli("offline", "--problem", "hertz", "--train", str(HERTZ_TRAIN), "--out", str(path), "--threads", "2")
    return path
