#include <contactrom/fom/rigid_bodies.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>

namespace contactrom::fom {

std::vector<std::string> unheld_bodies(const Problem& problem) {
  std::vector<std::string> out;
  const Mesh* mesh = problem.mesh();
  if (!mesh) return out;
  const int dpn = problem.dofs_per_node();
  std::vector<char> held(mesh->body_names.size(), 0);
  for (int e = 0; e < mesh->num_elements(); ++e)
    for (int node : mesh->element_nodes(e))
      for (int d = 0; d < dpn; ++d)
        if (problem.is_dirichlet()[static_cast<size_t>(dpn * node + d)]) held[static_cast<size_t>(mesh->element_body(e))] = 1;
  for (size_t b = 0; b < held.size(); ++b)
    if (!held[b]) out.push_back(mesh->body_names[b]);
  return out;
}

namespace {

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

/// `v` with 6 significant digits (a rotation centre computed from an eigenvector
/// carries its round-off: 0.9999999999999999 reads as 1).
std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

/// Plain words for the rigid motion v = (a, b, ω) (translation (a, b), rotation ω
/// per unit of `size` about `centre`).
std::string describe_motion(const Eigen::Vector3d& v, const Eigen::Vector2d& centre, double size) {
  const double a = v(0), b = v(1), w = v(2) / size;
  if (std::abs(v(2)) <= 1e-6 * v.norm()) {
    if (std::abs(b) <= 1e-6 * std::abs(a)) return "free to translate in x";
    if (std::abs(a) <= 1e-6 * std::abs(b)) return "free to translate in y";
    return "free to translate along (" + short_number(a / std::hypot(a, b)) + ", " +
           short_number(b / std::hypot(a, b)) + ")";
  }
  // Velocity t + ω e_z × (x − c) vanishes at x = c + (−b, a)/ω.
  // (A translation component far smaller than the rotation's leaves round-off only.)
  const double scale = size * 1e-9;
  const double px = centre.x() - b / w, py = centre.y() + a / w;
  return "free to rotate about (" + short_number(std::abs(px) < scale ? 0.0 : px) + ", " +
         short_number(std::abs(py) < scale ? 0.0 : py) + ")";
}

}  // namespace

std::vector<FreeRigidMotion> free_rigid_motions(const Problem& problem, double relative_tolerance) {
  std::vector<FreeRigidMotion> out;
  const Mesh* mesh = problem.mesh();
  if (!mesh || problem.dofs_per_node() != 2) return out;
  // Connected pieces: nodes linked by an element.
  const int nn = mesh->num_nodes();
  std::vector<int> parent(static_cast<size_t>(nn));
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& quad : mesh->quads)
    for (int k = 1; k < 4; ++k) parent[find_root(parent, quad[k])] = find_root(parent, quad[0]);
  std::vector<int> piece_of(static_cast<size_t>(nn), -1), roots;
  std::vector<char> in_element(static_cast<size_t>(nn), 0);
  for (const auto& quad : mesh->quads)
    for (int node : quad) in_element[node] = 1;
  for (int i = 0; i < nn; ++i) {
    if (!in_element[i]) continue;
    const int r = find_root(parent, i);
    auto it = std::find(roots.begin(), roots.end(), r);
    piece_of[i] = static_cast<int>(it - roots.begin());
    if (it == roots.end()) roots.push_back(r);
  }
  const size_t np = roots.size();
  std::vector<std::vector<int>> bodies(np);
  for (int q = 0; q < mesh->num_quads(); ++q) {
    std::vector<int>& b = bodies[static_cast<size_t>(piece_of[mesh->quads[q][0]])];
    if (std::find(b.begin(), b.end(), mesh->quad_body[q]) == b.end()) b.push_back(mesh->quad_body[q]);
  }
  // Centre and size of each piece, then AᵀA from its Dirichlet dofs.
  std::vector<Eigen::Vector2d> lo(np, Eigen::Vector2d::Constant(HUGE_VAL)), hi(np, Eigen::Vector2d::Constant(-HUGE_VAL));
  for (int i = 0; i < nn; ++i)
    if (piece_of[i] >= 0) {
      lo[piece_of[i]] = lo[piece_of[i]].cwiseMin(mesh->nodes.col(i));
      hi[piece_of[i]] = hi[piece_of[i]].cwiseMax(mesh->nodes.col(i));
    }
  std::vector<Eigen::Matrix3d> ata(np, Eigen::Matrix3d::Zero());
  std::vector<int> rows(np, 0);
  for (int i = 0; i < nn; ++i) {
    const int p = piece_of[i];
    if (p < 0) continue;
    const Eigen::Vector2d c = 0.5 * (lo[p] + hi[p]);
    const double size = std::max((hi[p] - lo[p]).norm(), 1e-300);
    const Eigen::Vector2d x = (mesh->nodes.col(i) - c) / size;
    for (int d = 0; d < 2; ++d) {
      if (!problem.is_dirichlet()[2 * i + d]) continue;
      const Eigen::Vector3d row = d == 0 ? Eigen::Vector3d(1.0, 0.0, -x.y()) : Eigen::Vector3d(0.0, 1.0, x.x());
      ata[p] += row * row.transpose();
      ++rows[p];
    }
  }
  for (size_t p = 0; p < np; ++p) {
    std::string names;
    for (size_t k = 0; k < bodies[p].size(); ++k) names += (k ? "+'" : "'") + mesh->body_names[bodies[p][k]] + "'";
    if (rows[p] == 0) {
      out.push_back({names, "held by no Dirichlet condition (free to move rigidly)"});
      continue;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(ata[p]);
    const Eigen::Vector3d& ev = eig.eigenvalues();  // ascending
    const Eigen::Vector2d c = 0.5 * (lo[p] + hi[p]);
    const double size = std::max((hi[p] - lo[p]).norm(), 1e-300);
    int free = 0;
    while (free < 3 && ev(free) <= relative_tolerance * ev(2)) ++free;
    if (free == 0) continue;
    Eigen::MatrixXd kernel = eig.eigenvectors().leftCols(free);
    if (free == 2) {  // a pure translation lies in a 2D null space: report it and its complement
      Eigen::Vector3d t = kernel * Eigen::Vector2d(kernel(2, 1), -kernel(2, 0));
      if (t.norm() > 0.0) {
        t.normalize();
        Eigen::Vector3d r = kernel.col(0) - t.dot(kernel.col(0)) * t;
        if (r.norm() < 1e-8) r = kernel.col(1) - t.dot(kernel.col(1)) * t;
        kernel.col(0) = t, kernel.col(1) = r.normalized();
      }
    }
    for (int k = 0; k < free; ++k) out.push_back({names, describe_motion(kernel.col(k), c, size)});
  }
  return out;
}

void check_rigid_motions_held(const Problem& problem) {
  if (!unheld_bodies(problem).empty()) throw InputError(singular_stiffness_message(problem));
  const std::vector<FreeRigidMotion> free = free_rigid_motions(problem);
  if (free.empty()) return;
  std::string what;
  for (size_t k = 0; k < free.size(); ++k) {
    if (k == 0 || free[k].body != free[k - 1].body) what += std::string(k ? "; " : "") + "body " + free[k].body + " is";
    else what += " and";
    what += " " + free[k].motion;
  }
  throw InputError("the stiffness of problem " + quoted(problem.name(), 200) + " is singular: " + what +
                   " (no Dirichlet condition stops that rigid motion, and contact cannot hold it); expected"
                   " Dirichlet conditions that stop every rigid motion of each body");
}

std::string singular_stiffness_message(const Problem& problem) {
  const std::vector<std::string> free = unheld_bodies(problem);
  std::string message = "the stiffness of problem " + quoted(problem.name(), 200) + " is singular";
  if (free.empty())
    return message + " (Cholesky factorisation failed); expected every body held by enough Dirichlet conditions to stop"
                     " its rigid motions";
  std::string names;
  for (size_t i = 0; i < free.size(); ++i) names += (i ? ", '" : "'") + free[i] + "'";
  return message + ": " + (free.size() == 1 ? "body " : "bodies ") + names +
         (free.size() == 1 ? " is" : " are") +
         " held by no Dirichlet condition (free to move rigidly); expected every body to have clamped or"
         " prescribed boundary nodes";
}

}  // namespace contactrom::fom
