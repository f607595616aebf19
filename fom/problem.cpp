#include <contactrom/fom/problem.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/fom/node_to_face_contact.hpp>
#include <contactrom/fom/rope.hpp>

namespace contactrom::fom {
namespace {

std::string point_text(const Mesh& mesh, int node) {
  std::ostringstream s;
  s << "(" << mesh.nodes(0, node);
  for (Eigen::Index i = 1; i < mesh.nodes.rows(); ++i) s << ", " << mesh.nodes(i, node);
  s << ")";
  return s.str();
}

std::string joined_keys(const std::map<std::string, std::vector<int>>& groups) {
  std::vector<std::string> names;
  for (const auto& group : groups) names.push_back(group.first);
  return join(names);
}

/// Affine terms: index 0 is the constant, index 1+i the coefficient of parameter i.
/// A term whose vectors are all zero is dropped by the caller.
struct AffineVectors {
  std::vector<Eigen::VectorXd> terms;  // 1 + num_params vectors
  AffineVectors(int num_params, int n) : terms(static_cast<size_t>(num_params + 1), Eigen::VectorXd::Zero(n)) {}
  void add(int dof, const AffineExpression& e, double factor = 1.0) {
    terms[0](dof) += factor * e.constant;
    for (int i = 0; i < e.coefficients.size(); ++i) terms[static_cast<size_t>(i + 1)](dof) += factor * e.coefficients(i);
  }
};

/// Builds a problem from its definition and mesh (see build_problem).
class Builder {
 public:
  Builder(const ProblemDefinition& def, const Mesh& mesh) : m_def(def), m_mesh(mesh) {}

  /// The formulation and the mesh agree on the dimension.
  void check_dimension() {
    if (m_def.dimension == m_mesh.dim) return;
    throw InputError(m_def.where(m_def.formulation_where) + ": the problem is " +
                     (m_def.dimension == 3 ? "3D (formulation = \"3d\")" : "2D") + " but the mesh '" + m_def.mesh +
                     "' is " + (m_mesh.dim == 3 ? "3D (physical volumes)" : "2D (physical surfaces of quads)") +
                     "; expected " + (m_mesh.dim == 3 ? "formulation = \"3d\"" : "a 2D formulation") +
                     " for this mesh");
  }

  void check_bodies() {
    const std::string kind = m_mesh.dim == 3 ? "physical volume" : "physical surface";
    for (const BodySpec& b : m_def.bodies)
      if (body_index(b.group) < 0)
        throw InputError(m_def.where(b.where) + ": the mesh has no " + kind + " '" + b.group +
                         "'; expected one of: " + body_list());
    for (const std::string& body : m_mesh.body_names) {
      bool listed = false;
      for (const BodySpec& b : m_def.bodies) listed = listed || b.group == body;
      if (!listed)
        throw InputError(m_def.where({0, "bodies"}) + ": the mesh's " + kind + " '" + body +
                         "' has no [[bodies]] entry; expected every " + (m_mesh.dim == 3 ? "volume" : "surface") +
                         " of " + quoted(m_def.mesh, 200) + " listed");
    }
  }

  /// Material terms: K_q assembled with E = the q-th affine coefficient of each body.
  void assemble_stiffness_terms(std::vector<SparseMatrix>& terms, std::vector<AffineExpression>& coeffs) const {
    const int np = m_def.parameters.size();
    for (int q = 0; q <= np; ++q) {
      std::vector<Material> mats(m_mesh.body_names.size());
      bool any = false;
      for (const BodySpec& b : m_def.bodies) {
        Material& m = mats[static_cast<size_t>(body_index(b.group))];
        m.young = q == 0 ? b.young.constant : b.young.coefficients(q - 1);
        m.poisson = b.poisson;
        m.plane_stress = m_def.plane_stress;
        any = any || m.young != 0.0;
      }
      if (!any) continue;
      terms.push_back(assemble_stiffness(m_mesh, mats));
      AffineExpression theta = AffineExpression::constant_value(q == 0 ? 1.0 : 0.0, np);
      if (q > 0) theta.coefficients(q - 1) = 1.0;
      coeffs.push_back(theta);
    }
  }

