#!/usr/bin/python3
"""Adaptive training against uniform and nested grids: true validation errors and
offline wall time against the number of snapshots, with the contactrom CLI.

    tools/adaptive_experiment.py [--exe PATH] [--out DIR] [--figure PATH] [--threads T]
                                 [--only hertz,punch_beam,ironing2] [--replot]

For each case, one validation parameter list (the validation set of the finest grid:
hertz the 119 midpoints of 120 uniform points, punch_beam the 15 midpoints of 16,
ironing2 level 6 minus level 5, 3136 points), written to DIR/<case>_params.csv from
`contactrom online --validation` on that grid, and

  grid      `contactrom offline --problem P --train n | --level n --out DIR/<case>_grid_<n>.h5
            --threads T --json` for the grid sizes below, each evaluated by
            `contactrom online --db ... --method greedy --delta 1e-8 --validation
            --params DIR/<case>_params.csv --threads T --json`;
  adaptive  `contactrom offline --problem P --adaptive --tolerance EPS --max-snapshots N1
            --candidates M --batch B --threads T --out DIR/<case>_adaptive.h5`, then
            `--append` with N2 > N1, ... (each stage starts from the file of the one
            before, copied to DIR/<case>_adaptive_<N>.h5 and evaluated as the grids): the
            stages are rounds of one run, since an appended run is the run it continues.

Cases (N: the checkpoints; B divides N − initial, so every checkpoint is a round):
  hertz     grids --train 12, 30, 60, 120;  adaptive M 1000, B 2, N 10, 20, 30, 40
  punch_beam grids --train 4, 8, 12, 16;    adaptive M 1000, B 1, N 6, 8, 10, 12, 15
  ironing2  grids --level 2, 3, 4, 5;       adaptive M 2000, B 8, N 49, 97, 193, 289, 385, 433
            (433 ≤ 40 % of the 1089 snapshots of level 5)
with EPS = 1e-3 (below every indicator reached: N stops each stage).

Prints a markdown table (snapshots, mean and max primal and dual errors, offline wall
time: the grid's `wall_time_s`, the adaptive run's total up to that checkpoint) and
draws the figure (default docs/figures/adaptive_training.png): per case, mean and max
validation errors against snapshots, grid and adaptive, and the adaptive run's largest
indicator over the candidates per round (from /adaptive in its database). Writes
DIR/adaptive_experiment.json. Use /usr/bin/python3 (matplotlib, h5py from Debian).
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys

import h5py

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CASES = {
    "hertz": dict(flag="--train", grids=[12, 30, 60, 120], candidates=1000, batch=2,
                  checkpoints=[10, 20, 30, 40]),
    "punch_beam": dict(flag="--train", grids=[4, 8, 12, 16], candidates=1000, batch=1,
                       checkpoints=[6, 8, 10, 12, 15]),
    "ironing2": dict(flag="--level", grids=[2, 3, 4, 5], candidates=2000, batch=8,
                     checkpoints=[49, 97, 193, 289, 385, 433]),
}
KEYS = ["mean_primal_error", "max_primal_error", "mean_dual_error", "max_dual_error"]


def run(cmd):
    print("$", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"command failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def evaluate(exe, db, params, threads, out_csv=None):
    cmd = [exe, "online", "--db", db, "--method", "greedy", "--delta", "1e-8", "--validation", "--threads",
           str(threads), "--json"]
    if params:
        cmd += ["--params", params]
    if out_csv:
        cmd += ["--out", out_csv]
    return run(cmd)


def write_params(validation_csv, params_csv, num_params):
    with open(validation_csv) as f, open(params_csv, "w") as g:
        rows = list(csv.reader(f))
        for row in rows:
            g.write(",".join(row[:num_params]) + "\n")


def case(exe, name, spec, out, threads):
    rows = []
    num_params = 2 if name == "ironing2" else 1
    params = os.path.join(out, f"{name}_params.csv")
    for n in spec["grids"]:
        db = os.path.join(out, f"{name}_grid_{n}.h5")
        o = run([exe, "offline", "--problem", name, spec["flag"], str(n), "--out", db, "--threads", str(threads),
                 "--json"])
        if n == spec["grids"][-1]:  # the finest grid's own validation set is the list
            validation = os.path.join(out, f"{name}_grid_{n}_validation.csv")
            evaluate(exe, db, None, threads, validation)
            write_params(validation, params, num_params)
        rows.append(dict(case=name, kind="grid", n=n, snapshots=o["snapshots"], wall_time_s=o["wall_time_s"]))
    for r in rows:
        r.update({k: v for k, v in evaluate(exe, os.path.join(out, f"{name}_grid_{r['n']}.h5"), params,
                                            threads).items() if k in KEYS + ["validation_size"]})
    db = os.path.join(out, f"{name}_adaptive.h5")
    if os.path.exists(db):
        os.remove(db)
    for k, n in enumerate(spec["checkpoints"]):
        target = ["--out", db, "--tolerance", "1e-3", "--candidates", str(spec["candidates"]), "--batch",
                  str(spec["batch"])] if k == 0 else ["--append", db]
        o = run([exe, "offline", "--problem", name, "--adaptive", "--max-snapshots", str(n), "--threads", str(threads),
                 "--json"] + target)
        copy = os.path.join(out, f"{name}_adaptive_{n}.h5")
        shutil.copyfile(db, copy)
        r = dict(case=name, kind="adaptive", n=n, snapshots=o["total_snapshots"], wall_time_s=o["wall_time_s"],
                 max_indicator=o["max_indicator"])
        r.update({key: v for key, v in evaluate(exe, copy, params, threads).items()
                  if key in KEYS + ["validation_size"]})
        rows.append(r)
    with h5py.File(db, "r") as f:
        rounds = dict(snapshots=f["adaptive/round_snapshots"][:].tolist(),
                      max_indicator=f["adaptive/round_max_indicator"][:].tolist(),
                      mean_indicator=f["adaptive/round_mean_indicator"][:].tolist())
    return rows, rounds


def figure(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(results)
    from matplotlib.ticker import NullFormatter
    fig, axes = plt.subplots(2, len(names), figsize=(4.6 * len(names), 7.5), squeeze=False)
    for c, name in enumerate(names):
        rows, rounds = results[name]
        for r, (field, label) in enumerate([("primal", "relative H¹ error (displacement)"),
                                            ("dual", "relative L²(Γc) error (pressure)")]):
            ax = axes[r][c]
            for kind, colour in (("grid", "tab:blue"), ("adaptive", "tab:red")):
                sel = [x for x in rows if x["kind"] == kind]
                n = [x["snapshots"] for x in sel]
                ax.loglog(n, [x[f"max_{field}_error"] for x in sel], "o-", color=colour, label=f"{kind}: max")
                ax.loglog(n, [x[f"mean_{field}_error"] for x in sel], "s--", color=colour, label=f"{kind}: mean")
            ax.loglog(rounds["snapshots"], rounds["max_indicator"], ":", color="tab:gray",
                      label="adaptive: max indicator (candidates)")
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel("snapshots")
            ax.set_ylabel(label)
            ax.set_title(f"{name}: validation errors")
            ax.grid(True, which="both", alpha=0.3)
            if r == 0 and c == 0:
                ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("figure written to", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--exe", default=os.path.join(REPO, "build", "tools", "contactrom"))
    ap.add_argument("--out", default=os.path.join(REPO, "results", "adaptive"))
    ap.add_argument("--figure", default=os.path.join(REPO, "docs", "figures", "adaptive_training.png"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--only", default=",".join(CASES))
    ap.add_argument("--replot", action="store_true", help="run nothing: redraw the figure from DIR's JSON")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.replot:
        with open(os.path.join(a.out, "adaptive_experiment.json")) as f:
            saved = json.load(f)
        figure({k: (v["rows"], v["rounds"]) for k, v in saved.items()}, a.figure)
        return
    results = {}
    for name in a.only.split(","):
        if name not in CASES:
            sys.exit(f"unknown case {name!r}; expected some of {','.join(CASES)}")
        results[name] = case(a.exe, name, CASES[name], a.out, a.threads)
    print("| case | training | snapshots | mean primal | max primal | mean dual | max dual | offline wall time (s) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name, (rows, _) in results.items():
        for x in rows:
            print(f"| {name} | {x['kind']} | {x['snapshots']} | {x['mean_primal_error']:.2e} | "
                  f"{x['max_primal_error']:.2e} | {x['mean_dual_error']:.2e} | {x['max_dual_error']:.2e} | "
                  f"{x['wall_time_s']:.2f} |")
    with open(os.path.join(a.out, "adaptive_experiment.json"), "w") as f:
        json.dump({k: dict(rows=v[0], rounds=v[1]) for k, v in results.items()}, f, indent=1)
    figure(results, a.figure)


if __name__ == "__main__":
    main()
