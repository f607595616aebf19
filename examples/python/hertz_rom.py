#!/usr/bin/env python3
"""Reduced model of the Hertz contact problem, from Python.

Builds a greedy ROM of `hertz` from 30 FOM snapshots, queries it at 200
parameters, and plots (PNG files in --out):
  hertz_pressure.png  the ROM contact pressure against the FOM at three parameters,
  hertz_error.png     the relative primal (H1) and dual (L2) errors along the range.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/hertz_rom.py --out plots
    PYTHONPATH=build/python /usr/bin/python3 examples/python/hertz_rom.py --quick --out plots   # 20 queries
"""
import argparse
import os
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import contactrom  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True, help="folder for the PNG files")
    parser.add_argument("--train", type=int, default=30, help="training snapshots (default 30)")
    parser.add_argument("--queries", type=int, default=200, help="query parameters (default 200)")
    parser.add_argument("--quick", action="store_true", help="20 queries (for the test suite)")
    parser.add_argument("--threads", type=int, default=0, help="threads of the FOM solves (default: all cores)")
    args = parser.parse_args()
    queries = 20 if args.quick else args.queries
    os.makedirs(args.out, exist_ok=True)

    problem = contactrom.problem("hertz")
    t0 = time.perf_counter()
    db = contactrom.offline(problem, args.train, threads=args.threads)
    rom = contactrom.ReducedModel(db, delta=1e-8, method="greedy")
    t_offline = time.perf_counter() - t0

    # Query parameters: midpoints of a uniform grid of (0, 0.3].
    lo, hi = problem.param_lower[0], problem.param_upper[0]
    d = lo + (hi - lo) * (np.arange(queries) + 0.5) / queries
    t0 = time.perf_counter()
    results = rom.solve_all(d)
    t_online = time.perf_counter() - t0
    report = rom.evaluate(d, threads=args.threads)  # errors against the FOM
    rows = report["rows"]

    # Pressure along the contact arc at three parameters.
    fom = contactrom.FullOrderSolver(problem)
    x = problem.contact_points[:, 0]
    order = np.argsort(x)
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for k, colour in zip((queries // 6, queries // 2, queries - 1), ("C0", "C1", "C2")):
        ref = fom.solve(d[k])
        ax.plot(x[order], ref.lam[order], "-", color=colour, label=f"FOM d = {d[k]:.3f}")
        ax.plot(x[order], results[k].lam[order], "o", color=colour, markersize=3, label=f"ROM d = {d[k]:.3f}")
    ax.set_xlabel("x on the contact arc")
    ax.set_ylabel("contact pressure")
    ax.set_xlim(-0.6, 0.6)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "hertz_pressure.png"), dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    ax.semilogy(rows["mu"][:, 0], np.maximum(rows["primal_error"], 1e-17), ".-", label="primal (H1)")
    ax.semilogy(rows["mu"][:, 0], np.maximum(rows["dual_error"], 1e-17), ".-", label="dual (L2 on the contact arc)")
    for k, d_train in enumerate(db.parameters[:, 0]):
        ax.axvline(d_train, color="0.85", linewidth=0.8, zorder=0, label="training parameters" if k == 0 else None)
    ax.set_xlabel("d")
    ax.set_ylabel("relative error of the ROM")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "hertz_error.png"), dpi=120)
    plt.close(fig)

    print(f"hertz: {args.train} snapshots, primal rank {rom.primal_rank}, dictionary {rom.dictionary_size}; "
          f"offline {t_offline:.2f} s")
    print(f"{queries} queries in {t_online * 1e3:.1f} ms; primal error mean {report['mean_primal_error']:.2e} "
          f"max {report['max_primal_error']:.2e}, dual error mean {report['mean_dual_error']:.2e} "
          f"max {report['max_dual_error']:.2e} (largest below the first training parameter); "
          f"not converged {report['nonconverged']}")
    print(f"plots written to {args.out}/hertz_pressure.png and {args.out}/hertz_error.png")
    if report["nonconverged"] or report["fom_failures"]:
        raise SystemExit("some queries did not converge")


if __name__ == "__main__":
    main()
