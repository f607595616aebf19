#include <contactrom/fom/rigid_bodies.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
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

/// Plain words for a free motion of a 3D piece, (t, ω) with the rotation ω per unit
/// of `size` about `centre`: a translation, or a rotation about an axis (the points
/// where the velocity t + ω × (x − c) is parallel to ω; a pitch along it is dropped).
std::string describe_motion_3d(const Eigen::Matrix<double, 6, 1>& v, const Eigen::Vector3d& centre, double size) {
  const Eigen::Vector3d t = v.head<3>(), w = v.tail<3>() / size;
  const auto direction = [](const Eigen::Vector3d& d) {
    const Eigen::Vector3d u = d.normalized();
    const char* names[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k)
      if (std::abs(std::abs(u(k)) - 1.0) <= 1e-6) return std::string(names[k]);
    return "(" + short_number(u(0)) + ", " + short_number(u(1)) + ", " + short_number(u(2)) + ")";
  };
  if (v.tail<3>().norm() <= 1e-6 * v.norm()) {
    const std::string d = direction(t);
    return "free to translate " + std::string(d.front() == '(' ? "along " : "in ") + d;
  }
  const Eigen::Vector3d p = centre + w.cross(t) / w.squaredNorm();
  const double scale = size * 1e-9;
  const std::string axis = direction(w);
  return "free to rotate about the axis " + std::string(axis.front() == '(' ? "along " : "parallel to ") + axis +
         " through (" + short_number(std::abs(p(0)) < scale ? 0.0 : p(0)) + ", " +
         short_number(std::abs(p(1)) < scale ? 0.0 : p(1)) + ", " + short_number(std::abs(p(2)) < scale ? 0.0 : p(2)) +
         ")";
}

/// The component along Dirichlet dof d of the rigid motions of a node at the centred,
/// scaled position x: 2D (t_x, t_y, ω), 3D (t_x, t_y, t_z, ω_x, ω_y, ω_z).
Eigen::VectorXd rigid_row(int dim, int d, const Eigen::VectorXd& x) {
  if (dim == 2) return d == 0 ? Eigen::Vector3d(1.0, 0.0, -x(1)) : Eigen::Vector3d(0.0, 1.0, x(0));
  Eigen::VectorXd row = Eigen::VectorXd::Zero(6);
  row(d) = 1.0;
  // (ω × x)_d
  if (d == 0) row(4) = x(2), row(5) = -x(1);
  if (d == 1) row(3) = -x(2), row(5) = x(0);
  if (d == 2) row(3) = x(1), row(4) = -x(0);
  return row;
}

/// The free motions of a 3D piece with null space `kernel` (6 x f): the free
/// translations first (the combinations without rotation), then rotations.
std::vector<std::string> describe_kernel_3d(const Eigen::MatrixXd& kernel, const Eigen::Vector3d& centre, double size) {
  const Eigen::Index f = kernel.cols();
  // Combinations c with no rotation part: the null space of the rotation rows.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(kernel.bottomRows(3), Eigen::ComputeFullV);
  Eigen::Index rank = 0;
  for (Eigen::Index k = 0; k < svd.singularValues().size(); ++k)
    if (svd.singularValues()(k) > 1e-8) ++rank;
  const Eigen::MatrixXd v = svd.matrixV();
  Eigen::MatrixXd basis(6, f);
  basis.leftCols(f - rank) = kernel * v.rightCols(f - rank);  // translations
  basis.rightCols(rank) = kernel * v.leftCols(rank);          // rotations (orthogonal to them)
  // Free translations along coordinate axes are named as such: all three, or the
  // two of a coordinate plane.
  const Eigen::Index nt = f - rank;
  if (nt == 3) basis.leftCols(3) = Eigen::MatrixXd::Identity(6, 3);
  if (nt == 2) {
    const Eigen::Vector3d normal = Eigen::Vector3d(basis.col(0).head<3>()).cross(Eigen::Vector3d(basis.col(1).head<3>()));
    for (int k = 0; k < 3; ++k)
      if (std::abs(std::abs(normal.normalized()(k)) - 1.0) <= 1e-9) {
        basis.leftCols(2).setZero();
        basis((k + 1) % 3, 0) = 1.0, basis((k + 2) % 3, 1) = 1.0;
        if (basis(0, 1) == 1.0 && basis(1, 0) == 1.0) basis.col(0).swap(basis.col(1));  // x before y
      }
  }
  std::vector<std::string> out;
  for (Eigen::Index k = 0; k < f; ++k) out.push_back(describe_motion_3d(basis.col(k), centre, size));
  return out;
}

}  // namespace

