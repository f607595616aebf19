#include <contactrom/fom/contact_checks.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_model.hpp>

namespace contactrom::fom {
namespace {

/// Per pair, in the reference configuration.
struct PairAtRest {
  std::string slave, master;
  int rows = 0, paired = 0, unpaired_near = 0;
  int facing = 0;  ///< paired slave nodes whose outward normal opposes the master's
  double overlap = 0.0;  ///< largest penetration of a paired slave node (length)
  int dim = 2;
};

/// "curve" (2D) or "surface" (3D).
std::string boundary_word(const PairAtRest& p) { return p.dim == 3 ? "surface" : "curve"; }

/// Mean length of the master's segments (2D) or of its facets' edges (3D).
double mean_master_length(const Mesh& mesh, const std::string& master) {
  double sum = 0.0;
  size_t n = 0;
  if (mesh.dim == 3) {
    const auto it = mesh.faces.find(master);
    if (it == mesh.faces.end()) return 0.0;
    for (const auto& facet : it->second) {
      const int k = facet[3] < 0 ? 3 : 4;
      for (int e = 0; e < k; ++e, ++n) sum += (mesh.nodes.col(facet[(e + 1) % k]) - mesh.nodes.col(facet[e])).norm();
    }
  } else {
    for (const auto& seg : mesh.group_segments(master)) {
      sum += (mesh.nodes.col(seg[1]) - mesh.nodes.col(seg[0])).norm();
      ++n;
    }
  }
  return sum / static_cast<double>(std::max<size_t>(n, 1));
}

/// Outward unit normals (dim x nodes; zero off the group) of the boundary group
/// `name` at its nodes, each segment's or facet's averaged per node. The mesh orients
/// them: 2D chains run with their body on the left, so (t_y, −t_x) points out of it
/// (as the contact model's master normals); 3D facets are counter-clockwise seen from
/// outside.
Eigen::MatrixXd outward_normals(const Mesh& mesh, const std::string& name) {
  const int d = mesh.dim;
  Eigen::MatrixXd normals = Eigen::MatrixXd::Zero(d, mesh.num_nodes());
  const auto point = [&](int node) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    x.head(d) = mesh.nodes.col(node);
    return x;
  };
  const auto add = [&](const int* nodes, int count, Eigen::Vector3d n) {
    if (n.norm() > 0.0) n.normalize();
    for (int a = 0; a < count; ++a) normals.col(nodes[a]) += n.head(d);
  };
  if (d == 3) {
    const auto it = mesh.faces.find(name);
    if (it != mesh.faces.end())
      for (const auto& f : it->second)
        add(f.data(), f[3] < 0 ? 3 : 4, (point(f[1]) - point(f[0])).cross(point(f[2]) - point(f[0])));
  } else if (mesh.segments.count(name)) {
    for (const auto& seg : mesh.group_segments(name)) {
      const Eigen::Vector3d t = point(seg[1]) - point(seg[0]);
      add(seg.data(), 2, Eigen::Vector3d(t.y(), -t.x(), 0.0));
    }
  }
  for (int j = 0; j < normals.cols(); ++j)
    if (normals.col(j).norm() > 0.0) normals.col(j).normalize();
  return normals;
}

std::vector<PairAtRest> pairs_at_rest(const Problem& problem) {
  std::vector<PairAtRest> out;
  const ContactModel& contact = problem.contact();
  const Mesh* mesh = problem.mesh();
  if (!contact.has_pairing() || !mesh) return out;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(contact.surface_dofs().size()));
  const Pairing pairing = contact.search(zero);
  ConstraintMatrix c;
  Eigen::VectorXd g;
  contact.assemble(pairing, c, g);
  const std::vector<ContactPairSpec>& specs = problem.definition().contact;
  out.resize(specs.size());
  // "Near" a master: within its mean segment (2D) or facet edge (3D) length (a node
  // just beyond an edge, as where two surfaces of different sizes meet), per pair.
  std::vector<double> reach(specs.size(), 0.0);
  std::vector<Eigen::MatrixXd> slave_normals(specs.size());
  for (size_t q = 0; q < specs.size(); ++q) {
    out[q].slave = specs[q].slave, out[q].master = specs[q].master, out[q].dim = mesh->dim;
    reach[q] = mean_master_length(*mesh, specs[q].master);
    slave_normals[q] = outward_normals(*mesh, specs[q].slave);
  }
  for (int s = 0; s < contact.num_constraints(); ++s) {
    const size_t q = static_cast<size_t>(contact.pair_of_row(s));
    if (q >= out.size()) continue;
    PairAtRest& pair = out[q];
    ++pair.rows;
    if (pairing.segment[static_cast<size_t>(s)] >= 0) {
      ++pair.paired;
      pair.overlap = std::max(pair.overlap, -g(s) / contact.weights()(s));
      const int node = contact.slave_node(s);
      if (node >= 0 && slave_normals[q].col(node).dot(pairing.normal.col(s)) < 0.0) ++pair.facing;
      continue;
    }
    // Unpaired: near the master (one of its nodes within reach)?
    const Eigen::VectorXd x = contact.constraint_points().col(s);
    double nearest = HUGE_VAL;
    for (int node : mesh->group_nodes(pair.master)) nearest = std::min(nearest, (mesh->nodes.col(node) - x).norm());
    if (nearest <= reach[q]) ++pair.unpaired_near;
  }
  return out;
}

