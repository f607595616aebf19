#!/usr/bin/python3
"""Reference NNLS solutions from SciPy for tests/rom/test_sparse_cli.cpp.

Usage: /usr/bin/python3 tests/rom/nnls_scipy_check.py DIR

For every pair DIR/<name>.A.csv, DIR/<name>.b.csv (one matrix row per line,
comma-separated; b one value per line) solves min ||A x - b||_2 s.t. x >= 0 with
scipy.optimize.nnls and prints one JSON object on stdout:

  {"scipy": "<version>",
   "problems": {"<name>": {"objective": 0.5*||A x - b||^2, "x": [...]}
                           or {"error": "<message>"}}}

Exit codes: 0 on success, 2 on bad usage, 3 if SciPy (or NumPy) cannot be
imported -- the C++ test turns that into a failure unless
CONTACTROM_ALLOW_NO_SCIPY=1, in which case it reports the skip.
"""
import glob
import json
import os
import sys


def main(argv):
    if len(argv) != 2 or not os.path.isdir(argv[1]):
        print("usage: nnls_scipy_check.py DIR", file=sys.stderr)
        return 2
    try:
        import numpy as np
        import scipy
        from scipy.optimize import nnls
    except Exception as error:  # ImportError, or a broken installation
        print("scipy not available to %s: %s" % (sys.executable, error), file=sys.stderr)
        return 3

    problems = {}
    for a_path in sorted(glob.glob(os.path.join(argv[1], "*.A.csv"))):
        name = os.path.basename(a_path)[: -len(".A.csv")]
        b_path = os.path.join(argv[1], name + ".b.csv")
        a = np.loadtxt(a_path, delimiter=",", ndmin=2)
        b = np.loadtxt(b_path, delimiter=",", ndmin=1)
        try:
            # Generous iteration cap: the reference must not stop early.
            x, _ = nnls(a, b, maxiter=50 * max(a.shape[1], 1))
        except RuntimeError as error:
            problems[name] = {"error": str(error)}
            continue
        r = a @ x - b
        problems[name] = {"objective": 0.5 * float(r @ r), "x": [float(v) for v in x]}
    json.dump({"scipy": scipy.__version__, "problems": problems}, sys.stdout)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
