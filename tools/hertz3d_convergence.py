#!/usr/bin/python3
"""hertz3d against Hertz theory under refinement (the table of docs/results.md).

For each refinement level and approach d: the FOM (active set) solution, its KKT
residual, the total contact force F (four times the quarter model's), the contact
radius a and peak pressure p0 of a least-squares fit of the Hertz profile
p^2 = p0^2 (1 - r^2/a^2) to the nodal pressures in contact, and Hertz's a and p0 for
the force F (sphere of radius R = 1 on a half-space, two bodies E = 1, nu = 0.3):
a = (3 F R / 4 E*)^(1/3), p0 = 3 F / (2 pi a^2), E* = E / (2 (1 - nu^2)).

    PYTHONPATH=build/python /usr/bin/python3 tools/hertz3d_convergence.py --refine 0 1 --d 0.01 0.02 0.03
"""
import argparse
import math
import time

import numpy as np

import contactrom

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--problem", default="hertz3d")
parser.add_argument("--refine", type=int, nargs="+", default=[0, 1])
parser.add_argument("--d", type=float, nargs="+", default=[0.01, 0.02, 0.03])
args = parser.parse_args()

E_STAR, RADIUS = 1.0 / (2.0 * (1.0 - 0.3 ** 2)), 1.0
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
        a_h = (3.0 * force * RADIUS / (4.0 * E_STAR)) ** (1.0 / 3.0)
        p0_h = 3.0 * force / (2.0 * math.pi * a_h ** 2)
        on = lam > 0
        slope, intercept = np.polyfit(r2[on], lam[on] ** 2, 1)
        a_fit, p0_fit = math.sqrt(-intercept / slope), math.sqrt(intercept)
        print(f"| {refine} | {problem.num_dofs} | {problem.num_constraints} | {setup:.1f} | {d:g} | {force:.5g} | "
              f"{a_fit:.4f} | {a_h:.4f} | {100 * (a_fit / a_h - 1):+.2f} % | {p0_fit:.4f} | {p0_h:.4f} | "
              f"{100 * (p0_fit / p0_h - 1):+.2f} % | {lam.max():.4f} ({100 * (lam.max() / p0_h - 1):+.1f} %) | "
              f"{sol.kkt['max']:.1e} |", flush=True)
