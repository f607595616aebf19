#!/usr/bin/python3
"""Offline stage at scale: snapshots/s, peak memory and POD time against the number of
snapshots and the dofs, with the contactrom CLI.

    tools/offline_scaling.py [--exe PATH] [--mpirun PATH] [--out DIR] [--runs r:m,r:m,...]
                             [--svd-max ENTRIES] [--threads T] [--keep]

For every run r:m (hertz, --refine r, --train m; default 0:100,0:1000,0:10000,
2:100,2:1000,2:2000):

  offline  `/usr/bin/time -v contactrom offline --problem hertz --refine r --train m
           --threads T --json --out DIR/hertz_r<r>_<m>.h5`: wall time, snapshots per
           second, peak resident memory, file size (kept with --keep if it exists).
  reduce   `/usr/bin/time -v contactrom reduce --db ... --method greedy --delta 1e-8
           --pod snapshots --threads T --json` and the same with `--pod svd` (up to
           --svd-max snapshot entries n*m, default 1e8), one after the other: POD time,
           whole time, peak memory, rank, and the agreement of the two (largest relative
           difference of the kept singular values, sine of the largest principal angle
           between the bases). A wide set (m >= dofs) runs the SVD only, as
           `--pod auto` does.
  mpi      for the last run that is not wide, `mpirun -np 2 contactrom reduce ... --pod snapshots
           --threads 1` against the serial `--pod snapshots --threads 1`: the same
           agreement measures.

Prints a markdown table per stage and writes DIR/offline_scaling.json. Use
/usr/bin/python3 (numpy, h5py from Debian). DIR defaults to results/offline_scaling
(git-ignored).
"""
import argparse
import json
import os
import re
import subprocess
import sys

import h5py
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed(cmd):
    """Runs `cmd` under /usr/bin/time -v; returns (JSON of stdout, wall s, peak RSS MB)."""
    print("$", " ".join(cmd), flush=True)
    r = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"command failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1)) / 1024.0
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", r.stderr).group(1)
    seconds = 0.0
    for part in wall.split(":"):
        seconds = 60.0 * seconds + float(part)
    return json.loads(r.stdout.strip().splitlines()[-1]), seconds, rss


def model(path):
    """Singular values, basis (n x r) of a reduced-model file."""
    with h5py.File(path, "r") as f:
        return f["singular_values"][:], f["basis"][:].T


