#!/usr/bin/python3
"""Regenerate the greedy active-set studies of the paper with the contactrom CLI.

    tools/experiments.py [--exe PATH] [--out RESULTS_DIR] [--figures DIR] [--quick]
                         [--only hertz|ironing|ironing2[,...]] [--threads T] [--replot]

Stages (each builds every snapshot database once and reuses it for all δ):

  hertz     training sizes 12/30/60/120 x δ ∈ {1e-6, 1e-8, 1e-10}, validation set of
            119 midpoints: summary table; mean errors + primal rank, iterations,
            time, time/iteration vs training size; per-parameter error curves;
            dual sparsity pattern (30 snapshots, δ=1e-8); dictionary spy pattern
            (30 snapshots); reconstruction examples d = 0.14, 0.26 (12 snapshots).
  ironing   nested levels 3..7 x δ: summary table, the same evolution figure vs
            level, dual sparsity pattern (level 5, δ=1e-8).
  ironing2  nested levels 2..5 x δ: summary table.
  (always)  comparison table: greedy vs cpg and full-dictionary (the methods the
            CLI registers) on hertz 30 and ironing level 7, when those were run.

Outputs: RESULTS_DIR (default results/, git-ignored) gets the databases (db/),
one CSV per (problem, training set, δ) with the per-parameter rows of
`contactrom online --validation`, <problem>_summary.csv, comparison.csv,
timings.csv and summary.md (markdown tables); the PNG figures go to --figures
(default docs/figures, or RESULTS_DIR/figures with --quick so that a smoke run
never overwrites the committed figures).

--replot runs nothing and redraws the hertz and ironing figures (all but the
reconstructions, which need the CLI) from the results of an earlier run in RESULTS_DIR.

--quick is a smoke mode (≈ 25 s on 2 busy cores; the full run ≈ 3 min): hertz
12/30, ironing levels 3/4, ironing2 level 2, δ = 1e-8 only; every code path
(tables, all figures) runs. Nothing is added to ctest.

Use /usr/bin/python3 (numpy, h5py, matplotlib from Debian).
"""
import argparse
import csv
import json
import os
import platform
import shutil
import subprocess
import sys
import time

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter  # noqa: E402
import numpy as np  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DELTAS = [1e-6, 1e-8, 1e-10]
DPI = 100
DELTA_COLORS = {1e-6: "tab:blue", 1e-8: "tab:orange", 1e-10: "tab:green"}
T0 = time.time()


def log(msg):
    print(f"[{time.time() - T0:7.1f} s] {msg}", flush=True)


def dtag(delta):
    return f"{delta:.0e}".replace("e-0", "e-")


def fmt(x, digits=2):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "–"
    if x == 0:
        return "0"
    return f"{x:.{digits}e}"


class Runner:
    """Runs the contactrom CLI; every call must print one JSON object."""

    def __init__(self, exe, threads):
        self.exe = exe
        self.threads = threads

    def run(self, *args):
        cmd = [self.exe, *map(str, args), "--json"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"command failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr.strip()}")
        lines = [l for l in proc.stdout.splitlines() if l.strip().startswith("{")]
        if not lines:
            raise RuntimeError(f"no JSON from: {' '.join(cmd)}\n{proc.stdout}")
        return json.loads(lines[-1])

    def offline(self, problem, kind, n, db):
        flag = "--train" if kind == "train" else "--level"
        return self.run("offline", "--problem", problem, flag, n, "--out", db, "--threads", self.threads)

    def validation(self, db, delta, out_csv, method="greedy"):
        # The method's own time: the error estimate of each answer (on by default in
        # `online`) is a separate feature, measured by `bench` (rom_greedy_with_estimate).
        return self.run("online", "--db", db, "--method", method, "--delta", f"{delta:g}", "--validation",
                        "--option", "estimate=false", "--out", out_csv, "--threads", self.threads)

    def single(self, db, delta, param, out_dir):
        return self.run("online", "--db", db, "--method", "greedy", "--delta", f"{delta:g}", "--param", param,
                        "--out", out_dir)

    def fom(self, problem, param, out_dir):
        return self.run("fom", "--problem", problem, "--param", param, "--out", out_dir)


