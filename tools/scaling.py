#!/usr/bin/python3
"""Scaling study with the contactrom CLI: cost against mesh size and against MPI ranks.

    tools/scaling.py [--exe PATH] [--mpirun PATH] [--out RESULTS_DIR] [--figures DIR]
                     [--only fom,bench,mpi] [--quick]

Stages (each command is printed as it runs; all of them are listed in RESULTS_DIR/scaling.md):

  fom    `/usr/bin/time -v contactrom fom --problem P --param V --refine k --json`:
         hertz d = 0.1, refine 0..4, and ironing d_x = 2, refine 0..2; dofs, FOM setup
         (factorisation + condensation), one cold query, peak resident memory, contact
         force.
  bench  `contactrom bench --problem hertz --refine k --ipopt-queries 1 --json`, k = 0, 1, 2:
         the median time per query of the FOM (factorisation reused) and of every ROM,
         all measured in the same run, and their ratios.
  mpi    `contactrom offline --problem hertz --refine 2 --train 32 --threads 1` serially
         and under `mpirun --oversubscribe --allow-run-as-root -np N` for N = 1, 2, 4:
         wall time, and every database compared bitwise with the serial one.

Outputs: RESULTS_DIR (default results/scaling, git-ignored) gets scaling.json (every
measurement), scaling.md (the tables, with the commands) and the databases; the PNG
figures scaling_mesh.png, scaling_bench.png and scaling_ranks.png go to --figures
(default docs/figures; RESULTS_DIR/figures with --quick, so a smoke run never
overwrites the committed figures); `--only ""` runs no stage and redraws the figures and
tables from RESULTS_DIR/scaling.json. --quick (≈ 1 min): hertz refine 0..2 and ironing
refine 0..1 for fom, refine 0..1 for bench, refine 1 for mpi.

Use /usr/bin/python3 (numpy, h5py, matplotlib from Debian).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DPI = 100
# The datasets that must be bit-identical between a serial and an MPI run.
SNAPSHOT_DATASETS = ["parameters", "primal", "dual", "status", "iterations", "pairing_iterations"]
# bench keys plotted against dofs, with their labels.
BENCH_METHODS = [
    ("fom_active_set", "FOM (factorisation reused)"),
    ("rom_greedy", "greedy"),
    ("rom_greedy_nested", "greedy-nested"),
    ("rom_greedy_init_empty", "greedy, init=empty (paper)"),
    ("rom_cpg", "CPG (cold)"),
    ("rom_cpg_warm", "CPG (warm)"),
    ("rom_full_dictionary", "full dictionary"),
    ("rom_convex_hull", "convex hull"),
]
T0 = time.time()


def log(msg):
    print(f"[{time.time() - T0:7.1f} s] {msg}", flush=True)


def run(cmd, env=None):
    """Runs `cmd` (a list); returns (stdout, stderr, wall seconds). Exits on failure."""
    log("$ " + " ".join(cmd))
    t = time.time()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.time() - t
    if proc.returncode != 0:
        sys.exit(f"scaling.py: command failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr}")
    return proc.stdout, proc.stderr, wall


def peak_memory_mb(time_v_stderr):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", time_v_stderr)
    return int(m.group(1)) / 1024.0 if m else float("nan")


def display(cmd):
    """A command as a user types it: programs by their name, databases without their folder."""
    return " ".join(os.path.basename(c) if c.endswith(("/contactrom", "/mpirun", ".h5")) else c for c in cmd)


def stage_fom(exe, cases):
    rows = []
    for problem, param, refines in cases:
        for k in refines:
            cmd = ["/usr/bin/time", "-v", exe, "fom", "--problem", problem, "--param", param, "--refine", str(k),
                   "--json"]
            out, err, wall = run(cmd)
            j = json.loads(out)
            rows.append({"problem": problem, "param": param, "refine": k, "dofs": j["dofs"],
                         "constraints": j["constraints"], "setup_s": j["setup_time_s"], "query_s": j["time_s"],
                         "peak_mb": peak_memory_mb(err), "process_s": wall, "contact_force": j["contact_force"],
                         "stationarity": j["kkt"]["stationarity"], "command": display(cmd[2:])})
            log(f"  {problem} refine {k}: {j['dofs']} dofs, setup {j['setup_time_s']:.3g} s, "
                f"query {1e3 * j['time_s']:.3g} ms, {rows[-1]['peak_mb']:.0f} MB")
    return rows


def stage_bench(exe, refines, dofs_of):
    rows = []
    for k in refines:
        cmd = [exe, "bench", "--problem", "hertz", "--refine", str(k), "--ipopt-queries", "1", "--json"]
        out, _, _ = run(cmd)
        j = json.loads(out)
        row = {"refine": k, "dofs": j.get("dofs", dofs_of.get(k)), "command": display(cmd)}
        row.update({key: j[key] for key, _ in BENCH_METHODS if key in j})
        row["fom_ipopt"] = j.get("fom_ipopt")
        rows.append(row)
        log(f"  refine {k}: FOM {1e3 * j['fom_active_set']:.3g} ms, greedy {1e6 * j['rom_greedy']:.3g} us, "
            f"ratio {j['fom_active_set'] / j['rom_greedy']:.0f}")
    return rows


def same_snapshots(a, b):
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        return all(fa[name][()].tobytes() == fb[name][()].tobytes() for name in SNAPSHOT_DATASETS)


def stage_mpi(exe, mpirun, refine, train, out_dir):
    db_dir = os.path.join(out_dir, "db")
    os.makedirs(db_dir, exist_ok=True)
    args = ["offline", "--problem", "hertz", "--refine", str(refine), "--train", str(train), "--threads", "1", "--json"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    serial = os.path.join(db_dir, "serial.h5")
    cmd = [exe] + args + ["--out", serial]
    out, _, wall = run(cmd)
    j = json.loads(out)
    rows = [{"ranks": "serial", "wall_s": wall, "offline_s": j["wall_time_s"], "setup_s": j["setup_time_s"],
             "identical": True, "command": display(cmd)}]
    for n in [1, 2, 4]:
        path = os.path.join(db_dir, f"mpi{n}.h5")
        cmd = [mpirun, "--oversubscribe", "--allow-run-as-root", "-np", str(n), exe] + args + ["--out", path]
        out, _, wall = run(cmd, env)
        j = json.loads(out)
        rows.append({"ranks": n, "wall_s": wall, "offline_s": j["wall_time_s"], "setup_s": j["setup_time_s"],
                     "identical": same_snapshots(serial, path), "command": display(cmd)})
        log(f"  {n} ranks: {wall:.2f} s, bit-identical {rows[-1]['identical']}")
    return rows


def plot_mesh(fom_rows, path):
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 4.2))
    for problem, marker in [("hertz", "o"), ("ironing", "s")]:
        rows = [r for r in fom_rows if r["problem"] == problem]
        if not rows:
            continue
        dofs = [r["dofs"] for r in rows]
        ax_t.loglog(dofs, [r["setup_s"] for r in rows], marker + "-", label=f"{problem}: setup")
        ax_t.loglog(dofs, [r["query_s"] for r in rows], marker + "--", label=f"{problem}: one query")
        ax_m.loglog(dofs, [r["peak_mb"] for r in rows], marker + "-", label=problem)
    ax_t.set(xlabel="degrees of freedom", ylabel="time (s)", title="FOM setup and one cold query")
    ax_m.set(xlabel="degrees of freedom", ylabel="peak resident memory (MB)", title="FOM peak memory (one solve)")
    for ax in (ax_t, ax_m):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def plot_bench(bench_rows, path):
    fig, ax = plt.subplots(figsize=(9, 4.5))
    dofs = [r["dofs"] for r in bench_rows]
    for key, label in BENCH_METHODS:
        if all(key in r for r in bench_rows):
            style = "k-o" if key == "fom_active_set" else "-o"
            ax.loglog(dofs, [r[key] for r in bench_rows], style, label=label, markersize=4)
    for i, r in enumerate(bench_rows):  # the first label right of its point, the others left
        ax.annotate(f"FOM/greedy {r['fom_active_set'] / r['rom_greedy']:.0f}×", (r["dofs"], r["fom_active_set"]),
                    textcoords="offset points", xytext=(4 if i == 0 else -4, 8), ha="left" if i == 0 else "right",
                    fontsize=8)
    ax.set(xlabel="degrees of freedom (hertz, refine 0, 1, 2)", ylabel="median time per query (s)",
           title="hertz 30 snapshots, δ = 1e-8: time per query against mesh size")
    ax.set_xticks(dofs)  # one tick per mesh: the log axis alone would label only 10^4
    ax.set_xticklabels([f"{d:,}" for d in dofs])
    ax.minorticks_off()
    ax.grid(True, which="major", alpha=0.3)
    ax.margins(y=0.15)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def plot_ranks(mpi_rows, path):
    rows = [r for r in mpi_rows if r["ranks"] != "serial"]
    ranks = [r["ranks"] for r in rows]
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot(ranks, [r["wall_s"] for r in rows], "o-", label="mpirun wall time")
    ax.plot(ranks, [r["offline_s"] for r in rows], "s-", label="offline stage (rank 0)")
    ax.plot(ranks, [rows[0]["offline_s"] / n for n in ranks], "k:", label="ideal 1/N")
    cores = os.cpu_count() or 1
    ax.axvline(cores, color="gray", alpha=0.4, label=f"cores of the machine ({cores})")
    ax.set(xlabel="MPI ranks", ylabel="time (s)", xticks=ranks,
           title="offline hertz refine 2, 32 snapshots")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def table(header, rows, commands):
    """A markdown table (header cells, rows of cells) followed by its commands."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return lines + ["", "Commands: " + "; ".join(f"`{c}`" for c in commands), ""]


