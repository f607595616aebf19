"""Problems made from files: meshing releases the GIL and stops on Ctrl-C, and the
warnings the CLI prints about a problem and a FOM solution reach Python."""
import os
import re
import signal
import threading
import time
import warnings

import numpy as np
import pytest

import contactrom
from conftest import run_cli, run_cli_json

# Two quad blocks, the bottom one [0, 1] x [0, 0.5] clamped at its base, the top one
# [0, 1] x [y0, y0 + 0.5] pressed down by d at its top; the top's base is the slave.
BLOCKS_GEO = """
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 0.5, 0}; Point(4) = {0, 0.5, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(5) = {0, Y0, 0}; Point(6) = {1, Y0, 0}; Point(7) = {1, Y0 + 0.5, 0}; Point(8) = {0, Y0 + 0.5, 0};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Transfinite Curve{1, 3, 5, 7} = 5; Transfinite Curve{2, 4, 6, 8} = 3;
Transfinite Surface{1}; Transfinite Surface{2}; Recombine Surface{1, 2};
Physical Surface("bottom", 1) = {1}; Physical Surface("top", 2) = {2};
Physical Curve("bottom_base", 11) = {1}; Physical Curve("bottom_top", 12) = {3};
Physical Curve("top_base", 13) = {5}; Physical Curve("top_top", 14) = {7};
"""

BLOCKS_TOML = """
[problem]
name = "blocks"
mesh = "blocks.geo"
displacement_scale = 0.1
EXTRA
[[parameters]]
name = "d"
range = [0.0, 1.5]
lower_open = true
[[bodies]]
group = "bottom"
young = 1.0
poisson = 0.3
[[bodies]]
group = "top"
young = 1.0
poisson = 0.3
[[dirichlet]]
group = "bottom_base"
displacement = [0.0, 0.0]
[[dirichlet]]
group = "top_top"
displacement = [0.0, "-d"]
[[contact]]
slave = "top_base"
master = "bottom_top"
"""

# gmsh runs this loop for hours before it meshes anything (on one line, gmsh runs
# its body once only).
ENDLESS_LOOP = "For i In {1:1e12}\nx = i;\nEndFor\n"


def blocks(folder, y0=0.5, geo_prefix="", extra=""):
    """Writes blocks.geo and blocks.toml into `folder`; the problem file's path."""
    (folder / "blocks.geo").write_text(geo_prefix + f"Y0 = {y0};\n" + BLOCKS_GEO)
    (folder / "blocks.toml").write_text(BLOCKS_TOML.replace("EXTRA", extra))
    return str(folder / "blocks.toml")


def children_of_this_process():
    """Pids of the live processes whose parent is this one (gmsh's children included)."""
    me, found = os.getpid(), []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == me:  # fields: state, ppid, ...
            found.append(int(entry))
    return found


def test_ctrl_c_stops_meshing_and_kills_gmsh(tmp_path):
    # A looping .geo under the default time limit (600 s): SIGINT at 0.5 s raises
    # KeyboardInterrupt at once; gmsh's process is gone and nothing is left behind.
    path = blocks(tmp_path, geo_prefix=ENDLESS_LOOP)
    before = sorted(os.listdir(tmp_path))
    for make in (contactrom.Problem.from_file, contactrom.problem):
        timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        start = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            make(path)
        elapsed = time.monotonic() - start
        timer.join()
        assert 0.4 < elapsed < 5.0, elapsed
        assert children_of_this_process() == []
    assert sorted(os.listdir(tmp_path)) == before
    assert contactrom.Problem.from_file(blocks(tmp_path)).num_dofs > 0  # the module still works


def test_other_threads_run_while_gmsh_meshes(tmp_path):
    # The loop stopped by its time limit (1.5 s): meanwhile a Python thread ticking
    # every 10 ms keeps ticking (it would stall for the whole 1.5 s under the GIL).
    path = blocks(tmp_path, geo_prefix=ENDLESS_LOOP, extra="mesh_time_limit = 1.5")
    ticks, done = [], threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.01)

    ticker = threading.Thread(target=tick)
    ticker.start()
    try:
        start = time.monotonic()
        with pytest.raises(ValueError, match="did not finish within the time limit of 1.5 s"):
            contactrom.Problem.from_file(path)
        end = time.monotonic()
    finally:
        done.set()
        ticker.join()
    during = [t for t in ticks if start <= t <= end]
    assert end - start >= 1.4
    assert len(during) > 20, len(during)
    assert np.max(np.diff([start, *during, end])) < 0.5