def read_rows(path):
    """Per-parameter rows of `online --validation --out FILE.csv`."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        sel = r.get("selected", "").split()
        out.append({
            "params": [float(r[k]) for k in r if k not in {"primal_error", "dual_error", "sparsity", "iterations",
                                                           "time_s", "converged", "status", "selected", "errors",
                                                           "penetration", "separation"}],
            "primal": float(r["primal_error"]),
            "dual": float(r["dual_error"]),
            "sparsity": int(r["sparsity"]),
            "iterations": int(r["iterations"]),
            "time": float(r["time_s"]),
            "converged": r["converged"] == "1" and r["status"] in ("success", "inaccurate"),
            "status": r["status"],
            "selected": [int(s) for s in sel],
        })
    return out


def summarize(rows, summary):
    it = np.array([r["iterations"] for r in rows], float)
    t = np.array([r["time"] for r in rows], float)
    return {
        "primal_rank": summary["primal_rank"],
        "dictionary_size": summary["dictionary_size"],
        "validation_size": len(rows),
        "mean_primal_error": float(np.mean([r["primal"] for r in rows])),
        "max_primal_error": float(np.max([r["primal"] for r in rows])),
        "mean_dual_error": float(np.mean([r["dual"] for r in rows])),
        "max_dual_error": float(np.max([r["dual"] for r in rows])),
        "mean_sparsity": float(np.mean([r["sparsity"] for r in rows])),
        "mean_iterations": float(np.mean(it)),
        "mean_time_s": float(np.mean(t)),
        "median_time_s": float(np.median(t)),
        # mean over the queries of time/iterations (queries with 0 iterations left out)
        "mean_time_per_iteration_s": float(np.mean(t[it > 0] / it[it > 0])) if np.any(it > 0) else float("nan"),
        "median_time_per_iteration_s": float(np.median(t[it > 0] / it[it > 0])) if np.any(it > 0) else float("nan"),
        "nonconverged": int(sum(not r["converged"] for r in rows)),
        "inaccurate": int(sum(r["status"] == "inaccurate" for r in rows)),
        "statuses": ",".join(sorted({r["status"] for r in rows if not r["converged"]})),
    }


SUMMARY_COLUMNS = ["problem", "kind", "n", "snapshots", "delta", "primal_rank", "validation_size",
                   "mean_primal_error", "max_primal_error", "mean_dual_error", "max_dual_error", "mean_sparsity",
                   "mean_iterations", "mean_time_s", "median_time_s", "mean_time_per_iteration_s", "median_time_per_iteration_s", "nonconverged",
                   "inaccurate", "statuses", "offline_wall_s", "mean_fom_time_s"]


def write_summary_csv(path, records):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in records:
            w.writerow(r)


def markdown_summary(records, label):
    """One markdown table: one line per (training set, δ)."""
    head = (f"| {label} | snapshots | δ | primal rank | mean primal H¹ error | mean dual L² error | mean sparsity "
            "| mean iterations | mean time (µs) | median time (µs) | time/iteration mean / median (µs) | not converged "
            "| inaccurate |\n"
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n")
    lines = []
    for r in records:
        nc = f"{r['nonconverged']}/{r['validation_size']}"
        if r["nonconverged"] and r["statuses"]:
            nc += f" ({r['statuses']})"
        lines.append(f"| {r['n']} | {r['snapshots']} | {r['delta']:.0e} | {r['primal_rank']} | "
                     f"{fmt(r['mean_primal_error'])} | {fmt(r['mean_dual_error'])} | {r['mean_sparsity']:.2f} | "
                     f"{r['mean_iterations']:.1f} | {1e6 * r['mean_time_s']:.0f} | {1e6 * r['median_time_s']:.0f} | "
                     f"{1e6 * r['mean_time_per_iteration_s']:.0f} / {1e6 * r['median_time_per_iteration_s']:.0f} | {nc} | "
                     f"{r.get('inaccurate', 0)} |")
    return head + "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- studies


def run_study(runner, outdir, problem, kind, ns, deltas, timings):
    """Builds one database per n and evaluates every δ on its validation set.

    Returns (records, rows, dbs): records = summary dicts, rows[(n, δ)] = per-parameter
    rows, dbs[n] = database path."""
    os.makedirs(os.path.join(outdir, "db"), exist_ok=True)
    os.makedirs(os.path.join(outdir, problem), exist_ok=True)
    records, rows, dbs = [], {}, {}
    for n in ns:
        db = os.path.join(outdir, "db", f"{problem}_{kind}{n}.h5")
        t = time.time()
        off = runner.offline(problem, kind, n, db)
        timings.append((f"{problem} offline {kind} {n}", time.time() - t))
        log(f"{problem} {kind} {n}: {off['snapshots']} snapshots in {off['wall_time_s']:.2f} s "
            f"(mean FOM {1e3 * off['mean_fom_time_s']:.2f} ms, {off['failed']} failed)")
        dbs[n] = db
        for delta in deltas:
            path = os.path.join(outdir, problem, f"{kind}{n}_delta{dtag(delta)}.csv")
            t = time.time()
            js = runner.validation(db, delta, path)
            timings.append((f"{problem} online {kind} {n} δ={dtag(delta)}", time.time() - t))
            rws = read_rows(path)
            rows[(n, delta)] = rws
            rec = {"problem": problem, "kind": kind, "n": n, "snapshots": off["snapshots"], "delta": delta,
                   "offline_wall_s": off["wall_time_s"], "mean_fom_time_s": off["mean_fom_time_s"]}
            rec.update(summarize(rws, js))
            records.append(rec)
            log(f"  δ={delta:.0e}: rank {rec['primal_rank']}, primal {fmt(rec['mean_primal_error'])}, "
                f"dual {fmt(rec['mean_dual_error'])}, {rec['mean_iterations']:.1f} it, "
                f"{1e6 * rec['mean_time_s']:.0f} µs mean / {1e6 * rec['median_time_s']:.0f} µs median, "
                f"{rec['nonconverged']}/{rec['validation_size']} not converged ({time.time() - t:.1f} s)")
    write_summary_csv(os.path.join(outdir, f"{problem}_summary.csv"), records)
    return records, rows, dbs


# ----------------------------------------------------------------------------- figures


def save_figure(fig, path):
    """Lays out `fig`, writes it to `path` (PNG, DPI) and releases it."""
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def evolution_figure(records, deltas, xlabel, path, n_contact, title, fom_time=None):
    """Six small panels against the number of snapshots (log axis), one line per δ:
    (a) mean primal error, (b) mean dual error, (c) primal rank, (d) mean iterations,
    (e) time per query (median solid, mean dotted: a query slowed by another job moves
    the mean only; the FOM solve as a reference line), (f) time per iteration, the same.
    A grey line marks as many snapshots as contact dofs."""
    ns = sorted({r["n"] for r in records})
    get = {(r["n"], r["delta"]): r for r in records}
    snaps = [get[(n, deltas[0])]["snapshots"] for n in ns]
    panels = [("mean_primal_error", 1.0, None, "(a) mean primal error", "relative H¹ error", True),
              ("mean_dual_error", 1.0, None, "(b) mean dual error", "relative L² error", True),
              ("primal_rank", 1.0, None, "(c) primal rank", "POD modes", False),
              ("mean_iterations", 1.0, None, "(d) iterations per query", "mean iterations", False),
              ("median_time_s", 1e6, "mean_time_s", "(e) time per query", "time (µs)", True),
              ("median_time_per_iteration_s", 1e6, "mean_time_per_iteration_s", "(f) time per iteration",
               "time (µs)", True)]
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.4))
    for a, (key, scale, key2, ttl, ylabel, logy) in zip(axes.flat, panels):
        for delta in deltas:
            c = DELTA_COLORS.get(delta)
            a.plot(snaps, [scale * get[(n, delta)][key] for n in ns], "o-", color=c)
            if key2:
                a.plot(snaps, [scale * get[(n, delta)][key2] for n in ns], "s:", color=c, ms=3)
        if key == "median_time_s" and fom_time:
            a.axhline(1e6 * fom_time, color="k", ls="--", lw=1.2)
        if n_contact <= max(snaps):
            a.axvline(n_contact, color="0.6", ls="-.", lw=1)
        a.set_xscale("log")
        a.set_xticks(snaps)
        a.set_xticklabels([f"{s}\n(L{n})" if "level" in xlabel else str(s) for n, s in zip(ns, snaps)])
        a.minorticks_off()
        if logy:
            a.set_yscale("log")
            # Label 1, 2, 5 × 10^k: errors and times span few decades, and a single
            # power of ten would leave an axis with one tick.
            a.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            a.yaxis.set_major_formatter(FormatStrFormatter("%g"))
            a.yaxis.set_minor_formatter(NullFormatter())
        else:
            a.set_ylim(bottom=0)
        a.set_title(ttl, fontsize=10)
        a.set_ylabel(ylabel)
        a.grid(alpha=0.3)
    for a in axes[1]:
        a.set_xlabel(xlabel)
    handles = [Line2D([], [], color=DELTA_COLORS.get(d), marker="o", label=f"δ = {d:.0e}") for d in deltas]
    handles.append(Line2D([], [], color="0.3", ls="-", label="mean (a–d), median (e, f)"))
    handles.append(Line2D([], [], color="0.3", marker="s", ms=3, ls=":", label="mean (e, f)"))
    if fom_time:
        handles.append(Line2D([], [], color="k", ls="--", label=f"FOM solve, offline-stage mean ({1e6 * fom_time:.0f} µs)"))
    if n_contact <= max(snaps):
        handles.append(Line2D([], [], color="0.6", ls="-.", label=f"snapshots = contact dofs ({n_contact})"))
    fig.suptitle(f"{title}: the greedy ROM's errors, rank, iterations and times against the number of training snapshots",
                 fontsize=11)
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def error_curves_figure(rows, ns, deltas, path):
    """Per-parameter errors over the validation set: one row of subplots per δ
    (primal left, dual right), one curve per training size, × where not converged."""
    fig, axes = plt.subplots(len(deltas), 2, figsize=(9, 2.5 * len(deltas) + 0.5), squeeze=False, sharex=True)
    colors = plt.cm.viridis(np.linspace(0, 0.85, len(ns)))
    any_bad = False
    for i, delta in enumerate(deltas):
        for j, (key, name, unit) in enumerate([("primal", "primal error", "relative H¹ error"),
                                               ("dual", "dual error", "relative L² error")]):
            a = axes[i, j]
            for n, c in zip(ns, colors):
                rw = rows[(n, delta)]
                d = np.array([r["params"][0] for r in rw])
                e = np.array([r[key] for r in rw])
                a.semilogy(d, e, "-", color=c, lw=1)
                bad = np.array([not r["converged"] for r in rw])
                if bad.any():
                    any_bad = True
                    a.semilogy(d[bad], e[bad], "x", color=c, ms=7, mew=1.5)
            a.set_title(f"{name}, δ = {delta:.0e}", fontsize=9)
            a.set_ylabel(unit, fontsize=8)
            a.grid(alpha=0.3)
            if i == len(deltas) - 1:
                a.set_xlabel("prescribed displacement d (cylinder radii)")
    handles = [Line2D([], [], color=c, lw=1, label=f"{n} snapshots") for n, c in zip(ns, colors)]
    if any_bad:
        handles.append(Line2D([], [], color="k", marker="x", ls="", ms=7, mew=1.5, label="not converged"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def sparsity_figure(rw, db, path, title, param_name):
    """Rows = validation parameters, dots at the selected dictionary columns."""
    with h5py.File(db, "r") as f:
        params = np.array(f["parameters"])
    nsnap = params.shape[0]
    fig, a = plt.subplots(figsize=(5.5, 5))
    for i, r in enumerate(rw):
        if r["selected"]:
            a.plot(r["selected"], [i] * len(r["selected"]), "k.", ms=3 if len(rw) < 150 else 2)
    a.set_xlim(-0.5, nsnap - 0.5)
    a.set_ylim(len(rw) - 0.5, -0.5)
    a.set_xlabel(f"selected dictionary column (snapshot index, in increasing {param_name})")
    a.set_ylabel(f"validation query ({len(rw)}, in increasing {param_name})")
    a.set_title(title, fontsize=9)
    a.grid(alpha=0.2)
    save_figure(fig, path)


def spy_figure(db, path, title):
    with h5py.File(db, "r") as f:
        dual = np.array(f["dual"])  # n_snap x n_c
    fig, a = plt.subplots(figsize=(4, 5.5))
    a.spy(dual.T, markersize=2.5, aspect="auto", precision=0.0)
    a.set_xlabel(f"dictionary column\n(snapshot index of {dual.shape[0]}, in increasing d)")
    a.set_ylabel(f"contact dof (slave node index, {dual.shape[1]})")
    a.xaxis.set_ticks_position("bottom")
    a.xaxis.set_label_position("bottom")
    a.set_title(title, fontsize=9)
    save_figure(fig, path)


def read_surface(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return data["x"], data["pressure"]


def reconstruction_figure(examples, db, path):
    """FOM vs ROM pressure and the selected dictionary columns times their coefficients."""
    with h5py.File(db, "r") as f:
        dual = np.array(f["dual"])
        params = np.array(f["parameters"])[:, 0]
    fig, axes = plt.subplots(1, len(examples), figsize=(5 * len(examples), 3.8), squeeze=False)
    for a, ex in zip(axes[0], examples):
        x, pf = ex["fom_x"], ex["fom_p"]
        order = np.argsort(x)
        xr, pr = ex["rom_x"], ex["rom_p"]
        a.plot(x[order], pf[order], "k-", lw=2, label="FOM")
        a.plot(xr[np.argsort(xr)], pr[np.argsort(xr)], "r--", lw=1.5, label="ROM (greedy)")
        coef = ex["json"].get("coefficients")
        for k, s in enumerate(ex["json"]["selected"]):
            col = dual[s]
            if coef is not None and len(coef) == len(ex["json"]["selected"]):
                col, lab = coef[k] * col, f"{coef[k]:.3f} × snapshot {s} (d={params[s]:.3f})"
            else:
                col, lab = col / max(np.abs(col).max(), 1e-300) * pr.max(), f"snapshot {s} (normalised)"
            a.plot(x[order], col[order], ":", lw=1.3, marker=".", ms=3, label=lab)
        support = np.abs(pf) + np.abs(pr) > 0
        if support.any():
            lo, hi = x[support].min(), x[support].max()
            pad = 0.3 * (hi - lo) + 0.02
            a.set_xlim(lo - pad, hi + pad)
        a.set_xlabel("x of the slave surface node (cylinder radii)")
        a.set_ylabel("contact pressure λ (units of E)")
        js = ex["json"]
        a.set_title(f"d = {ex['param']}, {js['dictionary_size']} snapshots, δ={js['delta']:.0e}\n"
                    f"dual error {js['dual_error']:.1e}, primal error {js['primal_error']:.1e}, "
                    f"{js['iterations']} it.", fontsize=9)
        a.legend(fontsize=7)
        a.grid(alpha=0.3)
    save_figure(fig, path)


# ----------------------------------------------------------------------------- stages


def contact_dofs(db):
    with h5py.File(db, "r") as f:
        return f["dual"].shape[1]


def hertz_figures(cfg, records, rows, dbs):
    """The Hertz figures drawn from the study's results (all but the reconstructions)."""
    sizes, deltas, fig = sorted(dbs), sorted({r["delta"] for r in records}, reverse=True), cfg["figures"]
    fom_time = float(np.mean([r["mean_fom_time_s"] for r in records]))
    evolution_figure(records, deltas, "training snapshots", os.path.join(fig, "hertz_evolution.png"),
                     contact_dofs(dbs[sizes[0]]), "Hertz", fom_time)
    error_curves_figure(rows, sizes, deltas, os.path.join(fig, "hertz_error_curves.png"))
    n_sp = 30 if 30 in sizes else sizes[0]
    d_sp = 1e-8 if 1e-8 in deltas else deltas[0]
    sparsity_figure(rows[(n_sp, d_sp)], dbs[n_sp], os.path.join(fig, "hertz_sparsity_train30.png"),
                    f"Hertz: snapshots selected by the greedy, {n_sp} snapshots, δ = {d_sp:.0e}", "d")
    spy_figure(dbs[n_sp], os.path.join(fig, "hertz_dictionary_spy.png"), f"Hertz dual dictionary, {n_sp} snapshots")


