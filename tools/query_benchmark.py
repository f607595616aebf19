#!/usr/bin/env python3
"""Load and query times of a saved reduced model against `online`, which re-reads
the database, rebuilds the reduced model and solves the FOM for every run.

    tools/query_benchmark.py [--exe build/tools/contactrom] [--problem hertz] [--train 30]
                             [--methods greedy,cpg] [--repeats 7] [--range 0,0.3] [--dir DIR]

Prints a Markdown table (medians over --repeats runs of each command):
  load_ms      reduced-model file read + problem rebuilt + online method built
  query_us     median online time per query over 200 queries (the `bench` convention)
  query_cmd_ms wall time of one `contactrom query --param` process
  online_cmd_ms wall time of one `contactrom online --param` process (database read,
               reduced model built, ROM query, FOM solved for the errors)
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def run(cmd):
    t0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return time.perf_counter() - t0, out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(os.path.dirname(__file__), "..", "build", "tools", "contactrom"))
    ap.add_argument("--problem", default="hertz")
    ap.add_argument("--train", type=int, default=30)
    ap.add_argument("--methods", default="greedy,cpg")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--range", default="0,0.3", help="range of the (first) parameter to query (hertz: 0,0.3)")
    ap.add_argument("--dir", default=None)
    a = ap.parse_args()
    work = a.dir or tempfile.mkdtemp(prefix="contactrom-query-")
    db = os.path.join(work, f"{a.problem}{a.train}.h5")
    run([a.exe, "offline", "--problem", a.problem, "--train", str(a.train), "--out", db])
    # 200 queries spread over the range of the first parameter (1-parameter problems).
    lo, hi = (float(v) for v in a.range.split(","))
    queries = os.path.join(work, "queries.csv")
    with open(queries, "w") as f:
        for i in range(200):
            f.write(f"{lo + (hi - lo) * (i + 0.5) / 200!r}\n")
    mid = repr(lo + 0.37 * (hi - lo))
    print(f"| method | load (ms) | query, median per query (µs) | `query --param` process (ms) | `online --param` process (ms) |")
    print("|---|---|---|---|---|")
    for method in a.methods.split(","):
        rom = os.path.join(work, f"{a.problem}{a.train}_{method}.h5")
        run([a.exe, "reduce", "--db", db, "--method", method, "--out", rom])
        load, per_query, query_cmd, online_cmd = [], [], [], []
        for _ in range(a.repeats):
            j = json.loads(run([a.exe, "query", "--rom", rom, "--params", queries, "--json"])[1])
            load.append(j["load_time_s"])
            per_query.append(j["median_time_s"])
            query_cmd.append(run([a.exe, "query", "--rom", rom, "--param", mid])[0])
            online_cmd.append(run([a.exe, "online", "--db", db, "--method", method, "--param", mid])[0])
        med = statistics.median
        print(f"| {method} | {med(load) * 1e3:.1f} | {med(per_query) * 1e6:.1f} | {med(query_cmd) * 1e3:.0f} | "
              f"{med(online_cmd) * 1e3:.0f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