  /// Dirichlet dofs and lifting; refuses two groups that prescribe different values on a dof.
  void dirichlet(std::vector<char>& is_dirichlet, AffineVectors& lift) const {
    std::vector<int> owner(is_dirichlet.size(), -1);
    for (size_t s = 0; s < m_def.dirichlet.size(); ++s) {
      const DirichletSpec& d = m_def.dirichlet[s];
      const int dim = m_mesh.dim;
      for (int node : group_nodes(d.group, d.where, dim == 3 ? "physical surface, curve or point" : "physical curve or point")) {
        for (int c = 0; c < dim; ++c) {
          const auto& value = d.displacement[static_cast<size_t>(c)];
          if (!value) continue;
          const int dof = dim * node + c;
          if (owner[dof] >= 0) {
            const auto& other = *m_def.dirichlet[static_cast<size_t>(owner[dof])].displacement[static_cast<size_t>(c)];
            if (other.constant != value->constant || other.coefficients != value->coefficients)
              throw InputError(m_def.where(d.where) + ": prescribes another displacement than dirichlet[" +
                               std::to_string(owner[dof]) + "] at the shared node " + point_text(m_mesh, node) +
                               "; expected equal values where Dirichlet groups meet");
            continue;
          }
          owner[dof] = static_cast<int>(s);
          is_dirichlet[dof] = 1;
          lift.add(dof, *value);
        }
      }
    }
  }

  /// Consistent nodal forces of the tractions (force per unit length, linear elements).
  void tractions(AffineVectors& fext) const {
    if (m_mesh.dim == 3) return surface_tractions(fext);
    for (const TractionSpec& t : m_def.traction) {
      group_nodes(t.group, t.where, "physical curve");
      if (m_mesh.group_segments(t.group).empty())
        throw InputError(m_def.where(t.where) + ": " + quoted(t.group, 200) + " is a physical point; expected a physical curve");
      for (const auto& seg : m_mesh.group_segments(t.group)) {
        const double half = 0.5 * (m_mesh.nodes.col(seg[1]) - m_mesh.nodes.col(seg[0])).norm();
        for (int node : seg)
          for (int c = 0; c < 2; ++c) fext.add(2 * node + c, t.traction[static_cast<size_t>(c)], half);
      }
    }
  }

  /// 3D: consistent nodal forces ∫ N_a t dA of the tractions (force per unit area).
  void surface_tractions(AffineVectors& fext) const {
    for (const TractionSpec& t : m_def.traction) {
      group_nodes(t.group, t.where, "physical surface");
      if (m_mesh.faces.count(t.group) == 0)
        throw InputError(m_def.where(t.where) + ": '" + t.group + "' is not a physical surface; expected one");
      for (const auto& f : m_mesh.faces.at(t.group)) {
        const std::array<double, 4> area = facet_node_areas(m_mesh.nodes, f);
        for (int a = 0; a < 4 && f[static_cast<size_t>(a)] >= 0; ++a)
          for (int c = 0; c < 3; ++c)
            fext.add(3 * f[static_cast<size_t>(a)] + c, t.traction[static_cast<size_t>(c)], area[static_cast<size_t>(a)]);
      }
    }
  }

