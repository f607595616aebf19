#!/usr/bin/python3
"""Comparison table of the online methods (the paper's tab:comparison_methods).

For each case (default: hertz with 30 snapshots, ironing level 7 = 129 snapshots)
the script runs the contactrom CLI:

  contactrom offline --problem P (--train N | --level n) --out DB.h5      (if DB.h5 is missing)
  contactrom online  --db DB.h5 --method M --validation --delta D --json  (M = greedy, greedy-nested, cpg, full-dictionary)
  contactrom verify  --db DB.h5 --method greedy,greedy-nested,cpg,full-dictionary --reference fom --bench --delta D --json
  contactrom verify  --db DB.h5 --method cpg --cpg-tolerance T --reference fom --bench --delta D --json
                                                                          (each extra --cpg-tolerance T)
  contactrom online  --db DB.h5 --method M --option init=I --validation --delta D --json
  contactrom verify  --db DB.h5 --method M --init I --reference fom --bench --delta D --json
                                         (M, I = greedy, empty: paper Alg. 1; cpg, cell: warm-started CPG)

and writes one markdown table per case (stdout and --md) and a CSV (--csv) with:
primal RB size, dual RB / dictionary size, mean time per query (online, one
sequential pass), median time per query and speed-up over the FOM with the
factorisation reused (verify --bench: the FOM and the methods timed together in
interleaved rounds, rom::time_interleaved), the median time without the
construction of the contact operators (the paper's timing convention; a clocked
twin of each method timed in the same rounds), mean primal
H1 and dual L2 errors against the FOM, mean |I|, mean iterations, non-converged
queries and the largest reduced-level penetration against tau. Every online and
verify run passes --option estimate=false: the methods are timed without the error
estimate they all share (`contactrom bench` times it, key rom_greedy_with_estimate).

Usage:
  /usr/bin/python3 tools/compare_methods.py --exe build/tools/contactrom --workdir /tmp/cmp \
      --md docs/comparison.md --csv comparison.csv [--cases hertz:train:30,ironing:level:7] \
      [--delta 1e-8] [--cpg-tolerance 1e-2 ...] [--threads 2]
"""
import argparse
import csv
import json
import os
import subprocess
import sys

METHODS = ["greedy", "greedy-nested", "cpg", "full-dictionary"]