def ironing_figures(cfg, records, rows, dbs):
    """The ironing figures drawn from the study's results."""
    levels, deltas, fig = sorted(dbs), sorted({r["delta"] for r in records}, reverse=True), cfg["figures"]
    fom_time = float(np.mean([r["mean_fom_time_s"] for r in records]))
    evolution_figure(records, deltas, "training snapshots (nested level L)", os.path.join(fig, "ironing_evolution.png"),
                     contact_dofs(dbs[levels[0]]), "Ironing", fom_time)
    lv = 5 if 5 in levels else levels[-1]
    d_sp = 1e-8 if 1e-8 in deltas else deltas[0]
    sparsity_figure(rows[(lv, d_sp)], dbs[lv], os.path.join(fig, "ironing_sparsity_level5.png"),
                    f"Ironing: snapshots selected by the greedy, level {lv}, δ = {d_sp:.0e}", "d_x")


def load_study(outdir, problem, kind):
    """The records, rows and databases a run of `run_study` left in `outdir` (for --replot)."""
    path = os.path.join(outdir, f"{problem}_summary.csv")
    if not os.path.exists(path):
        sys.exit(f"experiments.py --replot: {path} is missing; run the {problem} stage first")
    integers = {"n", "snapshots", "primal_rank", "validation_size", "nonconverged", "inaccurate"}
    with open(path, newline="") as f:
        records = [{k: (v if k in {"problem", "kind", "statuses"} else int(v) if k in integers else float(v))
                    for k, v in r.items()} for r in csv.DictReader(f)]
    rows = {(r["n"], r["delta"]): read_rows(os.path.join(outdir, problem, f"{kind}{r['n']}_delta{dtag(r['delta'])}.csv"))
            for r in records}
    dbs = {r["n"]: os.path.join(outdir, "db", f"{problem}_{kind}{r['n']}.h5") for r in records}
    return records, rows, dbs