  /// 3D: node-to-face contact of the physical surfaces named by the pairs, which
  /// must be made of boundary facets (faces of one cell only).
  std::unique_ptr<ContactModel> face_contact() const {
    std::set<int> contact_nodes;
    for (const ContactPairSpec& c : m_def.contact)
      for (const std::string* name : {&c.slave, &c.master}) {
        group_nodes(*name, c.where_of(*name), "physical surface");
        if (m_mesh.faces.count(*name) == 0)
          throw InputError(m_def.where(c.where_of(*name)) + ": '" + *name + "' is not a physical surface with facets");
        for (const auto& f : m_mesh.faces.at(*name))
          for (int v : f)
            if (v >= 0) contact_nodes.insert(v);
      }
    // Faces of cells on the contact surfaces, counted by their sorted nodes.
    static const int tet_faces[4][4] = {{0, 2, 1, -1}, {0, 1, 3, -1}, {1, 2, 3, -1}, {0, 3, 2, -1}};
    static const int hex_faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    std::map<std::array<int, 4>, int> face_count;
    auto key = [](std::array<int, 4> f) {
      std::sort(f.begin(), f.end());  // −1 first for triangles
      return f;
    };
    for (const auto& cell : m_mesh.cells) {
      const bool tet = Mesh::cell_size(cell) == 4;
      for (int k = 0; k < (tet ? 4 : 6); ++k) {
        const int* local = tet ? tet_faces[k] : hex_faces[k];
        std::array<int, 4> f{-1, -1, -1, -1};
        bool on_surface = true;
        for (int a = 0; a < (tet ? 3 : 4); ++a) {
          f[static_cast<size_t>(a)] = cell[static_cast<size_t>(local[a])];
          on_surface = on_surface && contact_nodes.count(f[static_cast<size_t>(a)]) > 0;
        }
        if (on_surface) ++face_count[key(f)];
      }
    }
    std::vector<ContactPairFacets> pairs;
    for (const ContactPairSpec& c : m_def.contact) {
      ContactPairFacets facets;
      facets.slave = m_mesh.faces.at(c.slave);
      facets.master = m_mesh.faces.at(c.master);
      for (const std::string* name : {&c.slave, &c.master})
        for (const auto& f : m_mesh.faces.at(*name))
          if (face_count[key(f)] != 1)
            throw InputError(m_def.where(c.where_of(*name)) + ": the surface '" + *name + "' has the facet at " +
                             point_text(m_mesh, f[0]) +
                             " inside a body; expected a contact surface on the boundary of its body");
      pairs.push_back(std::move(facets));
    }
    try {
      return std::make_unique<NodeToFaceContact>(m_mesh.nodes, pairs);
    } catch (const InputError& e) {
      throw InputError(pair_error<NodeToFaceContact>(pairs, e));
    }
  }

  std::unique_ptr<ContactModel> contact() const {
    if (m_mesh.dim == 3) return face_contact();
    // Boundary edges: quad edges used once.
    std::map<std::pair<int, int>, int> edge_count;
    for (const auto& q : m_mesh.quads)
      for (int a = 0; a < 4; ++a) {
        const int i = q[a], j = q[(a + 1) % 4];
        ++edge_count[{std::min(i, j), std::max(i, j)}];
      }
    std::vector<ContactPairChains> pairs;
    for (const ContactPairSpec& c : m_def.contact) {
      ContactPairChains chains;
      chains.slave = group_nodes(c.slave, c.where, "physical curve");
      chains.master = group_nodes(c.master, c.where_master, "physical curve");
      for (const std::string* name : {&c.slave, &c.master}) {
        if (m_mesh.segments.count(*name) == 0 || m_mesh.segments.at(*name).empty())
          throw InputError(m_def.where(c.where_of(*name)) + ": '" + *name + "' is not a physical curve with segments");
        for (const auto& seg : m_mesh.segments.at(*name))
          if (edge_count[{std::min(seg[0], seg[1]), std::max(seg[0], seg[1])}] != 1)
            throw InputError(m_def.where(c.where_of(*name)) + ": the curve '" + *name + "' has the segment " +
                             point_text(m_mesh, seg[0]) + "-" + point_text(m_mesh, seg[1]) +
                             " inside a body; expected a contact curve on the boundary of its body");
      }
      pairs.push_back(std::move(chains));
    }
    try {
      return std::make_unique<NodeToSegmentContact>(m_mesh.nodes, pairs);
    } catch (const InputError& e) {
      throw InputError(pair_error<NodeToSegmentContact>(pairs, e));
    }
  }

