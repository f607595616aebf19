"""A 3D problem written by a user, end to end: a gmsh .geo of two bodies (physical
volumes and surfaces), a problem file with formulation = "3d", Young's modulus a
parameter and a Dirichlet condition with "free" components; `fom`, `offline`,
`online --validation`, `reduce`, `query` (VTU with tetrahedra, surface CSV with z),
`chls` (against SciPy) and the Python FOM, which agrees with the CLI."""
import csv
import os

import h5py
import numpy as np
import pytest
from scipy.optimize import nnls

import contactrom
from conftest import run_cli, run_cli_json

GEO = """SetFactory("OpenCASCADE");
// a rounded punch (a quarter of a ball, radius 0.5, centred (0,0,0.5)) on a block
Sphere(1) = {0, 0, 0.5, 0.5};
Box(2) = {0, 0, 0, 0.5, 0.5, 0.5};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {0, 0, -0.6, 0.8, 0.8, 0.6};
e = 1e-6;
Physical Volume("punch") = {3};
Physical Volume("base") = {4};
top() = Surface In BoundingBox{-e, -e, 0.5 - e, 0.5 + e, 0.5 + e, 0.5 + e};
sx() = Surface In BoundingBox{-e, -e, -e, e, 0.5 + e, 0.5 + e};
sy() = Surface In BoundingBox{-e, -e, -e, 0.5 + e, e, 0.5 + e};
face() = Abs(Boundary{ Volume{3}; });
face() -= top();
face() -= sx();
face() -= sy();
Physical Surface("punch_face") = face();
Physical Surface("punch_top") = top();
Physical Surface("base_top") = Surface In BoundingBox{-e, -e, -e, 0.8 + e, 0.8 + e, e};
Physical Surface("base_bottom") = Surface In BoundingBox{-e, -e, -0.6 - e, 0.8 + e, 0.8 + e, -0.6 + e};
Physical Surface("symmetry_x") = Surface In BoundingBox{-e, -e, -0.6 - e, e, 0.8 + e, 0.5 + e};
Physical Surface("symmetry_y") = Surface In BoundingBox{-e, -e, -0.6 - e, 0.8 + e, e, 0.5 + e};
Mesh.CharacteristicLengthMax = 0.12;
"""

TOML = """[problem]
name = "user3d"
mesh = "user3d.geo"
formulation = "3d"

[[parameters]]
name = "d"
range = [0.005, 0.03]

[[parameters]]
name = "E"
range = [1.0, 3.0]

[[bodies]]
group = "punch"
young = "E"

[[bodies]]
group = "base"
young = 1.0
poisson = 0.25

[[dirichlet]]
group = "base_bottom"
displacement = [0.0, 0.0, 0.0]

[[dirichlet]]
group = "punch_top"
displacement = ["free", "free", "-d"]

[[dirichlet]]
group = "symmetry_x"
displacement = [0.0, "free", "free"]

[[dirichlet]]
group = "symmetry_y"
displacement = ["free", 0.0, "free"]

[[contact]]
slave = "punch_face"
master = "base_top"

[training]
sampling = "nested"

[validation]
sampling = "next_level"
"""


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("user3d")
    (folder / "user3d.geo").write_text(GEO)
    (folder / "user3d.toml").write_text(TOML)
    return folder


def test_fom_cli_and_python_agree(case):
    path = str(case / "user3d.toml")
    cli = run_cli_json("fom", "--problem", path, "--param", "0.02,2.0")
    assert cli["status"] == "success"
    assert max(cli["kkt"].values()) <= 1e-10
    assert cli["active"] > 0
    problem = contactrom.Problem.from_file(path)
    assert problem.dofs_per_node == 3
    assert problem.contact_points.shape == (problem.num_constraints, 3)
    assert problem.node_coordinates.shape[1] == 3
    sol = contactrom.FullOrderSolver(problem).solve([0.02, 2.0])
    assert sol.status == "success"
    assert sol.contact_force == pytest.approx(cli["contact_force"], rel=1e-12)
    assert sol.kkt["max"] <= 1e-10


@pytest.fixture(scope="module")
def database(case):
    """The user problem's level-2 database (5 x 5 tensor grid) written by `offline`."""
    db = str(case / "user3d.h5")
    run_cli("offline", "--problem", str(case / "user3d.toml"), "--level", "2", "--out", db)
    return db


