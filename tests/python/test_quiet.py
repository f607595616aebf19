"""The module writes nothing on stdout (a Python program owns its stdout), and
reports the version of the C++ library it wraps."""
import os
import subprocess
import sys

import contactrom
from conftest import run_cli

SCRIPT = """
import contactrom
hertz = contactrom.problem("hertz")
contactrom.FullOrderSolver(hertz).solve(0.2)
contactrom.FullOrderSolver(hertz, solver="ipopt").solve(0.2)
db = contactrom.offline(hertz, 5, threads=2)
db.save(DB)
db = contactrom.load_database(DB)
for method in contactrom.online_methods():
    if method != "convex-hull":
        contactrom.ReducedModel(db, method=method).solve(0.1)
try:
    contactrom.problem("no-such-problem")
except ValueError:
    pass
"""


def test_nothing_on_stdout(tmp_path):
    db = str(tmp_path / "db.h5")
    proc = subprocess.run([sys.executable, "-c", f"DB = {db!r}\n" + SCRIPT], capture_output=True, text=True,
                          env=dict(os.environ), timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ""


def test_version_is_the_command_line_tool_s():
    assert run_cli("--version").stdout == f"contactrom {contactrom.__version__}\n"
    assert contactrom.__version__.count(".") == 2