 private:
  /// The message of a contact model that refused `pairs`: located at the first pair
  /// that the model refuses on its own, else at the `contact` tables together.
  template <class Model, class Pairs>
  std::string pair_error(const Pairs& pairs, const InputError& e) const {
    for (size_t i = 0; i < pairs.size(); ++i) {
      try {
        Model single(m_mesh.nodes, Pairs{pairs[i]});
      } catch (const InputError& one) {
        return m_def.where({m_def.contact[i].where.line, "contact[" + std::to_string(i) + "]"}) + ": " + one.what();
      }
    }
    return m_def.where({0, "contact"}) + ": " + e.what();
  }

  int body_index(const std::string& name) const {
    for (size_t b = 0; b < m_mesh.body_names.size(); ++b)
      if (m_mesh.body_names[b] == name) return static_cast<int>(b);
    return -1;
  }
  std::string body_list() const {
    std::string out;
    for (const auto& n : m_mesh.body_names) out += (out.empty() ? "" : ", ") + n;
    return out;
  }
  const std::vector<int>& group_nodes(const std::string& group, const SourceLocation& where, const char* kind) const {
    auto it = m_mesh.curve_nodes.find(group);
    if (it == m_mesh.curve_nodes.end())
      throw InputError(m_def.where(where) + ": the mesh has no " + kind + " " + quoted(group, 200) + "; expected one of: " +
                       joined_keys(m_mesh.curve_nodes));
    return it->second;
  }