def stage_hertz(runner, cfg, timings, md):
    sizes, deltas = cfg["hertz_sizes"], cfg["deltas"]
    records, rows, dbs = run_study(runner, cfg["out"], "hertz", "train", sizes, deltas, timings)
    t = time.time()
    fig = cfg["figures"]
    hertz_figures(cfg, records, rows, dbs)
    # Reconstruction examples, 12 snapshots, as in the paper.
    n_rec = 12 if 12 in sizes else sizes[0]
    d_rec = 1e-10 if 1e-10 in deltas else deltas[-1]
    examples = []
    for p in ["0.14", "0.26"]:
        rdir = os.path.join(cfg["out"], "hertz", f"reconstruction_d{p}")
        js = runner.single(dbs[n_rec], d_rec, p, os.path.join(rdir, "rom"))
        runner.fom("hertz", p, os.path.join(rdir, "fom"))
        fx, fp = read_surface(os.path.join(rdir, "fom", "hertz_surface.csv"))
        rx, rp = read_surface(os.path.join(rdir, "rom", "hertz_greedy_surface.csv"))
        examples.append({"param": p, "json": js, "fom_x": fx, "fom_p": fp, "rom_x": rx, "rom_p": rp})
        log(f"  reconstruction d={p}: selected {js['selected']} coefficients "
            f"{[round(c, 4) for c in js.get('coefficients', [])]}, dual error {js['dual_error']:.2e}")
    reconstruction_figure(examples, dbs[n_rec], os.path.join(fig, "hertz_reconstruction.png"))
    timings.append(("hertz figures + reconstructions", time.time() - t))

    md.append("### Hertz (training sizes " + "/".join(map(str, sizes)) + ")\n\n"
              + markdown_summary(records, "train") + "\n")
    md.append("Reconstruction examples (12 snapshots, δ=%.0e):\n\n" % d_rec +
              "| d | selected snapshots | coefficients | dual error | primal error | iterations |\n"
              "|---:|---|---|---:|---:|---:|\n" +
              "".join(f"| {e['param']} | {e['json']['selected']} | "
                      f"{[round(c, 4) for c in e['json'].get('coefficients', [])]} | {e['json']['dual_error']:.2e} | "
                      f"{e['json']['primal_error']:.2e} | {e['json']['iterations']} |\n" for e in examples) + "\n")
    return records, dbs


