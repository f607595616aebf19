#!/usr/bin/python3
"""Convex-hull experiments on the elastic rope (paper appendix B, section "Illustrative
example: elastic rope-obstacle problem"), reproduced with the contactrom CLI.

Usage:
    /usr/bin/python3 tools/rope_experiments.py RESULTS_DIR [--exe PATH] [--delta 1e-7]
                                               [--bench] [--threads 2]

The executable is --exe, else $CONTACTROM_EXE, else build/tools/contactrom under the
repository root. Run with /usr/bin/python3 (Debian's matplotlib; see TOOLCHAIN.md).

Writes into RESULTS_DIR:
    rope.h5                         snapshot database (contactrom offline --problem rope)
    rope_chls.csv, rope_chls.png    leave-one-out CHLS errors vs gamma (contactrom chls)
    rope_hull_{training,validation}[_nopolish].csv
                                    per-query results of contactrom hull-report: errors,
                                    sparsity, |1'a - 1|, penetration, complementarity,
                                    selected snapshots and coefficients
    rope_online_validation.csv      contactrom online --method convex-hull --validation
    rope_hull_errors.png            primal (H1) and dual (L2) errors vs gamma, training and
                                    validation, sparsity on the right axis (paper figure)
    rope_compliance.csv, rope_compliance.md
                                    the compliance table (max over each set), with the exact
                                    simplex polish (default) and without (the paper's variant)
    rope_summary.json               every number above, and the commands that produced them
    bench.json (--bench)            median online time per query, rope and hertz (30 snapshots)
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(exe, args, commands):
    """Runs `exe args`, records the command line, returns stdout; exits on failure."""
    cmd = [exe] + [str(a) for a in args]
    commands.append(" ".join(["contactrom"] + cmd[1:]))
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit("command failed (%d): %s\n%s" % (proc.returncode, " ".join(cmd), proc.stderr.strip()))
    return proc.stdout


def run_json(exe, args, commands):
    return json.loads(run(exe, list(args) + ["--json"], commands))


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def column(rows, key, kind=float):
    return [kind(r[key]) for r in rows]


def plot_chls(rows, path):
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.semilogy(column(rows, "gamma"), column(rows, "chls_error"), "o-")
    ax.set_xlabel(r"stiffness $\nu = \gamma$ of the left half")
    ax.set_ylabel(r"CHLS distance $\epsilon_{\mathtt{CHLS}}$ (relative)")
    ax.set_title("Leave-one-out convex hull least squares (rope)")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def plot_errors(training, validation, path):
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    floor = 1e-17  # training errors can be exactly 0; show them at the floor
    for ax, key, title in ((axes[0], "primal_error", "Displacement (H1)"),
                           (axes[1], "dual_error", "Contact pressure (L2)")):
        for rows, style, label in ((training, "o", "training"), (validation, "s", "validation")):
            ax.semilogy(column(rows, "gamma"), [max(v, floor) for v in column(rows, key)], style,
                        label=label + " error")
        ax.set_xlabel(r"stiffness $\nu = \gamma$ of the left half")
        ax.set_ylabel("relative error")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        right = ax.twinx()
        for rows, colour, label in ((training, "C0", "training"), (validation, "C1", "validation")):
            right.plot(column(rows, "gamma"), column(rows, "sparsity", int), "x", color=colour, ms=8,
                       label=label + " sparsity")
        right.set_ylabel("sparsity (selected snapshots)")
        right.set_ylim(0, 5)
        lines = ax.get_legend_handles_labels()
        rlines = right.get_legend_handles_labels()
    fig.suptitle(r"Convex hull reconstruction, rope, $\mathbf{B} = \mathrm{svd}(D_p, \delta)$"
                 "\n(errors of exactly 0 drawn at 1e-17)", fontsize=10)
    fig.legend(lines[0] + rlines[0], lines[1] + rlines[1], fontsize=8, loc="lower center", ncol=4, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=150)
    plt.close(fig)


COMPLIANCE = [
    ("|1'a - 1|", "sum_violation"),
    ("penetration (relative)", "penetration"),
    ("penetration (absolute, length)", "penetration_abs"),
    ("complementary slack (relative)", "complementarity"),
    ("complementary slack (absolute, |l'(Cu - g)|)", "complementarity_abs"),
    ("primal H1 error", "primal_error"),
    ("dual L2 error", "dual_error"),
]


def compliance_table(sets):
    """sets: {name: rows}; returns [(label, {name: max})]."""
    table = []
    for label, key in COMPLIANCE:
        table.append((label, {name: max(column(rows, key)) for name, rows in sets.items()}))
    return table


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", help="folder for the CSV, PNG and JSON outputs")
    parser.add_argument("--exe", default=os.environ.get("CONTACTROM_EXE",
                                                        os.path.join(REPO, "build", "tools", "contactrom")))
    parser.add_argument("--delta", type=float, default=1e-7, help="SVD tolerance of B (paper: 1e-7)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--bench", action="store_true",
                        help="also time the online solve on rope and hertz (30 snapshots)")
    a = parser.parse_args()
    if not os.path.isfile(a.exe):
        sys.exit("contactrom executable not found: %s (give --exe or set CONTACTROM_EXE)" % a.exe)
    os.makedirs(a.results, exist_ok=True)
    out = lambda name: os.path.join(a.results, name)  # noqa: E731
    commands = []
    summary = {"delta": a.delta}

    db = out("rope.h5")
    run(a.exe, ["offline", "--problem", "rope", "--out", db, "--threads", a.threads], commands)

    summary["chls"] = run_json(a.exe, ["chls", "--db", db, "--out", out("rope_chls.csv")], commands)
    plot_chls(read_csv(out("rope_chls.csv")), out("rope_chls.png"))

    sets = {}
    for polish in (True, False):
        suffix = "" if polish else "_nopolish"
        for name in ("training", "validation"):
            path = out("rope_hull_%s%s.csv" % (name, suffix))
            args = ["hull-report", "--db", db, "--set", name, "--delta", a.delta, "--out", path,
                    "--threads", a.threads]
            if not polish:  # the paper's variant: convexity only through the weighted row (weight 1)
                args += ["--no-polish", "--sum-weight", 1]
            summary["hull_%s%s" % (name, suffix)] = run_json(a.exe, args, commands)
            sets[name + suffix] = read_csv(path)
    summary["online_validation"] = run_json(
        a.exe, ["online", "--db", db, "--method", "convex-hull", "--delta", a.delta, "--validation",
                "--out", out("rope_online_validation.csv"), "--threads", a.threads], commands)
    plot_errors(sets["training"], sets["validation"], out("rope_hull_errors.png"))

    # Validation: are the two training neighbours gamma +- 2.5 selected?
    training_gammas = [float(g) for g in column(sets["training"], "gamma")]
    neighbours = []
    for row in sets["validation"]:
        g = float(row["gamma"])
        selected = [training_gammas[int(i)] for i in row["selected"].split()]
        neighbours.append(all(any(abs(s - t) < 1e-9 for s in selected) for t in (g - 2.5, g + 2.5)))
    summary["validation_selects_neighbours"] = neighbours

    table = compliance_table(sets)
    names = ["training", "validation", "training_nopolish", "validation_nopolish"]
    with open(out("rope_compliance.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["quantity"] + names)
        for label, values in table:
            w.writerow([label] + ["%.3e" % values[n] for n in names])
    with open(out("rope_compliance.md"), "w") as f:
        f.write("| max over the set | training | validation | training (no polish) | validation (no polish) |\n")
        f.write("|---|---|---|---|---|\n")
        for label, values in table:
            f.write("| %s | %s |\n" % (label.replace("|", "\\|"), " | ".join("%.1e" % values[n] for n in names)))
    summary["compliance"] = {label: values for label, values in table}

    if a.bench:
        bench = {}
        bench["rope"] = run_json(a.exe, ["hull-report", "--db", db, "--set", "validation", "--delta", a.delta,
                                         "--time", "--repeats", 20, "--threads", a.threads], commands)
        hertz = out("hertz30.h5")
        run(a.exe, ["offline", "--problem", "hertz", "--train", 30, "--out", hertz, "--threads", a.threads],
            commands)
        bench["hertz"] = run_json(a.exe, ["hull-report", "--db", hertz, "--set", "validation", "--delta", 1e-8,
                                          "--time", "--repeats", 3, "--threads", a.threads], commands)
        with open(out("bench.json"), "w") as f:
            json.dump({k: {"median_time_s": v["median_time_s"], "median_total_time_s": v["median_total_time_s"],
                           "timed_queries": v["timed_queries"], "mean_pairing_iterations":
                           v["mean_pairing_iterations"]} for k, v in bench.items()}, f, indent=2)
        summary["bench"] = bench

    summary["commands"] = commands
    with open(out("rope_summary.json"), "w") as f:
        json.dump(summary, f, indent=2)

    print("rope convex hull (delta %g), results in %s" % (a.delta, a.results))
    print("CHLS: max %.3e, mean %.3e" % (summary["chls"]["max_chls_error"], summary["chls"]["mean_chls_error"]))
    for name in ("training", "validation"):
        s = summary["hull_" + name]
        print("%-10s max primal %.2e, max dual %.2e, mean sparsity %.2f, max |1'a-1| %.1e, "
              "max penetration %.1e, max complementarity %.1e"
              % (name, s["max_primal_error"], s["max_dual_error"], s["mean_sparsity"], s["max_sum_violation"],
                 s["max_penetration"], s["max_complementarity"]))
    print("validation selects both training neighbours: %d of %d" % (sum(neighbours), len(neighbours)))
    with open(out("rope_compliance.md")) as f:
        print(f.read(), end="")
    if a.bench:
        for k, v in summary["bench"].items():
            print("bench %-6s median online time per query %.1f us" % (k, v["median_time_s"] * 1e6))


if __name__ == "__main__":
    main()