  const ProblemDefinition& m_def;
  const Mesh& m_mesh;
};

/// Keeps the terms of `v` that are not all zero, with their coefficient functions.
void keep_nonzero_terms(const AffineVectors& lift, const AffineVectors& fext, int num_params,
                        std::vector<Eigen::VectorXd>& lift_terms, std::vector<Eigen::VectorXd>& fext_terms,
                        std::vector<AffineExpression>& coeffs) {
  for (size_t q = 0; q < lift.terms.size(); ++q) {
    if (lift.terms[q].cwiseAbs().maxCoeff() == 0.0 && fext.terms[q].cwiseAbs().maxCoeff() == 0.0) continue;
    lift_terms.push_back(lift.terms[q]);
    fext_terms.push_back(fext.terms[q]);
    AffineExpression phi = AffineExpression::constant_value(q == 0 ? 1.0 : 0.0, num_params);
    if (q > 0) phi.coefficients(static_cast<Eigen::Index>(q - 1)) = 1.0;
    coeffs.push_back(phi);
  }
}

/// U: the file's value, else the largest prescribed displacement over the box (1 if none).
double displacement_scale(const ProblemDefinition& def) {
  double scale = def.displacement_scale;
  if (!(scale > 0)) {
    for (const PrescribedDisplacement& p : prescribed_displacements(def)) scale = std::max(scale, p.magnitude);
    if (!(scale > 0)) scale = 1.0;
  }
  return scale;
}

}  // namespace

std::vector<PrescribedDisplacement> prescribed_displacements(const ProblemDefinition& def) {
  std::vector<PrescribedDisplacement> out;
  for (const DirichletSpec& d : def.dirichlet)
    for (size_t k = 0; k < d.displacement.size(); ++k)
      if (const auto& v = d.displacement[k])
        out.push_back({d.group, static_cast<int>(k),
                       std::max(std::abs(v->min_over(def.parameters)), std::abs(v->max_over(def.parameters)))});
  return out;
}

std::string text_fingerprint(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char ch : text) h = (h ^ ch) * 1099511628211ULL;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

Problem::Problem(ProblemParts parts)
    : m_definition(std::move(parts.definition)),
      m_dofs_per_node(parts.dofs_per_node),
      m_is_dirichlet(std::move(parts.is_dirichlet)),
      m_k_terms(std::move(parts.stiffness_terms)),
      m_k_coeff(std::move(parts.stiffness_coefficients)),
      m_load_coeff(std::move(parts.load_coefficients)),
      m_lift_terms(std::move(parts.lifting_terms)),
      m_fext_terms(std::move(parts.external_load_terms)),
      m_contact(std::move(parts.contact)),
      m_h1(std::move(parts.h1_gram)),
      m_mesh(std::move(parts.mesh)),
      m_fingerprint(std::move(parts.fingerprint)),
      m_u_scale(parts.displacement_scale) {
  check_sizes();
  for (int i = 0; i < num_dofs(); ++i)
    if (!m_is_dirichlet[i]) m_free_dofs.push_back(i);
  for (const SparseMatrix& k : m_k_terms) {
    Eigen::MatrixXd kl(num_dofs(), num_load_terms());
    for (int t = 0; t < num_load_terms(); ++t) kl.col(t) = k * m_lift_terms[static_cast<size_t>(t)];
    m_k_lift.push_back(std::move(kl));
  }
}

void Problem::check_sizes() const {
  const auto n = static_cast<Eigen::Index>(m_is_dirichlet.size());
  bool ok = m_contact && !m_k_terms.empty() && m_k_terms.size() == m_k_coeff.size() && !m_lift_terms.empty() &&
            m_lift_terms.size() == m_fext_terms.size() && m_lift_terms.size() == m_load_coeff.size() &&
            m_h1.rows() == n && m_h1.cols() == n && m_u_scale > 0.0;
  for (const SparseMatrix& k : m_k_terms) ok = ok && k.rows() == n && k.cols() == n;
  for (size_t t = 0; t < m_lift_terms.size() && ok; ++t) ok = m_lift_terms[t].size() == n && m_fext_terms[t].size() == n;
  if (!ok) throw std::invalid_argument("Problem: the parts of '" + name() + "' disagree in size");
}

Eigen::VectorXd Problem::stiffness_coefficients(const Param& mu) const {
  Eigen::VectorXd theta(num_stiffness_terms());
  for (int q = 0; q < theta.size(); ++q) theta(q) = m_k_coeff[static_cast<size_t>(q)](mu);
  return theta;
}

Eigen::VectorXd Problem::load_coefficients(const Param& mu) const {
  Eigen::VectorXd phi(num_load_terms());
  for (int k = 0; k < phi.size(); ++k) phi(k) = m_load_coeff[static_cast<size_t>(k)](mu);
  return phi;
}

std::vector<Material> Problem::materials(const Param& mu) const {
  std::vector<Material> out;
  if (!m_mesh) return out;
  out.resize(m_mesh->body_names.size());
  for (const BodySpec& b : m_definition.bodies)
    for (size_t i = 0; i < out.size(); ++i)
      if (m_mesh->body_names[i] == b.group)
        out[i] = Material{mu.size() == b.young.coefficients.size() ? b.young(mu) : b.young.constant, b.poisson,
                          m_definition.plane_stress};
  return out;
}

SparseMatrix Problem::stiffness(const Param& mu) const {
  const Eigen::VectorXd theta = stiffness_coefficients(mu);
  SparseMatrix k = theta(0) * m_k_terms[0];
  for (int q = 1; q < num_stiffness_terms(); ++q) k += theta(q) * m_k_terms[q];
  return k;
}

Eigen::VectorXd Problem::apply_stiffness(const Param& mu, const Eigen::VectorXd& v) const {
  const Eigen::VectorXd theta = stiffness_coefficients(mu);
  Eigen::VectorXd kv = m_k_terms[0] * v;
  if (theta(0) != 1.0) kv *= theta(0);
  for (int q = 1; q < num_stiffness_terms(); ++q) kv.noalias() += theta(q) * (m_k_terms[q] * v);
  return kv;
}

Eigen::VectorXd Problem::lifting(const Param& mu) const {
  const Eigen::VectorXd phi = load_coefficients(mu);
  Eigen::VectorXd l = Eigen::VectorXd::Zero(num_dofs());
  for (int k = 0; k < num_load_terms(); ++k) l += phi(k) * m_lift_terms[k];
  return l;
}

Eigen::VectorXd Problem::rhs(const Param& mu) const {
  const Eigen::VectorXd phi = load_coefficients(mu);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(num_dofs());
  for (int k = 0; k < num_load_terms(); ++k) f += phi(k) * m_fext_terms[k];
  const Eigen::VectorXd theta = stiffness_coefficients(mu);  // f −= K(μ) lifting(μ)
  for (int q = 0; q < num_stiffness_terms(); ++q) f.noalias() -= theta(q) * (m_k_lift[static_cast<size_t>(q)] * phi);
  for (int i = 0; i < num_dofs(); ++i)
    if (m_is_dirichlet[i]) f(i) = 0.0;
  return f;
}

SparseMatrix free_block(const SparseMatrix& k, const std::vector<int>& free_index, int num_free) {
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(k.nonZeros());
  for (int col = 0; col < k.outerSize(); ++col) {
    if (free_index[col] < 0) continue;
    for (SparseMatrix::InnerIterator it(k, col); it; ++it)
      if (free_index[it.row()] >= 0) trip.emplace_back(free_index[it.row()], free_index[col], it.value());
  }
  SparseMatrix kff(num_free, num_free);
  kff.setFromTriplets(trip.begin(), trip.end());
  return kff;
}

std::unique_ptr<Problem> build_problem(ProblemDefinition definition, Mesh mesh) {
  ProblemParts p;
  p.definition = std::move(definition);
  p.mesh = std::make_unique<Mesh>(std::move(mesh));
  const ProblemDefinition& def = p.definition;
  const Mesh& m = *p.mesh;
  const int n = m.dim * m.num_nodes(), np = def.parameters.size();
  p.dofs_per_node = m.dim;
  Builder b(def, m);
  b.check_dimension();
  b.check_bodies();
  b.assemble_stiffness_terms(p.stiffness_terms, p.stiffness_coefficients);
  p.h1_gram = assemble_h1_gram(m);
  p.is_dirichlet.assign(static_cast<size_t>(n), 0);
  AffineVectors lift(np, n), fext(np, n);
  b.dirichlet(p.is_dirichlet, lift);
  b.tractions(fext);
  keep_nonzero_terms(lift, fext, np, p.lifting_terms, p.external_load_terms, p.load_coefficients);
  if (p.lifting_terms.empty()) {  // no load at all: keep one zero term so φ has a size
    p.lifting_terms.push_back(Eigen::VectorXd::Zero(n));
    p.external_load_terms.push_back(Eigen::VectorXd::Zero(n));
    p.load_coefficients.push_back(AffineExpression::constant_value(1.0, np));
  }
  p.contact = b.contact();
  p.displacement_scale = displacement_scale(def);
  p.fingerprint = text_fingerprint(def.text + "|" + m.fingerprint());
  auto problem = std::make_unique<Problem>(std::move(p));
  check_contact_pairs_face(*problem);
  return problem;
}

std::unique_ptr<Problem> make_problem(const std::string& name_or_path, const ProblemOptions& options) {
  if (name_or_path == "rope") return make_rope_problem();
  ProblemDefinition def = read_problem_file(find_problem_file(name_or_path));
  if (options.refine < 0 || options.refine > 6)
    throw InputError("refine " + std::to_string(options.refine) + " is invalid; expected 0..6");
  def.refine += options.refine;
  MeshOptions mesh_options;
  mesh_options.refine = def.refine;
  mesh_options.max_nodes = def.max_mesh_nodes;
  mesh_options.time_limit_s = def.mesh_time_limit;
  mesh_options.progress = options.progress;
  std::error_code ec;
  if (!std::filesystem::exists(def.mesh, ec))
    throw InputError(def.where(def.mesh_where) + ": mesh file " + quoted(def.mesh, 200) +
                     " not found; expected a gmsh .geo or .msh file (a relative path is taken from the problem file's folder)");
  Mesh mesh = load_mesh(def.mesh, mesh_options);
  return build_problem(std::move(def), std::move(mesh));
}

std::vector<Param> training_set(const Problem& problem, int n) {
  return problem.definition().training.points_for(problem.parameters(), n);
}

std::vector<Param> validation_set(const Problem& problem, int n) {
  return problem.definition().validation.points_for(problem.parameters(), n);
}

Param parse_param(const Problem& problem, const std::string& text) { return problem.parameters().parse(text, problem.name()); }

}  // namespace contactrom::fom
