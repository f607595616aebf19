#!/usr/bin/python3
"""FOM solutions of the shipped 2D problems, to check that a change of library
(e.g. the BLAS under CHOLMOD) leaves them unchanged.

    PYTHONPATH=build/python /usr/bin/python3 tools/fom_fingerprint.py --out a.npz
    (change the library, e.g. update-alternatives --config libblas.so.3-x86_64-linux-gnu)
    PYTHONPATH=build/python /usr/bin/python3 tools/fom_fingerprint.py --out b.npz
    /usr/bin/python3 tools/fom_fingerprint.py --compare a.npz b.npz

--compare prints, per problem and parameter, the largest difference of the
displacements relative to the largest displacement, and of the pressures relative
to the largest pressure, and exits 1 if any exceeds --tol (default 1e-10).
"""
import argparse
import sys

import numpy as np

CASES = {  # shipped problem: parameter points (the ends and inside of their ranges)
    "hertz": [[0.01], [0.15], [0.3]],
    "ironing": [[0.0], [1.7], [4.0]],
    "ironing2": [[0.0, 0.1], [2.5, 0.2], [4.0, 0.3]],
    "punch_beam": [[0.05], [0.1], [0.2]],
}

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--out", help="write the solutions to this .npz file")
parser.add_argument("--compare", nargs=2, metavar=("A", "B"), help="compare two such files")
parser.add_argument("--tol", type=float, default=1e-10)
args = parser.parse_args()

if args.out:
    import contactrom
    arrays = {}
    for name, params in CASES.items():
        solver = contactrom.FullOrderSolver(contactrom.problem(name))
        for i, mu in enumerate(params):
            sol = solver.solve(mu)
            assert sol.status == "success", (name, mu, sol.status)
            arrays[f"{name}/{i}/u"], arrays[f"{name}/{i}/lam"] = np.array(sol.u), np.array(sol.lam)
    np.savez(args.out, **arrays)
if args.compare:
    a, b = (np.load(path) for path in args.compare)
    worst = 0.0
    print("| problem | parameter | max |Δu| / max |u| | max |Δλ| / max |λ| |")
    print("|---|---|---|---|")
    for name, params in CASES.items():
        for i, mu in enumerate(params):
            du = np.abs(a[f"{name}/{i}/u"] - b[f"{name}/{i}/u"]).max() / np.abs(a[f"{name}/{i}/u"]).max()
            dl = np.abs(a[f"{name}/{i}/lam"] - b[f"{name}/{i}/lam"]).max() / np.abs(a[f"{name}/{i}/lam"]).max()
            worst = max(worst, du, dl)
            print(f"| {name} | {', '.join(f'{x:g}' for x in mu)} | {du:.1e} | {dl:.1e} |")
    print(f"largest: {worst:.1e} (tolerance {args.tol:g})")
    sys.exit(0 if worst <= args.tol else 1)