def agreement(a, b):
    """Largest relative difference of the kept singular values, sine of the largest
    principal angle between the two bases (None when the ranks differ)."""
    (sa, pa), (sb, pb) = model(a), model(b)
    r = pa.shape[1]
    if pb.shape[1] != r:
        return {"rank_a": r, "rank_b": pb.shape[1]}
    rel = float(np.max(np.abs(sa[:r] - sb[:r]) / sa[:r])) if r else 0.0
    residual = pa - pb @ (pb.T @ pa)
    angle = float(np.linalg.svd(residual, compute_uv=False)[0]) if r else 0.0
    return {"rank": r, "sigma_rel": rel, "subspace": angle}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--exe", default=os.path.join(REPO, "build", "tools", "contactrom"))
    p.add_argument("--mpirun", default="mpirun")
    p.add_argument("--out", default=os.path.join(REPO, "results", "offline_scaling"))
    p.add_argument("--runs", default="0:100,0:1000,0:10000,2:100,2:1000,2:2000")
    p.add_argument("--svd-max", type=float, default=1e8)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--keep", action="store_true", help="reuse databases already in --out")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    runs = [tuple(int(x) for x in item.split(":")) for item in a.runs.split(",")]
    rows = []
    for refine, m in runs:
        db = os.path.join(a.out, f"hertz_r{refine}_{m}.h5")
        row = {"refine": refine, "snapshots": m}
        if not (a.keep and os.path.exists(db)):
            out, wall, rss = timed([a.exe, "offline", "--problem", "hertz", "--refine", str(refine), "--train", str(m),
                                    "--threads", str(a.threads), "--json", "--out", db])
            row.update(offline_wall_s=wall, offline_rss_mb=rss, snapshots_per_s=m / out["wall_time_s"],
                       setup_s=out["setup_time_s"])
        with h5py.File(db, "r") as f:
            row["dofs"] = int(f["primal"].shape[1])
        row["db_mb"] = os.path.getsize(db) / 2**20
        wide = m >= row["dofs"]  # `--pod auto` takes the SVD; the Gram matrix would be m x m
        for pod in ["snapshots", "svd"]:
            if (pod == "svd" and row["dofs"] * m > a.svd_max and not wide) or (pod == "snapshots" and wide):
                continue
            rom = os.path.join(a.out, f"rom_r{refine}_{m}_{pod}.h5")
            out, wall, rss = timed([a.exe, "reduce", "--db", db, "--method", "greedy", "--delta", "1e-8", "--pod", pod,
                                    "--threads", str(a.threads), "--json", "--out", rom])
            row["pod_" + pod] = {"pod_s": out["pod_time_s"], "reduce_s": wall, "rss_mb": rss, "rank": out["primal_rank"],
                        "rom_mb": out["bytes"] / 2**20}
        if "pod_svd" in row and "pod_snapshots" in row:
            row["agreement"] = agreement(os.path.join(a.out, f"rom_r{refine}_{m}_svd.h5"),
                                         os.path.join(a.out, f"rom_r{refine}_{m}_snapshots.h5"))
        rows.append(row)
        print(json.dumps(row), flush=True)

    tall = [r for r in rows if "pod_snapshots" in r]
    if not tall:
        sys.exit("no run has fewer snapshots than dofs: nothing for the method of snapshots under MPI")
    refine, m = tall[-1]["refine"], tall[-1]["snapshots"]
    db = os.path.join(a.out, f"hertz_r{refine}_{m}.h5")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    roms = {}
    for ranks in [1, 2]:
        rom = os.path.join(a.out, f"rom_mpi{ranks}.h5")
        cmd = ([a.mpirun, "--oversubscribe", "-np", "2"] if ranks == 2 else []) + [
            a.exe, "reduce", "--db", db, "--method", "greedy", "--delta", "1e-8", "--pod", "snapshots", "--threads", "1",
            "--json", "--out", rom]
        print("$", " ".join(cmd), flush=True)
        r = subprocess.run(cmd, capture_output=True, text=True, env=env)
        if r.returncode != 0:
            sys.exit(r.stderr)
        roms[ranks] = (rom, json.loads(r.stdout.strip().splitlines()[-1]))
    mpi = {"refine": refine, "snapshots": m, "serial_pod_s": roms[1][1]["pod_time_s"],
           "mpi2_pod_s": roms[2][1]["pod_time_s"], **agreement(roms[1][0], roms[2][0])}
    print(json.dumps(mpi), flush=True)
    with open(os.path.join(a.out, "offline_scaling.json"), "w") as f:
        json.dump({"runs": rows, "mpi": mpi}, f, indent=1)

    print("\n| refine | dofs | snapshots | offline wall | snapshots/s | offline peak RSS | database |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        if "offline_wall_s" in r:
            print(f"| {r['refine']} | {r['dofs']:,} | {r['snapshots']:,} | {r['offline_wall_s']:.1f} s | "
                  f"{r['snapshots_per_s']:.1f} | {r['offline_rss_mb']:.0f} MB | {r['db_mb']:.0f} MB |")
    print("\n| refine | dofs | snapshots | POD snapshots | reduce peak RSS | POD svd | reduce peak RSS (svd) | svd/snapshots | rank | max rel. σ diff | subspace |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        s, v, g = r.get("pod_snapshots"), r.get("pod_svd"), r.get("agreement", {})
        if s is None:  # a wide set: the SVD only
            print(f"| {r['refine']} | {r['dofs']:,} | {r['snapshots']:,} | — | — | {v['pod_s']:.2f} s | "
                  f"{v['rss_mb']:.0f} MB | — | {v['rank']} | — | — |")
            continue
        print(f"| {r['refine']} | {r['dofs']:,} | {r['snapshots']:,} | {s['pod_s']:.2f} s | {s['rss_mb']:.0f} MB | "
              + (f"{v['pod_s']:.2f} s | {v['rss_mb']:.0f} MB | {v['pod_s'] / s['pod_s']:.1f}× | {g.get('rank')} | "
                 f"{g.get('sigma_rel', float('nan')):.1e} | {g.get('subspace', float('nan')):.1e} |"
                 if v else "— | — | — | " + f"{s['rank']} | — | — |"))
    print(f"\nmpirun -np 2 reduce (refine {refine}, {m} snapshots): POD {mpi['mpi2_pod_s']:.2f} s against "
          f"{mpi['serial_pod_s']:.2f} s serial (one thread each); rank {mpi.get('rank')}, max rel. σ diff "
          f"{mpi.get('sigma_rel', float('nan')):.1e}, subspace {mpi.get('subspace', float('nan')):.1e}")


if __name__ == "__main__":
    main()