def markdown(results):
    lines = []
    if results.get("fom"):
        lines += table(["problem", "refine", "dofs", "contact rows", "setup", "one query", "peak memory", "contact force"],
                       [[r["problem"], str(r["refine"]), f"{r['dofs']:,}", str(r["constraints"]), f"{r['setup_s']:.3g} s",
                         f"{1e3 * r['query_s']:.3g} ms", f"{r['peak_mb']:.0f} MB", f"{r['contact_force']:.7g}"]
                        for r in results["fom"]],
                       ["/usr/bin/time -v " + r["command"] for r in results["fom"]])
    if results.get("bench"):
        keys = [(k, lab) for k, lab in BENCH_METHODS if all(k in r for r in results["bench"])]
        lines += table(["refine", "dofs"] + [lab for _, lab in keys] + ["FOM/greedy"],
                       [[str(r["refine"]), f"{r['dofs']:,}"] +
                        [f"{1e3 * r[k]:.3g} ms" if k == "fom_active_set" else f"{1e6 * r[k]:.3g} µs" for k, _ in keys] +
                        [f"{r['fom_active_set'] / r['rom_greedy']:.0f}×"] for r in results["bench"]],
                       [r["command"] for r in results["bench"]])
    if results.get("mpi"):
        lines += table(["ranks", "wall time", "offline stage", "rank 0's setup", "bit-identical to serial"],
                       [[str(r["ranks"]), f"{r['wall_s']:.2f} s", f"{r['offline_s']:.2f} s", f"{r['setup_s']:.2f} s",
                         "yes" if r["identical"] else "NO"] for r in results["mpi"]],
                       [r["command"] for r in results["mpi"]])
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--exe", default=os.path.join(REPO, "build", "tools", "contactrom"))
    ap.add_argument("--mpirun", default=shutil.which("mpirun") or "mpirun")
    ap.add_argument("--out", default=os.path.join(REPO, "results", "scaling"))
    ap.add_argument("--figures", default=None)
    ap.add_argument("--only", default="fom,bench,mpi")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    stages = set(a.only.split(","))
    figures = a.figures or (os.path.join(a.out, "figures") if a.quick else os.path.join(REPO, "docs", "figures"))
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(figures, exist_ok=True)
    exe = os.path.abspath(a.exe)
    results_path = os.path.join(a.out, "scaling.json")
    results = json.load(open(results_path)) if os.path.exists(results_path) else {}

    if "fom" in stages:
        hertz = range(3) if a.quick else range(5)
        ironing = range(2) if a.quick else range(3)
        results["fom"] = stage_fom(exe, [("hertz", "0.1", hertz), ("ironing", "2", ironing)])
    if "bench" in stages:
        dofs_of = {r["refine"]: r["dofs"] for r in results.get("fom", []) if r["problem"] == "hertz"}
        results["bench"] = stage_bench(exe, range(2) if a.quick else range(3), dofs_of)
    if "mpi" in stages:
        results["mpi"] = stage_mpi(exe, a.mpirun, 1 if a.quick else 2, 32, a.out)

    with open(results_path, "w") as f:
        json.dump(results, f, indent=1)
    with open(os.path.join(a.out, "scaling.md"), "w") as f:
        f.write(markdown(results) + "\n")
    if results.get("fom"):
        plot_mesh(results["fom"], os.path.join(figures, "scaling_mesh.png"))
    if results.get("bench"):
        plot_bench(results["bench"], os.path.join(figures, "scaling_bench.png"))
    if results.get("mpi"):
        plot_ranks(results["mpi"], os.path.join(figures, "scaling_ranks.png"))
    log(f"tables in {os.path.join(a.out, 'scaling.md')}, figures in {figures}")


if __name__ == "__main__":
    main()