def stage_ironing(runner, cfg, timings, md):
    levels, deltas = cfg["ironing_levels"], cfg["deltas"]
    records, rows, dbs = run_study(runner, cfg["out"], "ironing", "level", levels, deltas, timings)
    t = time.time()
    ironing_figures(cfg, records, rows, dbs)
    timings.append(("ironing figures", time.time() - t))
    md.append("### Ironing (nested levels " + "/".join(map(str, levels)) + ")\n\n"
              + markdown_summary(records, "level") + "\n")
    return records, dbs


def stage_ironing2(runner, cfg, timings, md):
    levels, deltas = cfg["ironing2_levels"], cfg["deltas"]
    records, _, dbs = run_study(runner, cfg["out"], "ironing2", "level", levels, deltas, timings)
    md.append("### Two-parameter ironing (nested levels " + "/".join(map(str, levels)) + ")\n\n"
              + markdown_summary(records, "level") + "\n")
    return records, dbs


def stage_comparison(runner, cfg, dbs, timings, md):
    """The paper's comparison table: greedy vs the non-sparse methods, if the CLI has them."""
    t = time.time()
    rows = []
    cases = []
    if "hertz" in dbs and 30 in dbs["hertz"]:
        cases.append(("hertz", "train 30", dbs["hertz"][30]))
    if "ironing" in dbs and 7 in dbs["ironing"]:
        cases.append(("ironing", "level 7", dbs["ironing"][7]))
    methods = ["greedy", "greedy-nested", "cpg", "full-dictionary"]
    missing = set()
    for problem, label, db in cases:
        for m in methods:
            basis_size = None
            if m == "cpg":  # the CPG basis size is reported by `verify`, not by `online`
                try:
                    vj = runner.run("verify", "--db", db, "--method", "cpg", "--reference", "fom",
                                    "--threads", runner.threads)
                    basis_size = vj["methods"]["cpg"].get("dual_basis_size")
                except (RuntimeError, KeyError) as e:
                    log(f"  (cpg basis size not available: {str(e).splitlines()[0]})")
            for delta in cfg["deltas"]:
                path = os.path.join(cfg["out"], problem, f"compare_{label.replace(' ', '')}_{m}_delta{dtag(delta)}.csv")
                try:
                    js = runner.validation(db, delta, path, method=m)
                except RuntimeError as e:
                    if "unknown online method" in str(e):
                        missing.add(m)
                        break
                    raise
                rec = {"problem": problem, "training": label, "method": m, "delta": delta}
                rec.update(summarize(read_rows(path), js))
                rec["dual_size"] = basis_size if m == "cpg" else rec["dictionary_size"]
                rows.append(rec)
    if not rows:
        return
    with open(os.path.join(cfg["out"], "comparison.csv"), "w", newline="") as f:
        cols = ["problem", "training", "method", "delta", "primal_rank", "dictionary_size", "dual_size",
                "mean_primal_error",
                "mean_dual_error", "mean_sparsity", "mean_iterations", "mean_time_s", "median_time_s", "nonconverged"]
        w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    text = ("### Comparison with the non-sparse methods\n\n"
            "| problem | training | method | δ | primal rank | dual basis / dictionary size | mean sparsity "
            "| mean iterations | mean primal error | mean dual error | mean time (µs) | median time (µs) "
            "| not converged |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n")
    for r in rows:
        text += (f"| {r['problem']} | {r['training']} | {r['method']} | {r['delta']:.0e} | {r['primal_rank']} | "
                 f"{r['dual_size'] if r['dual_size'] is not None else '–'} | {r['mean_sparsity']:.2f} | "
                 f"{r['mean_iterations']:.1f} | {fmt(r['mean_primal_error'])} | {fmt(r['mean_dual_error'])} | "
                 f"{1e6 * r['mean_time_s']:.0f} | {1e6 * r['median_time_s']:.0f} | "
                 f"{r['nonconverged']}/{r['validation_size']} |\n")
    if missing:
        text += f"\nNot available in this build of the CLI: {', '.join(sorted(missing))}.\n"
    md.append(text + "\n")
    timings.append(("comparison", time.time() - t))
    log(f"comparison: {len(rows)} evaluations" + (f"; methods not available: {sorted(missing)}" if missing else ""))