/// A length for a message, to 3 significant digits (0.05, not 0.04999999999999999).
std::string length_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string pair_name(size_t q, const PairAtRest& p) {
  return "contact pair " + std::to_string(q) + " (slave " + quoted(p.slave, 200) + " on master " + quoted(p.master, 200) +
         ")";
}

/// Whether `u` turns element e inside out: a corner whose Jacobian determinant
/// (2D: the cross product of its two edges; hexahedron: the triple product of its
/// three edges; tetrahedron: the volume) changes sign from the reference one.
bool inverted(const Mesh& mesh, const Eigen::VectorXd& u, int e) {
  const std::vector<int> nodes = mesh.element_nodes(e);
  const int d = mesh.dim, k = static_cast<int>(nodes.size());
  const auto at = [&](int i, bool deformed) -> Eigen::Vector3d {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    const int n = nodes[static_cast<size_t>(i)];
    x.head(d) = mesh.nodes.col(n);
    if (deformed) x.head(d) += u.segment(d * n, d);
    return x;
  };
  // The edges from each corner, as corner, first, second[, third] node.
  static constexpr int kQuad[4][3] = {{0, 1, 3}, {1, 2, 0}, {2, 3, 1}, {3, 0, 2}};
  static constexpr int kHex[8][4] = {{0, 1, 3, 4}, {1, 2, 0, 5}, {2, 3, 1, 6}, {3, 0, 2, 7},
                                     {4, 7, 5, 0}, {5, 4, 6, 1}, {6, 5, 7, 2}, {7, 6, 4, 3}};
  static constexpr int kTet[1][4] = {{0, 1, 2, 3}};
  const auto det = [&](const int* c, bool deformed) {
    const Eigen::Vector3d o = at(c[0], deformed), a = at(c[1], deformed) - o, b = at(c[2], deformed) - o;
    if (d == 2) return a.x() * b.y() - a.y() * b.x();
    return a.cross(b).dot(at(c[3], deformed) - o);
  };
  const auto flips = [&](const auto& corners, int count) {
    for (int i = 0; i < count; ++i)
      if (det(corners[i], true) * det(corners[i], false) <= 0.0) return true;
    return false;
  };
  if (d == 2) return flips(kQuad, 4);
  return k == 8 ? flips(kHex, 8) : flips(kTet, 1);
}

}  // namespace

std::vector<std::string> solution_warnings(const Problem& problem, const Eigen::VectorXd& u) {
  std::vector<std::string> out;
  const Mesh* mesh = problem.mesh();
  if (!mesh || u.size() != problem.num_dofs()) return out;
  std::vector<int> count(mesh->body_names.size(), 0), total(mesh->body_names.size(), 0);
  for (int e = 0; e < mesh->num_elements(); ++e) {
    const size_t b = static_cast<size_t>(mesh->element_body(e));
    if (b >= count.size()) continue;
    ++total[b];
    if (inverted(*mesh, u, e)) ++count[b];
  }
  for (size_t b = 0; b < count.size(); ++b)
    if (count[b] > 0)
      out.push_back("the solution turns " + std::to_string(count[b]) + " of the " + std::to_string(total[b]) +
                    " elements of body " + quoted(mesh->body_names[b], 200) +
                    " inside out: far beyond the small-strain model, and the bodies may have passed through each"
                    " other where the contact search cannot see it; expected displacements small against the"
                    " bodies");
  return out;
}