def test_offline_online_reduce_query(case, database):
    db, rom = database, str(case / "user3d_rom.h5")
    online = run_cli_json("online", "--db", db, "--method", "greedy", "--validation")
    assert online["nonconverged"] == 0
    assert online["validation_size"] > 0
    assert np.isfinite(online["mean_primal_error"]) and online["mean_primal_error"] < 0.1
    run_cli("reduce", "--db", db, "--method", "greedy", "--out", rom)
    fields = case / "fields"
    query = run_cli_json("query", "--rom", rom, "--param", "0.017,1.5", "--fields", str(fields))
    assert query["queries"][0]["status"] == "success"
    vtu = (fields / "user3d_greedy.vtu").read_text()
    types = vtu.split('Name="types"')[1].split("</DataArray>")[0].split(">")[1].split()
    assert set(types) == {"10"}  # VTK tetrahedra
    with open(fields / "user3d_greedy_surface.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0].keys()) == ["x", "y", "z", "gap", "pressure", "u_x", "u_y", "u_z"]
    assert max(float(r["pressure"]) for r in rows) > 0.0


def test_chls_of_the_3d_database_matches_an_independent_solve(database):
    # Leave-one-out convex-hull least squares of the 3D primal snapshots; the centre
    # of the 5 x 5 grid is checked against SciPy's NNLS with the constraint
    # sum(alpha) = 1 as a heavily weighted extra row.
    result = run_cli_json("chls", "--db", database)
    errors = np.array(result["chls_error"])
    with h5py.File(database) as f:
        primal = f["primal"][()]  # one row per snapshot
    assert primal.shape[0] == len(errors) == 25 and primal.shape[1] % 3 == 0
    assert np.all(np.isfinite(errors)) and np.all(errors >= 0.0)
    k = 12
    others = np.delete(primal, k, axis=0).T
    target = primal[k]
    weight = 1e4 * np.linalg.norm(target)
    alpha, _ = nnls(np.vstack([others, weight * np.ones(others.shape[1])]), np.append(target, weight))
    reference = np.linalg.norm(others @ alpha - target) / np.linalg.norm(target)
    assert abs(alpha.sum() - 1.0) <= 1e-6
    assert errors[k] == pytest.approx(reference, rel=1e-4, abs=1e-10)
    assert 1e-6 < errors[k] < 0.5  # an interior point of the grid is close to its neighbours' hull


@pytest.mark.parametrize("edit,key,words", [
    # a 2D formulation with three-component vectors
    (('formulation = "3d"\n', ''), "dirichlet[0].displacement",
     "expected an array of two components [x, y] (number, affine expression or \"free\"); the problem's formulation is 2D"),
    # two components in 3D
    (('displacement = ["free", "free", "-d"]', 'displacement = ["free", "-d"]'), "dirichlet[1].displacement",
     "expected an array of three components [x, y, z]"),
    # an unknown formulation
    (('formulation = "3d"', 'formulation = "4d"'), "problem.formulation", "expected \"plane_strain\", \"plane_stress\" or \"3d\""),
    # a volume that is not a body
    (('group = "base"\n', 'group = "basis"\n'), "bodies[1].group", "the mesh has no physical volume 'basis'"),
])
def test_malformed_3d_problem_files_are_one_line_errors(case, edit, key, words):
    from conftest import cli_error
    path = case / "broken.toml"
    text = TOML.replace(*edit)
    assert text != TOML
    path.write_text(text.replace('name = "user3d"', 'name = "broken"'))
    message = cli_error("fom", "--problem", str(path), "--param", "0.02,2.0")
    assert f"problem file '{path}'" in message and f"key '{key}'" in message and ", line " in message, message
    assert words in message, message


def test_a_3d_formulation_on_a_2d_mesh_names_the_key(case):
    from conftest import cli_error
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    text = open(os.path.join(root, "problems", "hertz.toml")).read()
    text = text.replace('formulation = "plane_strain"', 'formulation = "3d"')
    text = text.replace('displacement = [0.0, 0.0]', 'displacement = [0.0, 0.0, 0.0]')
    text = text.replace('displacement = [0.0, "-d"]', 'displacement = [0.0, "-d", 0.0]')
    text = text.replace('"../meshes/hertz.geo"', repr(os.path.join(root, "meshes", "hertz.geo")).replace("'", '"'))
    path = case / "hertz_as_3d.toml"
    path.write_text(text)
    message = cli_error("fom", "--problem", str(path), "--param", "0.1")
    assert "key 'problem.formulation'" in message and "the problem is 3D" in message and "is 2D" in message, message