# ----------------------------------------------------------------------------- main


def cpu_model():
    """The processor's model name as `lscpu` prints it (platform.processor() when lscpu is missing)."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    except OSError:
        out = ""
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown processor"


def find_exe(given):
    if given:
        return given
    for cand in [os.path.join(REPO, "build", "tools", "contactrom"), shutil.which("contactrom")]:
        if cand and os.path.isfile(cand) and os.access(cand, os.X_OK):
            return cand
    sys.exit("experiments.py: no contactrom executable found; build it and pass --exe PATH")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--exe", help="contactrom executable (default: build/tools/contactrom, then PATH)")
    ap.add_argument("--out", default=os.path.join(REPO, "results"), help="results folder (default results/)")
    ap.add_argument("--figures", help="figure folder (default docs/figures; RESULTS_DIR/figures with --quick)")
    ap.add_argument("--quick", action="store_true", help="fast smoke mode (few training sets, δ=1e-8 only)")
    ap.add_argument("--only", help="comma-separated subset of hertz,ironing,ironing2")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1, help="threads for offline/FOM references")
    ap.add_argument("--replot", action="store_true",
                    help="run nothing: redraw the hertz and ironing figures (all but the reconstructions) from the "
                         "results of an earlier run in RESULTS_DIR")
    args = ap.parse_args(argv)

    stages = ["hertz", "ironing", "ironing2"]
    if args.only:
        stages = [s.strip() for s in args.only.split(",") if s.strip()]
        bad = [s for s in stages if s not in {"hertz", "ironing", "ironing2"}]
        if bad:
            ap.error(f"--only: unknown stage(s) {bad}; expected hertz, ironing, ironing2")
    exe = os.path.abspath(find_exe(args.exe))
    out = os.path.abspath(args.out)
    figures = os.path.abspath(args.figures or (os.path.join(out, "figures") if args.quick
                                               else os.path.join(REPO, "docs", "figures")))
    os.makedirs(out, exist_ok=True)
    os.makedirs(figures, exist_ok=True)
    if args.quick:
        cfg = {"deltas": [1e-8], "hertz_sizes": [12, 30], "ironing_levels": [3, 4], "ironing2_levels": [2]}
    else:
        cfg = {"deltas": DELTAS, "hertz_sizes": [12, 30, 60, 120], "ironing_levels": [3, 4, 5, 6, 7],
               "ironing2_levels": [2, 3, 4, 5]}
    cfg.update(out=out, figures=figures)
    if args.replot:
        for stage, kind, draw in [("hertz", "train", hertz_figures), ("ironing", "level", ironing_figures)]:
            if stage in stages:
                draw(cfg, *load_study(out, stage, kind))
        log(f"figures redrawn from {out} in {figures}")
        return
    runner = Runner(exe, args.threads)
    log(f"contactrom: {exe}; results -> {out}; figures -> {figures}; stages {stages}; "
        f"{'quick' if args.quick else 'full'} mode; {args.threads} threads")

    timings, md, dbs = [], [], {}
    stage_fn = {"hertz": stage_hertz, "ironing": stage_ironing, "ironing2": stage_ironing2}
    for s in stages:
        t = time.time()
        log(f"=== {s}")
        _, dbs[s] = stage_fn[s](runner, cfg, timings, md)
        timings.append((f"stage {s} (total)", time.time() - t))
        log(f"=== {s} done in {time.time() - t:.1f} s")
    stage_comparison(runner, cfg, dbs, timings, md)
    total = time.time() - T0
    timings.append(("total", total))

    with open(os.path.join(out, "timings.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["stage", "seconds"])
        for name, sec in timings:
            w.writerow([name, f"{sec:.3f}"])
    version = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip()
    header = (f"Generated by `{' '.join(['tools/experiments.py'] + (argv if argv is not None else sys.argv[1:]))}` "
              f"with {version or exe} on {cpu_model()} ({os.cpu_count()} cores); total {total:.1f} s. "
              f"Times are per query, on a machine shared with other jobs: the medians are the robust figure.\n\n")
    stage_times = "| stage | seconds |\n|---|---:|\n" + "".join(
        f"| {n} | {s:.1f} |\n" for n, s in timings if n.startswith("stage") or n in {"total", "comparison"})
    with open(os.path.join(out, "summary.md"), "w") as f:
        f.write("## Paper experiments (tools/experiments.py)\n\n" + header + "".join(md) + "### Run time\n\n"
                + stage_times)
    log(f"done in {total:.1f} s; tables in {out}/summary.md, figures in {figures}")


if __name__ == "__main__":
    main()