def test_reference_overlap_is_a_runtime_warning_and_listed(tmp_path):
    # The top block sunk 0.05 into the bottom one: half of U = 0.1, more than 10 %.
    path = blocks(tmp_path, y0=0.45)
    with pytest.warns(RuntimeWarning, match=r"problem 'blocks': contact pair 0 \(slave 'top_base' on master "
                                            r"'bottom_top'\) overlaps by 0\.05"):
        problem = contactrom.Problem.from_file(path)
    assert len(problem.warnings) == 1 and "overlaps by 0.05" in problem.warnings[0]
    with pytest.warns(RuntimeWarning, match="overlaps by 0.05"):
        contactrom.problem(path)
    # The CLI's warnings, word for word.
    assert run_cli_json("fom", "--problem", path, "--param", "0.01")["warnings"] == problem.warnings
    # Touching blocks: no warning at all, an empty list.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        flush = contactrom.Problem.from_file(blocks(tmp_path, y0=0.5))
    assert flush.warnings == []


def test_solution_that_turns_elements_inside_out_is_warned_about(tmp_path):
    # Pressed down by 1.2, both blocks (0.5 high each, as stiff as each other) are
    # turned inside out: a KKT point far beyond the small-strain model.
    path = blocks(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        problem = contactrom.Problem.from_file(path)
        fom = contactrom.FullOrderSolver(problem)
        small = fom.solve(0.05)
    assert small.warnings == []
    with pytest.warns(RuntimeWarning, match=r"FOM solution of 'blocks' at d = 1\.2: the solution turns \d+ of the "
                                            r"\d+ elements of body 'top' inside out") as record:
        large = fom.solve(1.2)
    assert len(record) == 2 and len(large.warnings) == 2
    assert "body 'bottom'" in large.warnings[0] and "body 'top'" in large.warnings[1]
    assert run_cli_json("fom", "--problem", path, "--param", "1.2")["warnings"] == large.warnings
    # A list of solves: one warning, counting the solutions that carry some.
    with pytest.warns(RuntimeWarning, match=r"1 of the 2 FOM solutions of 'blocks' carry warnings") as record:
        both = fom.solve_all([0.05, 1.2], threads=2)
    assert len(record) == 1
    assert both[0].warnings == [] and both[1].warnings == large.warnings
    # An answer the FOM gives behind a reduced model carries the same warnings.
    db = contactrom.offline(problem, [[0.05], [0.1]], threads=1)
    fallback = contactrom.ReducedModel(db).with_fallback(primal_tolerance=1e-12, dual_tolerance=1e-12)
    with pytest.warns(RuntimeWarning, match=r"FOM solution of 'blocks' at d = 1\.2: the solution turns"):
        answer = fallback.solve(1.2)
    assert answer["source"] == "fom" and answer["warnings"] == large.warnings
    # Errors measured against such references are flagged, by Python and by the CLI.
    message = r"1 of the 2 FOM references of 'blocks' carry warnings; the first, at d = 1\.2: the solution turns"
    with pytest.warns(RuntimeWarning, match=message):
        contactrom.ReducedModel(db).evaluate([[0.05], [1.2]], threads=1)
    contactrom.offline(problem, 2, threads=1).save(tmp_path / "blocks.h5")
    (tmp_path / "params.csv").write_text("d\n0.05\n1.2\n")
    proc = run_cli("online", "--db", str(tmp_path / "blocks.h5"), "--validation", "--params",
                   str(tmp_path / "params.csv"))
    assert re.search("contactrom: warning: " + message, proc.stderr), proc.stderr


def test_verify_refuses_a_reference_of_another_problem_of_the_same_sizes(tmp_path):
    # The same mesh with a stiffer bottom block: the fields have the same sizes, so
    # only the problem's fingerprint tells the two apart.
    (tmp_path / "soft").mkdir()
    (tmp_path / "stiff").mkdir()
    soft = contactrom.Problem.from_file(blocks(tmp_path / "soft"))
    stiff_path = blocks(tmp_path / "stiff")
    with open(stiff_path) as f:
        text = f.read()
    with open(stiff_path, "w") as f:
        f.write(text.replace("young = 1.0", "young = 3.0", 1))
    stiff = contactrom.Problem.from_file(stiff_path)
    assert (soft.num_dofs, soft.num_constraints) == (stiff.num_dofs, stiff.num_constraints)
    a = contactrom.FullOrderSolver(soft).solve(0.05)
    b = contactrom.FullOrderSolver(stiff).solve(0.05)
    assert np.abs(a.u - b.u).max() > 1e-3  # the two answers do differ
    with pytest.raises(ValueError, match=r"reference is a solution of problem 'blocks' \(fingerprint [0-9a-f]{16}\), "
                                         r"not of 'blocks' \(fingerprint [0-9a-f]{16}\)"):
        contactrom.verify(soft, 0.05, a.u, a.lam, reference=b)
    assert contactrom.verify(soft, 0.05, a.u, a.lam, reference=a)["status"] == "success"