namespace {

/// A default U (no `displacement_scale` in the file) far above some prescribed
/// displacement: the largest is likely a slide, and the residuals and statuses
/// relative to it are then too lenient for the indentation. Empty otherwise.
std::string default_scale_warning(const Problem& problem) {
  const ProblemDefinition& def = problem.definition();
  if (def.displacement_scale > 0.0) return "";
  double largest = 0.0, smallest = std::numeric_limits<double>::infinity();
  std::string where;
  for (const PrescribedDisplacement& p : prescribed_displacements(def)) {
    if (!(p.magnitude > 0.0)) continue;  // a fixed component is no displacement scale
    smallest = std::min(smallest, p.magnitude);
    if (p.magnitude > largest)
      largest = p.magnitude, where = "group " + quoted(p.group, 200) + ", component " + "xyz"[p.component];
  }
  constexpr double kRatio = 5.0;
  if (!(largest >= kRatio * smallest)) return "";
  return "displacement_scale is not set, so U = " + format_number(largest) +
         ", the largest prescribed displacement (" + where + "), " + format_number(std::round(10.0 * largest / smallest) / 10.0) +
         " times the smallest nonzero one (" + format_number(smallest) +
         "); penetration, complementarity and the reduced answers' statuses are relative to U, so a slide makes them "
         "lenient: expected displacement_scale set to the indentation in the problem file";
}

}  // namespace

std::vector<std::string> reference_contact_warnings(const Problem& problem) {
  std::vector<std::string> out;
  if (std::string w = default_scale_warning(problem); !w.empty()) out.push_back(std::move(w));
  const std::vector<PairAtRest> pairs = pairs_at_rest(problem);
  const double u = problem.displacement_scale();
  for (size_t q = 0; q < pairs.size(); ++q) {
    const PairAtRest& p = pairs[q];
    if (p.overlap > kReferenceOverlapFraction * u)
      out.push_back(pair_name(q, p) + " overlaps by " + length_text(p.overlap) +
                    " in the reference configuration, more than " + format_number(kReferenceOverlapFraction) +
                    " of the displacement scale U = " + format_number(u) +
                    "; expected surfaces that touch or are apart before loading");
    if (p.unpaired_near > 0)
      out.push_back(pair_name(q, p) + ": " + std::to_string(p.unpaired_near) + " of its " + std::to_string(p.rows) +
                    " slave nodes lie just beyond the " + (p.dim == 3 ? "edges of the master surface (within one"
                    " facet edge" : "ends of the master curve (within one master segment") + " of it) and are not paired,"
                    " so no pressure acts there; expected a master " + boundary_word(p) + " that covers the slave " +
                    boundary_word(p));
  }
  return out;
}

void check_contact_pairs_face(const Problem& problem) {
  const std::vector<PairAtRest> pairs = pairs_at_rest(problem);
  for (size_t q = 0; q < pairs.size(); ++q) {
    if (pairs[q].rows > 0 && pairs[q].paired == 0)
      throw InputError(pair_name(q, pairs[q]) + " has no slave node facing its master " + boundary_word(pairs[q]) +
                       " in the reference configuration, so none is ever paired; expected " + boundary_word(pairs[q]) +
                       "s that face each other");
    if (pairs[q].paired > 0 && pairs[q].facing == 0)
      throw InputError(pair_name(q, pairs[q]) + ": at each of its " + std::to_string(pairs[q].paired) +
                       " paired slave nodes the slave " + boundary_word(pairs[q]) + "'s outward normal points the"
                       " same way as the master's, so the slave faces away from the master and the bodies would pass"
                       " through each other unseen; expected the side of the slave body that meets the master");
  }
}

std::string solutions_warning(const Problem& problem, const std::vector<Param>& params,
                              const std::vector<std::vector<std::string>>& warnings, const std::string& what) {
  size_t first = warnings.size(), warned = 0;
  for (size_t i = 0; i < warnings.size(); ++i) {
    if (warnings[i].empty()) continue;
    if (warned++ == 0) first = i;
  }
  if (warned == 0 || first >= params.size()) return "";
  return std::to_string(warned) + " of the " + std::to_string(warnings.size()) + " " + what + " of " +
         quoted(problem.name(), 200) + " carry warnings; the first, at " + problem.parameters().text(params[first]) +
         ": " + warnings[first].front();
}

}  // namespace contactrom::fom