std::vector<FreeRigidMotion> free_rigid_motions(const Problem& problem, double relative_tolerance) {
  std::vector<FreeRigidMotion> out;
  const Mesh* mesh = problem.mesh();
  const int dim = mesh ? mesh->dim : 0;
  if (!mesh || (dim != 2 && dim != 3) || problem.dofs_per_node() != dim) return out;
  const int modes = dim == 2 ? 3 : 6;
  // Connected pieces: nodes linked by an element.
  const int nn = mesh->num_nodes(), ne = mesh->num_elements();
  std::vector<int> parent(static_cast<size_t>(nn));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<char> in_element(static_cast<size_t>(nn), 0);
  for (int e = 0; e < ne; ++e) {
    const std::vector<int> nodes = mesh->element_nodes(e);
    for (size_t k = 0; k < nodes.size(); ++k) {
      in_element[nodes[k]] = 1;
      if (k > 0) parent[find_root(parent, nodes[k])] = find_root(parent, nodes[0]);
    }
  }
  std::vector<int> piece_of(static_cast<size_t>(nn), -1), roots;
  for (int i = 0; i < nn; ++i) {
    if (!in_element[i]) continue;
    const int r = find_root(parent, i);
    auto it = std::find(roots.begin(), roots.end(), r);
    piece_of[i] = static_cast<int>(it - roots.begin());
    if (it == roots.end()) roots.push_back(r);
  }
  const size_t np = roots.size();
  std::vector<std::vector<int>> bodies(np);
  for (int e = 0; e < ne; ++e) {
    std::vector<int>& b = bodies[static_cast<size_t>(piece_of[mesh->element_nodes(e)[0]])];
    if (std::find(b.begin(), b.end(), mesh->element_body(e)) == b.end()) b.push_back(mesh->element_body(e));
  }
  // Centre and size of each piece, then AᵀA from its Dirichlet dofs.
  std::vector<Eigen::VectorXd> lo(np, Eigen::VectorXd::Constant(dim, HUGE_VAL)),
      hi(np, Eigen::VectorXd::Constant(dim, -HUGE_VAL));
  for (int i = 0; i < nn; ++i)
    if (piece_of[i] >= 0) {
      lo[piece_of[i]] = lo[piece_of[i]].cwiseMin(mesh->nodes.col(i));
      hi[piece_of[i]] = hi[piece_of[i]].cwiseMax(mesh->nodes.col(i));
    }
  std::vector<Eigen::MatrixXd> ata(np, Eigen::MatrixXd::Zero(modes, modes));
  std::vector<int> rows(np, 0);
  for (int i = 0; i < nn; ++i) {
    const int p = piece_of[i];
    if (p < 0) continue;
    const Eigen::VectorXd c = 0.5 * (lo[p] + hi[p]);
    const double size = std::max((hi[p] - lo[p]).norm(), 1e-300);
    const Eigen::VectorXd x = (mesh->nodes.col(i) - c) / size;
    for (int d = 0; d < dim; ++d) {
      if (!problem.is_dirichlet()[static_cast<size_t>(dim * i + d)]) continue;
      const Eigen::VectorXd row = rigid_row(dim, d, x);
      ata[p] += row * row.transpose();
      ++rows[p];
    }
  }
  // A body meshed in several unconnected pieces: each piece is named by where it is.
  std::vector<int> pieces_of_body(mesh->body_names.size(), 0);
  for (const std::vector<int>& b : bodies)
    for (int body : b) ++pieces_of_body[static_cast<size_t>(body)];
  for (size_t p = 0; p < np; ++p) {
    const Eigen::VectorXd c = 0.5 * (lo[p] + hi[p]);  // the piece's centre
    std::string names;
    bool split = false;
    for (size_t k = 0; k < bodies[p].size(); ++k) {
      names += (k ? "+'" : "'") + mesh->body_names[bodies[p][k]] + "'";
      split = split || pieces_of_body[static_cast<size_t>(bodies[p][k])] > 1;
    }
    if (split) {
      std::string at;
      for (int d = 0; d < dim; ++d) at += (d ? ", " : "") + format_number(std::round(c(d) * 1e6) / 1e6);
      names += " (its piece around (" + at + "), not connected to the rest of it)";
    }
    if (rows[p] == 0) {
      out.push_back({names, "held by no Dirichlet condition (free to move rigidly)"});
      continue;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(ata[p]);
    const Eigen::VectorXd& ev = eig.eigenvalues();  // ascending
    const double size = std::max((hi[p] - lo[p]).norm(), 1e-300);
    int free = 0;
    while (free < modes && ev(free) <= relative_tolerance * ev(modes - 1)) ++free;
    if (free == 0) continue;
    Eigen::MatrixXd kernel = eig.eigenvectors().leftCols(free);
    if (dim == 3) {
      for (const std::string& m : describe_kernel_3d(kernel, Eigen::Vector3d(c), size)) out.push_back({names, m});
      continue;
    }
    if (free == 2) {  // a pure translation lies in a 2D null space: report it and its complement
      Eigen::Vector3d t = kernel * Eigen::Vector2d(kernel(2, 1), -kernel(2, 0));
      if (t.norm() > 0.0) {
        t.normalize();
        Eigen::Vector3d r = kernel.col(0) - t.dot(kernel.col(0)) * t;
        if (r.norm() < 1e-8) r = kernel.col(1) - t.dot(kernel.col(1)) * t;
        kernel.col(0) = t, kernel.col(1) = r.normalized();
      }
    }
    for (int k = 0; k < free; ++k) out.push_back({names, describe_motion(Eigen::Vector3d(kernel.col(k)), Eigen::Vector2d(c), size)});
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
