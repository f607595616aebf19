#!/usr/bin/python3
"""FOM setup time, query time and peak memory of 3D problems against their size
and against their contact surface (the 3D scale tables of docs/results.md).

Each case is hertz3d's geometry (meshes/hertz3d.geo) with the mesh constants
overridden before it is included (element size hmin at the contact point, growth
alpha, contact cap and disk radii rc and rm), refined `refine` times and solved
once at d = 0.02 by `contactrom fom` under /usr/bin/time -v:

    /usr/bin/python3 tools/scaling3d.py --exe build/tools/contactrom --series dofs
    /usr/bin/python3 tools/scaling3d.py --exe build/tools/contactrom --series contact

Series `dofs`: the whole mesh refined (coarse gradings and the shipped one,
refine 0, 1, 2; 3.9k to 299k dofs). Series `contact`: the shipped mesh with a larger and larger contact cap
and disk (about the same dofs, more contact nodes).

Columns: dofs, contact rows (slave nodes), surface dofs (slave and master nodes,
three each: the size of the condensed contact problem), setup (factorisation and
condensation, s), query (the first solve of the process, s), peak resident memory
(GiB) of the whole process, gmsh included. The BLAS is whatever the executable
loads (`ldd` shows it).
"""
import argparse
import json
import os
import re
import subprocess
import tempfile

COARSE = (0.03, 0.15, 0.2, 0.25)     # hmin, alpha, rc, rm
FINER = (0.03, 0.13, 0.2, 0.25)
MEDIUM = (0.025, 0.12, 0.2, 0.25)
SHIPPED = (0.015, 0.08, 0.3, 0.4)    # meshes/hertz3d.geo's defaults
SERIES = {  # (hmin, alpha, rc, rm, refine)
    "dofs": [COARSE + (0,), SHIPPED + (0,), COARSE + (1,), SHIPPED + (1,), COARSE + (2,), FINER + (2,),
             MEDIUM + (2,)],
    "contact": [(0.015, 0.08, rc, rc + 0.1, 0) for rc in (0.15, 0.3, 0.45, 0.6, 0.75, 0.9)]
               + [(0.015, 0.08, rc, rc + 0.1, 1) for rc in (0.15, 0.45, 0.6, 0.9)],
}

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--exe", default="build/tools/contactrom")
parser.add_argument("--series", choices=sorted(SERIES), default="dofs")
parser.add_argument("--cases", type=int, nargs="+", help="indices into the series (default: all)")
args = parser.parse_args()
cases = SERIES[args.series]
root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
shipped = open(os.path.join(root, "problems", "hertz3d.toml")).read()

print("| hmin | alpha | rc | refine | dofs | contact rows | surface dofs | setup (s) | query (s) | peak memory (GiB) | force |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
with tempfile.TemporaryDirectory() as tmp:
    for i in (args.cases if args.cases is not None else range(len(cases))):
        hmin, alpha, rc, rm, refine = cases[i]
        geo = os.path.join(tmp, f"case{i}.geo")
        with open(geo, "w") as f:
            f.write(f"hmin = {hmin}; alpha = {alpha}; rc = {rc}; rm = {rm};\n"
                    f'Include "{os.path.join(root, "meshes", "hertz3d.geo")}";\n')
        toml = os.path.join(tmp, f"case{i}.toml")
        with open(toml, "w") as f:
            f.write(shipped.replace('"../meshes/hertz3d.geo"', f'"{geo}"').replace('name = "hertz3d"', f'name = "case{i}"'))
        proc = subprocess.run(["/usr/bin/time", "-v", args.exe, "fom", "--problem", toml, "--param", "0.02",
                               "--refine", str(refine), "--json"], capture_output=True, text=True)
        j = json.loads(proc.stdout)
        rss_kib = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", proc.stderr).group(1))
        py = subprocess.run(["/usr/bin/python3", "-c",
                             "import contactrom,sys; p = contactrom.Problem.from_file(sys.argv[1], refine=int(sys.argv[2]));"
                             " print(len(p.surface_dofs))", toml, str(refine)],
                            capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=os.path.join(root, "build", "python")))
        surface = py.stdout.strip() or "?"
        print(f"| {hmin} | {alpha} | {rc} | {refine} | {j['dofs']:,} | {j['constraints']:,} | {surface} | "
              f"{j['setup_time_s']:.1f} | {j['time_s']:.3f} | {rss_kib / 2**20:.2f} | {j['contact_force']:.5e} |", flush=True)
        assert j["status"] == "success", j
