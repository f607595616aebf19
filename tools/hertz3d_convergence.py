#!/usr/bin/python3
"""hertz3d against Hertz theory under refinement (the table of docs/results.md).

For each refinement level and approach d: the FOM (active set) solution, its KKT
residual, the total contact force F (four times the quarter model's), the contact
radius a and peak pressure p0 of a least-squares fit of the Hertz profile
p^2 = p0^2 (1 - r^2/a^2) to the nodal pressures in contact, and Hertz's a and p0 for
the force F (sphere of radius R = 1 on a half-space, two bodies E = 1, nu = 0.3):
a = (3 F R / 4 E*)^(1/3), p0 = 3 F / (2 pi a^2), E* = E / (2 (1 - nu^2)).

    PYTHONPATH=build/python /usr/bin/python3 tools/hertz3d_convergence.py --refine 0 1 --d 0.01 0.02 0.03

--mesh overrides the constants of meshes/hertz3d.geo (as tools/scaling3d.py does),
e.g. the coarse grading whose refine 0, 1, 2 give the contact force's rate:

    PYTHONPATH=build/python /usr/bin/python3 tools/hertz3d_convergence.py \
        --mesh "hmin = 0.03; alpha = 0.15; rc = 0.2; rm = 0.25;" --refine 0 1 2 --d 0.01 0.02 0.03
"""
import argparse
import math
import os
import tempfile
import time

import numpy as np

import contactrom

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--problem", default="hertz3d")
parser.add_argument("--refine", type=int, nargs="+", default=[0, 1])
parser.add_argument("--d", type=float, nargs="+", default=[0.01, 0.02, 0.03])
parser.add_argument("--mesh", help="gmsh assignments of hertz3d.geo's constants, e.g. \"hmin = 0.03;\"")
args = parser.parse_args()
tmp = tempfile.TemporaryDirectory()
if args.mesh:  # hertz3d with its mesh constants overridden before the .geo is included
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    geo = os.path.join(tmp.name, "variant.geo")
    with open(geo, "w") as f:
        f.write(f'{args.mesh}\nInclude "{os.path.join(root, "meshes", "hertz3d.geo")}";\n')
    text = open(os.path.join(root, "problems", "hertz3d.toml")).read()
    args.problem = os.path.join(tmp.name, "variant.toml")
    with open(args.problem, "w") as f:
        f.write(text.replace('"../meshes/hertz3d.geo"', f'"{geo}"').replace('name = "hertz3d"', 'name = "variant"'))

E_STAR, RADIUS = 1.0 / (2.0 * (1.0 - 0.3 ** 2)), 1.0
forces = {}
print("| refine | dofs | contact rows | setup (s) | d | F | a fit | a Hertz | error | p0 fit | p0 Hertz | error | max nodal p | KKT max |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for refine in args.refine:
    t0 = time.perf_counter()
    problem = contactrom.problem(args.problem, refine=refine)
    solver = contactrom.FullOrderSolver(problem)
    setup = time.perf_counter() - t0
    xy = np.asarray(problem.contact_points)[:, :2]
    r2 = (xy ** 2).sum(axis=1)
    for d in args.d:
        sol = solver.solve(d)
        assert sol.status == "success", sol.status
        lam = np.asarray(sol.lam)
        force = 4.0 * sol.contact_force
        forces[(refine, d)] = force
        a_h = (3.0 * force * RADIUS / (4.0 * E_STAR)) ** (1.0 / 3.0)
        p0_h = 3.0 * force / (2.0 * math.pi * a_h ** 2)
        on = lam > 0
        slope, intercept = np.polyfit(r2[on], lam[on] ** 2, 1)
        a_fit, p0_fit = math.sqrt(-intercept / slope), math.sqrt(intercept)
        print(f"| {refine} | {problem.num_dofs} | {problem.num_constraints} | {setup:.1f} | {d:g} | {force:.5g} | "
              f"{a_fit:.4f} | {a_h:.4f} | {100 * (a_fit / a_h - 1):+.2f} % | {p0_fit:.4f} | {p0_h:.4f} | "
              f"{100 * (p0_fit / p0_h - 1):+.2f} % | {lam.max():.4f} ({100 * (lam.max() / p0_h - 1):+.1f} %) | "
              f"{sol.kkt['max']:.1e} |", flush=True)

# Contact force under refinement: the change from each level to the next, and with
# three consecutive levels the observed order p = log2(|F0 - F1| / |F1 - F2|) (the
# element size halves per level) and the Richardson limit F2 + (F2 - F1) / (2^p - 1).
levels = sorted(args.refine)
if len(levels) >= 2:
    print()
    print("| d | " + " | ".join(f"F refine {k}" for k in levels) + " | changes | order p | Richardson limit |")
    print("|---|" + "---|" * len(levels) + "---|---|---|")
    for d in args.d:
        f = [forces[(k, d)] for k in levels]
        changes = ", ".join(f"{100 * (b / a - 1):+.2f} %" for a, b in zip(f, f[1:]))
        order = limit = "–"
        if len(f) >= 3 and (f[-3] - f[-2]) * (f[-2] - f[-1]) > 0:
            p = math.log2(abs(f[-3] - f[-2]) / abs(f[-2] - f[-1]))
            order, limit = f"{p:.2f}", f"{f[-1] + (f[-1] - f[-2]) / (2 ** p - 1):.5g}"
        print(f"| {d:g} | " + " | ".join(f"{x:.5g}" for x in f) + f" | {changes} | {order} | {limit} |")
