#pragma once
// Structured 3D box meshes built without gmsh, for tests: an nx x ny x nz grid of
// hexahedra (gmsh node order) or of tetrahedra (each hexahedron split into six
// around its diagonal 0-6, a conforming split), with the six sides as outward
// facet groups "x0", "x1", "y0", "y1", "bottom", "top"; and the union of boxes as
// the bodies of one mesh (groups prefixed with the body name and '_').
#include <Eigen/Dense>
#include <array>
#include <random>
#include <string>
#include <vector>

#include <contactrom/fom/mesh.hpp>

namespace contactrom::test {

struct BoxSpec {
  std::string name = "block";
  std::array<int, 3> cells = {2, 2, 2};
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), size = Eigen::Vector3d::Ones();
  bool tets = false;
  double jitter = 0.0;  ///< interior nodes moved by up to this fraction of a cell
  unsigned seed = 7;
};

inline fom::Mesh box_mesh(const BoxSpec& b) {
  fom::Mesh m;
  m.dim = 3;
  m.body_names = {b.name};
  const int px = b.cells[0] + 1, py = b.cells[1] + 1, pz = b.cells[2] + 1;
  m.nodes.resize(3, px * py * pz);
  std::mt19937 rng(b.seed);
  std::uniform_real_distribution<double> u(-b.jitter, b.jitter);
  auto id = [&](int i, int j, int k) { return (k * py + j) * px + i; };
  for (int k = 0; k < pz; ++k)
    for (int j = 0; j < py; ++j)
      for (int i = 0; i < px; ++i) {
        const bool inner = i > 0 && j > 0 && k > 0 && i < px - 1 && j < py - 1 && k < pz - 1;
        Eigen::Vector3d x(double(i) / b.cells[0], double(j) / b.cells[1], double(k) / b.cells[2]);
        if (inner) x += Eigen::Vector3d(u(rng) / b.cells[0], u(rng) / b.cells[1], u(rng) / b.cells[2]);
        m.nodes.col(id(i, j, k)) = b.origin + x.cwiseProduct(b.size);
      }
  const int split[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  for (int k = 0; k + 1 < pz; ++k)
    for (int j = 0; j + 1 < py; ++j)
      for (int i = 0; i + 1 < px; ++i) {
        const std::array<int, 8> h = {id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
                                      id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
        if (!b.tets) {
          m.cells.push_back(h);
          m.cell_body.push_back(0);
          continue;
        }
        for (const auto& t : split) {
          std::array<int, 8> c = {h[t[0]], h[t[1]], h[t[2]], h[t[3]], -1, -1, -1, -1};
          const Eigen::Vector3d a = m.nodes.col(c[1]) - m.nodes.col(c[0]), bb = m.nodes.col(c[2]) - m.nodes.col(c[0]),
                                d = m.nodes.col(c[3]) - m.nodes.col(c[0]);
          if (a.cross(bb).dot(d) < 0) std::swap(c[1], c[2]);
          m.cells.push_back(c);
          m.cell_body.push_back(0);
        }
      }
  // Sides: quads (hexahedra) or the two triangles of the tetrahedra's split, outward.
  auto side = [&](const std::string& name, int axis, int at, bool outward_positive) {
    auto& facets = m.faces[name];
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const int n1 = b.cells[static_cast<size_t>(a1)], n2 = b.cells[static_cast<size_t>(a2)];
    auto node = [&](int s, int t) {
      std::array<int, 3> ijk{};
      ijk[static_cast<size_t>(axis)] = at, ijk[static_cast<size_t>(a1)] = s, ijk[static_cast<size_t>(a2)] = t;
      return id(ijk[0], ijk[1], ijk[2]);
    };
    for (int s = 0; s < n1; ++s)
      for (int t = 0; t < n2; ++t) {
        // (a1, a2, axis) is right-handed: s, s+1 then t+1 runs counter-clockwise seen from +axis.
        std::array<int, 4> q = {node(s, t), node(s + 1, t), node(s + 1, t + 1), node(s, t + 1)};
        if (!outward_positive) std::swap(q[1], q[3]);
        if (!b.tets) {
          facets.push_back(q);
          continue;
        }
        // The tetrahedra split every side along the diagonal through the node with the
        // smallest (i, j, k): in the grid, that of (s, t) and (s+1, t+1).
        facets.push_back({q[0], q[1], q[2], -1});
        facets.push_back({q[0], q[2], q[3], -1});
      }
    std::vector<int>& nodes = m.curve_nodes[name];
    for (const auto& f : facets)
      for (int v : f)
        if (v >= 0) nodes.push_back(v);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  };
  side("x0", 0, 0, false), side("x1", 0, b.cells[0], true);
  side("y0", 1, 0, false), side("y1", 1, b.cells[1], true);
  side("bottom", 2, 0, false), side("top", 2, b.cells[2], true);
  return m;
}

/// The boxes as the bodies of one mesh (distinct nodes); group G of box B is "B_G".
inline fom::Mesh union_of(const std::vector<fom::Mesh>& parts) {
  fom::Mesh m;
  m.dim = 3;
  int total = 0;
  for (const auto& p : parts) total += p.num_nodes();
  m.nodes.resize(3, total);
  int offset = 0;
  for (size_t b = 0; b < parts.size(); ++b) {
    const fom::Mesh& p = parts[b];
    m.nodes.middleCols(offset, p.num_nodes()) = p.nodes;
    m.body_names.push_back(p.body_names[0]);
    for (auto c : p.cells) {
      for (int& v : c)
        if (v >= 0) v += offset;
      m.cells.push_back(c);
      m.cell_body.push_back(static_cast<int>(b));
    }
    for (const auto& [name, facets] : p.faces) {
      auto& out = m.faces[p.body_names[0] + "_" + name];
      for (auto f : facets) {
        for (int& v : f)
          if (v >= 0) v += offset;
        out.push_back(f);
      }
    }
    for (const auto& [name, nodes] : p.curve_nodes) {
      auto& out = m.curve_nodes[p.body_names[0] + "_" + name];
      for (int v : nodes) out.push_back(v + offset);
    }
    offset += p.num_nodes();
  }
  return m;
}

}  // namespace contactrom::test