def run_json(cmd):
    """Runs a CLI command that prints one JSON object; exits with its stderr on failure."""
    print("+ " + " ".join(cmd), file=sys.stderr, flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        sys.exit("compare_methods: command failed (exit %d): %s\n%s" % (proc.returncode, " ".join(cmd), proc.stderr))
    return json.loads(proc.stdout)


def fmt(value, digits=2):
    if value is None:
        return "-"
    if isinstance(value, int):
        return str(value)
    return "%.*e" % (digits, value)


def parse_cases(text):
    cases = []
    for item in text.split(","):
        parts = item.split(":")
        if len(parts) != 3 or parts[1] not in ("train", "level"):
            sys.exit("compare_methods: bad case '%s'; expected problem:train:N or problem:level:n" % item)
        cases.append((parts[0], parts[1], int(parts[2])))
    return cases


def evaluate_case(args, problem, kind, n):
    db = os.path.join(args.workdir, "%s_%s%d.h5" % (problem, kind, n))
    if not os.path.exists(db):
        run_json([args.exe, "offline", "--problem", problem, "--" + kind, str(n), "--out", db,
                  "--threads", str(args.threads), "--json"])
    # The methods are compared as the paper times them: the error estimate, which every
    # method shares and which is timed on its own by `bench`, is off.
    shared = ["--delta", repr(args.delta), "--option", "estimate=false"]
    columns = []
    online = {m: run_json([args.exe, "online", "--db", db, "--method", m, "--validation", "--threads",
                           str(args.threads), "--json"] + shared) for m in METHODS}
    verify = run_json([args.exe, "verify", "--db", db, "--method", ",".join(METHODS), "--reference", "fom",
                       "--bench", "--threads", str(args.threads), "--json"] + shared)
    for m in METHODS:
        o, v = online[m], verify["methods"][m]
        label = m if m != "cpg" else "cpg (tol %g, default)" % default_tolerance(problem)
        columns.append(column(label, o["primal_rank"], v["dual_basis_size"], o["mean_time_s"], v, o["mean_primal_error"],
                              o["mean_dual_error"], o["mean_sparsity"], o["mean_iterations"], o["nonconverged"]))
    for tol in args.cpg_tolerance:
        if tol == default_tolerance(problem):
            continue  # already the default column
        v = run_json([args.exe, "verify", "--db", db, "--method", "cpg", "--reference", "fom", "--bench",
                      "--cpg-tolerance", repr(tol), "--threads", str(args.threads), "--json"] + shared)["methods"]["cpg"]
        columns.append(column("cpg (tol %g)" % tol, v["primal_rank"], v["dual_basis_size"], v["mean_time_s"], v,
                              v["mean_primal_error"], v["mean_dual_error"], v["mean_sparsity"], v["mean_iterations"],
                              v["nonconverged"]))
    # The other starting points: the greedy as in the paper's Alg. 1 (the default is
    # warm) and CPG warm-started like the greedy (the default is the paper's cold start).
    for m, init, label in (("greedy", "empty", "greedy (init=empty, paper Alg. 1)"),
                           ("cpg", "cell", "cpg (default tol, init=cell)")):
        o = run_json([args.exe, "online", "--db", db, "--method", m, "--option", "init=" + init, "--validation",
                      "--threads", str(args.threads), "--json"] + shared)
        v = run_json([args.exe, "verify", "--db", db, "--method", m, "--init", init, "--reference", "fom", "--bench",
                      "--threads", str(args.threads), "--json"] + shared)["methods"][m]
        columns.append(column(label, o["primal_rank"], v["dual_basis_size"], o["mean_time_s"], v, o["mean_primal_error"],
                              o["mean_dual_error"], o["mean_sparsity"], o["mean_iterations"], o["nonconverged"]))
    return {"problem": problem, "kind": kind, "n": n, "db": db, "fom_median_time_s": verify["fom_median_time_s"],
            "validation_size": verify["validation_size"], "columns": columns}


def default_tolerance(problem):
    return 5e-2 if problem in ("ironing", "ironing2") else 1e-2


def column(label, rank, dual, mean_time, v, primal, dual_err, sparsity, iterations, nonconverged):
    return {"method": label, "primal_rb_size": rank, "dual_size": dual, "mean_time_s": mean_time,
            "median_time_s": v["median_time_s"], "speedup_vs_fom": v["speedup_vs_fom"],
            "median_time_without_operators_s": v["median_time_without_operators_s"],
            "mean_primal_error": primal, "mean_dual_error": dual_err, "mean_sparsity": sparsity,
            "mean_iterations": iterations, "nonconverged": nonconverged,
            "max_reduced_penetration": v["max_reduced_penetration"], "tau": v["tau"]}


def markdown(case):
    cols = case["columns"]
    title = "%s, %s %d (%d validation parameters; FOM median %.3g ms per query, factorisation reused)" % (
        case["problem"], "--train" if case["kind"] == "train" else "--level", case["n"], case["validation_size"],
        1e3 * case["fom_median_time_s"])
    rows = [
        ("Primal RB size", lambda c: str(c["primal_rb_size"])),
        ("Dual RB / dictionary size", lambda c: str(c["dual_size"])),
        ("Mean time per query (s)", lambda c: fmt(c["mean_time_s"])),
        ("Median time per query (s)", lambda c: fmt(c["median_time_s"])),
        ("Speed-up over the FOM (median)", lambda c: "%.1f" % c["speedup_vs_fom"]),
        ("Median time without building the contact operators (s)",
         lambda c: fmt(c["median_time_without_operators_s"]) if c["median_time_without_operators_s"] >= 0 else "—"),
        ("Mean primal H1 error", lambda c: fmt(c["mean_primal_error"])),
        ("Mean dual L2 error", lambda c: fmt(c["mean_dual_error"])),
        ("Mean active columns #I", lambda c: "%.2f" % c["mean_sparsity"]),
        ("Mean iterations", lambda c: "%.2f" % c["mean_iterations"]),
        ("Not converged", lambda c: str(c["nonconverged"])),
        ("Max reduced penetration (tau)", lambda c: "%s (%s)" % (fmt(c["max_reduced_penetration"]), fmt(c["tau"], 0))),
    ]
    out = ["**%s**" % title, "", "| | " + " | ".join(c["method"] for c in cols) + " |",
           "|---|" + "---|" * len(cols)]
    for name, f in rows:
        out.append("| %s | %s |" % (name, " | ".join(f(c) for c in cols)))
    return "\n".join(out) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--exe", default="build/tools/contactrom", help="contactrom executable")
    parser.add_argument("--workdir", default="compare_methods", help="folder for the databases (reused)")
    parser.add_argument("--cases", default="hertz:train:30,ironing:level:7", help="problem:train:N or problem:level:n, comma-separated")
    parser.add_argument("--delta", type=float, default=1e-8, help="POD tolerance (default 1e-8)")
    parser.add_argument("--cpg-tolerance", type=float, nargs="*", default=[], help="extra CPG tolerances to tabulate")
    parser.add_argument("--threads", type=int, default=2, help="threads for offline and FOM references (default 2)")
    parser.add_argument("--md", help="write the markdown tables here")
    parser.add_argument("--csv", help="write the CSV here")
    args = parser.parse_args()
    if not os.access(args.exe, os.X_OK):
        sys.exit("compare_methods: executable '%s' not found; pass --exe" % args.exe)
    os.makedirs(args.workdir, exist_ok=True)
    cases = [evaluate_case(args, *c) for c in parse_cases(args.cases)]
    text = "\n".join(markdown(c) for c in cases)
    print(text)
    if args.md:
        with open(args.md, "w") as f:
            f.write(text)
    if args.csv:
        keys = ["problem", "kind", "n", "method", "primal_rb_size", "dual_size", "mean_time_s", "median_time_s",
                "speedup_vs_fom", "median_time_without_operators_s", "mean_primal_error", "mean_dual_error", "mean_sparsity", "mean_iterations",
                "nonconverged", "max_reduced_penetration", "tau"]
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys)
            w.writeheader()
            for c in cases:
                for col in c["columns"]:
                    w.writerow(dict(col, problem=c["problem"], kind=c["kind"], n=c["n"]))


if __name__ == "__main__":
    main()
