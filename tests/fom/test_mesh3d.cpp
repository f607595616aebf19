// Tests of fom/mesh in 3D: physical volumes as bodies of tetrahedra or hexahedra,
// physical surfaces as outward-oriented facet groups, refinement splitting every
// cell in eight, the fingerprint, and the errors of unsupported 3D elements.
#define BOOST_TEST_MODULE fom_mesh3d
#include <boost/test/unit_test.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/input_error.hpp"
#include <contactrom/fom/mesh.hpp>

using contactrom::fom::load_mesh;
using contactrom::fom::Mesh;
using contactrom::fom::MeshOptions;
using contactrom::test::input_error_of;
using Eigen::Vector3d;

namespace {

/// A .geo file in a fresh temporary folder, removed with the folder at scope exit.
struct GeoFile {
  std::filesystem::path dir, path;
  GeoFile(const std::string& name, const std::string& content) {
    dir = std::filesystem::temp_directory_path() / ("contactrom_test_mesh3d_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    path = dir / name;
    std::ofstream(path) << content;
  }
  ~GeoFile() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

// The unit cube of tetrahedra (OpenCASCADE box: faces 1..6 are x=0, x=1, y=0,
// y=1, z=0, z=1).
const char* kTetraCube = R"(SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Mesh.CharacteristicLengthMax = 0.4;
Physical Volume("block") = {1};
Physical Surface("x0") = {1};
Physical Surface("x1") = {2};
Physical Surface("y0") = {3};
Physical Surface("y1") = {4};
Physical Surface("bottom") = {5};
Physical Surface("top") = {6};
Physical Point("corner") = {1};
)";

// The unit cube of 2 x 2 x 2 hexahedra (a recombined transfinite square extruded
// in two layers).
const char* kHexaCube = R"(Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 3; Transfinite Surface{1}; Recombine Surface{1};
out[] = Extrude{0, 0, 1}{ Surface{1}; Layers{2}; Recombine; };
Physical Volume("block") = {out[1]};
Physical Surface("bottom") = {1};
Physical Surface("top") = {out[0]};
Physical Surface("y0") = {out[2]};
Physical Surface("x1") = {out[3]};
Physical Surface("y1") = {out[4]};
Physical Surface("x0") = {out[5]};
Physical Curve("edge") = {1};
)";

Vector3d x3(const Mesh& m, int node) { return m.nodes.col(node); }

double tetra_volume(const Mesh& m, const std::array<int, 8>& c) {
  return (x3(m, c[1]) - x3(m, c[0])).cross(x3(m, c[2]) - x3(m, c[0])).dot(x3(m, c[3]) - x3(m, c[0])) / 6.0;
}

/// Volume of a hexahedron whose faces are planar: the sum of its six tetrahedra
/// around the diagonal 0-6.
double hexa_volume(const Mesh& m, const std::array<int, 8>& c) {
  const int tets[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  double v = 0.0;
  for (const auto& t : tets) v += tetra_volume(m, {c[t[0]], c[t[1]], c[t[2]], c[t[3]], -1, -1, -1, -1});
  return v;
}

double volume(const Mesh& m) {
  double v = 0.0;
  for (const auto& c : m.cells) v += Mesh::cell_size(c) == 4 ? tetra_volume(m, c) : hexa_volume(m, c);
  return v;
}

/// Area-weighted normal of a facet (triangle, or planar quad: half the diagonals' cross product).
Vector3d area_normal(const Mesh& m, const std::array<int, 4>& f) {
  if (f[3] < 0) return 0.5 * (x3(m, f[1]) - x3(m, f[0])).cross(x3(m, f[2]) - x3(m, f[0]));
  return 0.5 * (x3(m, f[2]) - x3(m, f[0])).cross(x3(m, f[3]) - x3(m, f[1]));
}

/// Every facet of `group` has the outward normal `n`; returns the group's area.
double check_outward(const Mesh& m, const std::string& group, const Vector3d& n) {
  double area = 0.0;
  for (const auto& f : m.faces.at(group)) {
    const Vector3d a = area_normal(m, f);
    BOOST_TEST((a.normalized() - n).norm() <= 1e-12, group << " facet normal " << a.transpose());
    area += a.norm();
  }
  return area;
}

void check_cube(const Mesh& m) {
  BOOST_TEST(m.dim == 3);
  BOOST_TEST(m.nodes.rows() == 3);
  BOOST_TEST(m.body_names == std::vector<std::string>{"block"});
  BOOST_TEST(m.num_elements() == m.num_cells());
  BOOST_TEST(m.quads.empty());
  for (const auto& c : m.cells) {
    const double v = Mesh::cell_size(c) == 4 ? tetra_volume(m, c) : hexa_volume(m, c);
    BOOST_TEST(v > 0.0);
  }
  BOOST_TEST(std::abs(volume(m) - 1.0) <= 1e-12);
  const struct {
    const char* name;
    Vector3d n;
    int axis;
    double value;
  } sides[] = {{"x0", {-1, 0, 0}, 0, 0.0}, {"x1", {1, 0, 0}, 0, 1.0},    {"y0", {0, -1, 0}, 1, 0.0},
               {"y1", {0, 1, 0}, 1, 1.0},  {"bottom", {0, 0, -1}, 2, 0.0}, {"top", {0, 0, 1}, 2, 1.0}};
  for (const auto& s : sides) {
    BOOST_TEST(std::abs(check_outward(m, s.name, s.n) - 1.0) <= 1e-12, s.name);
    for (int node : m.group_nodes(s.name)) BOOST_TEST(std::abs(m.nodes(s.axis, node) - s.value) <= 1e-12);
  }
}

}  // namespace

BOOST_AUTO_TEST_CASE(tetrahedral_cube_has_positive_cells_and_outward_facets) {
  const GeoFile geo("tet_cube.geo", kTetraCube);
  const Mesh m = load_mesh(geo.path.string());
  check_cube(m);
  for (const auto& c : m.cells) BOOST_TEST(Mesh::cell_size(c) == 4);
  BOOST_REQUIRE(m.group_nodes("corner").size() == 1u);  // a physical point: its node, a corner of the cube
  const Vector3d corner = x3(m, m.group_nodes("corner")[0]);
  for (int i = 0; i < 3; ++i) BOOST_TEST((corner(i) == 0.0 || corner(i) == 1.0));
}

BOOST_AUTO_TEST_CASE(hexahedral_cube_has_positive_cells_and_outward_facets) {
  const GeoFile geo("hex_cube.geo", kHexaCube);
  const Mesh m = load_mesh(geo.path.string());
  check_cube(m);
  BOOST_TEST(m.num_cells() == 8);
  BOOST_TEST(m.num_nodes() == 27);
  for (const auto& c : m.cells) BOOST_TEST(Mesh::cell_size(c) == 8);
  BOOST_TEST(m.faces.at("top").size() == 4u);
  BOOST_TEST(m.group_nodes("edge").size() == 3u);  // a physical curve: its nodes
}

BOOST_AUTO_TEST_CASE(refinement_splits_every_cell_in_eight) {
  const GeoFile tet("tet_cube.geo", kTetraCube), hex("hex_cube.geo", kHexaCube);
  MeshOptions fine;
  fine.refine = 1;
  for (const auto* geo : {&tet, &hex}) {
    const Mesh coarse = load_mesh(geo->path.string()), refined = load_mesh(geo->path.string(), fine);
    check_cube(refined);
    BOOST_TEST(refined.num_cells() == 8 * coarse.num_cells());
    BOOST_TEST(refined.faces.at("top").size() == 4 * coarse.faces.at("top").size());
    BOOST_TEST(refined.fingerprint() != coarse.fingerprint());
  }
  BOOST_TEST(load_mesh(hex.path.string(), fine).num_nodes() == 125);
}

BOOST_AUTO_TEST_CASE(fingerprint_is_stable_and_tells_meshes_apart) {
  const GeoFile tet("tet_cube.geo", kTetraCube), hex("hex_cube.geo", kHexaCube);
  const std::string a = load_mesh(tet.path.string()).fingerprint();
  BOOST_TEST(a.size() == 16u);
  BOOST_TEST(load_mesh(tet.path.string()).fingerprint() == a);
  BOOST_TEST(load_mesh(hex.path.string()).fingerprint() != a);
}

BOOST_AUTO_TEST_CASE(prisms_are_refused_naming_the_element_kind) {
  const GeoFile geo("prisms.geo", R"(Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3}; Plane Surface(1) = {1};
out[] = Extrude{0, 0, 1}{ Surface{1}; Layers{1}; Recombine; };
Physical Volume("wedge") = {out[1]};
)");
  const std::string msg = input_error_of([&] { load_mesh(geo.path.string()); });
  BOOST_TEST(msg.find("volume elements must be 4-node tetrahedra or 8-node hexahedra") != std::string::npos, msg);
  BOOST_TEST(msg.find("prisms.geo") != std::string::npos, msg);
}

BOOST_AUTO_TEST_CASE(a_surface_group_off_the_volumes_is_refused) {
  // A physical surface not bounding the body: its facets are no faces of a cell.
  const GeoFile geo("loose.geo", std::string(kHexaCube) + R"(
Point(101) = {0, 0, 2}; Point(102) = {1, 0, 2}; Point(103) = {1, 1, 2}; Point(104) = {0, 1, 2};
Line(101) = {101, 102}; Line(102) = {102, 103}; Line(103) = {103, 104}; Line(104) = {104, 101};
Curve Loop(101) = {101, 102, 103, 104}; Plane Surface(101) = {101};
Physical Surface("loose") = {101};
)");
  const std::string msg = input_error_of([&] { load_mesh(geo.path.string()); });
  BOOST_TEST(msg.find("'loose'") != std::string::npos, msg);
}
