#include "fom/problem.hpp"

#include <cstdlib>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "fom/errors.hpp"

namespace contactrom::fom {
namespace {

std::string format_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out;
}

std::string hash_text(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char ch : text) h = (h ^ ch) * 1099511628211ULL;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

/// Sorted node ids of a set of physical curves, marking both dofs Dirichlet.
void mark_dirichlet(const Mesh& mesh, const std::string& group, std::vector<char>& is_dirichlet) {
  for (int node : mesh.group_nodes(group)) is_dirichlet[2 * node] = is_dirichlet[2 * node + 1] = 1;
}

std::vector<Eigen::Vector2d> body_centroids(const Mesh& mesh, int body) {
  std::vector<Eigen::Vector2d> out;
  for (int q = 0; q < mesh.num_quads(); ++q) {
    if (mesh.quad_body[q] != body) continue;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (int a = 0; a < 4; ++a) c += 0.25 * mesh.nodes.col(mesh.quads[q][a]);
    out.push_back(c);
  }
  return out;
}

int body_index(const Mesh& mesh, const std::string& name, const std::string& file) {
  for (size_t b = 0; b < mesh.body_names.size(); ++b)
    if (mesh.body_names[b] == name) return static_cast<int>(b);
  throw InputError("mesh '" + file + "' has no physical surface '" + name + "'");
}

/// Base for the two-body Q1 problems: loads the mesh, assembles K and the H¹
/// Gram matrix, sets Dirichlet dofs and the node-to-segment contact.
class TwoBodyProblem : public Problem {
 protected:
  void setup_mesh(const ProblemOptions& opt, const std::string& file, const std::string& master_body,
                  const std::vector<std::string>& dirichlet_groups) {
    const std::string dir = opt.mesh_dir.empty() ? mesh_directory() : opt.mesh_dir;
    const std::string path = dir + "/" + file;
    MeshOptions mo;  // LOCAL HACK, not to be committed
    if (const char* r = std::getenv("CONTACTROM_REFINE_HACK")) mo.refine = std::atoi(r);
    m_mesh = std::make_unique<Mesh>(load_mesh(path, mo));
    const Mesh& mesh = *m_mesh;
    m_materials.assign(mesh.body_names.size(), Material{});
    m_k_terms = {assemble_stiffness(mesh, m_materials)};
    m_h1 = assemble_h1_gram(mesh);
    m_is_dirichlet.assign(2 * mesh.num_nodes(), 0);
    for (const auto& g : dirichlet_groups) mark_dirichlet(mesh, g, m_is_dirichlet);
    finalize_dofs();
    m_contact = std::make_unique<NodeToSegmentContact>(
        mesh.nodes, mesh.group_nodes("slave"), mesh.group_nodes("master"),
        body_centroids(mesh, body_index(mesh, master_body, path)));
  }
  /// Lifting vector: `value` on component `comp` of the nodes of `group`.
  Eigen::VectorXd lift(const std::string& group, int comp, double value) const {
    Eigen::VectorXd l = Eigen::VectorXd::Zero(num_dofs());
    for (int node : m_mesh->group_nodes(group)) l(2 * node + comp) = value;
    return l;
  }
};

class HertzProblem final : public TwoBodyProblem {
 public:
  explicit HertzProblem(const ProblemOptions& opt) {
    m_name = "hertz";
    m_param_names = {"d"};
    m_lower = Eigen::VectorXd::Constant(1, 0.0);
    m_upper = Eigen::VectorXd::Constant(1, 0.3);
    m_lower_open = true;
    setup_mesh(opt, "hertz.geo", "bottom", {"bottom_clamp", "top_load"});
    m_lift_terms = {lift("top_load", 1, -1.0)};
    m_fext_terms = {Eigen::VectorXd::Zero(num_dofs())};
    m_u_scale = 0.3;
    m_fingerprint = hash_text("hertz|" + m_mesh->fingerprint());
  }
  Eigen::VectorXd stiffness_coefficients(const Param&) const override { return Eigen::VectorXd::Ones(1); }
  Eigen::VectorXd load_coefficients(const Param& mu) const override { return mu.head(1); }
  std::vector<Param> training_set(int n) const override {
    if (n < 1 || n > 100000) throw InputError("hertz training size " + std::to_string(n) + " invalid; expected 1..100000");
    std::vector<Param> out;
    for (int i = 1; i <= n; ++i) out.push_back(Eigen::VectorXd::Constant(1, 0.3 * i / n));
    return out;
  }
  std::vector<Param> validation_set(int) const override {
    std::vector<Param> out;
    for (int i = 1; i < 120; ++i) out.push_back(Eigen::VectorXd::Constant(1, 0.3 * (i + 0.5) / 120.0));
    return out;
  }
};

class IroningProblem final : public TwoBodyProblem {
 public:
  IroningProblem(const ProblemOptions& opt, bool free_dy) : m_free_dy(free_dy), m_dy(opt.ironing_dy) {
    if (!(opt.ironing_length > 0)) throw InputError("ironing length " + format_number(opt.ironing_length) + " invalid; expected > 0");
    m_name = free_dy ? "ironing2" : "ironing";
    m_param_names = free_dy ? std::vector<std::string>{"d_x", "d_y"} : std::vector<std::string>{"d_x"};
    if (free_dy) {
      m_lower = Eigen::Vector2d(0.0, 0.1);
      m_upper = Eigen::Vector2d(opt.ironing_length, 0.3);
    } else {
      m_lower = Eigen::VectorXd::Constant(1, 0.0);
      m_upper = Eigen::VectorXd::Constant(1, opt.ironing_length);
    }
    setup_mesh(opt, "ironing.geo", "slab", {"slab_bottom", "iron_top"});
    m_lift_terms = {lift("iron_top", 0, 1.0), lift("iron_top", 1, -1.0)};
    m_fext_terms = {Eigen::VectorXd::Zero(num_dofs()), Eigen::VectorXd::Zero(num_dofs())};
    m_u_scale = 0.3;
    m_fingerprint = hash_text(m_name + "|" + m_mesh->fingerprint() + "|" + format_number(opt.ironing_length) +
                              "|" + format_number(m_dy));
  }
  bool uses_levels() const override { return true; }
  Eigen::VectorXd stiffness_coefficients(const Param&) const override { return Eigen::VectorXd::Ones(1); }
  Eigen::VectorXd load_coefficients(const Param& mu) const override {
    return Eigen::Vector2d(mu(0), m_free_dy ? mu(1) : m_dy);
  }
  std::vector<Param> training_set(int level) const override { return grid(check_level(level)); }
  std::vector<Param> validation_set(int level) const override {
    // ironing: level 8 minus level 7 (fixed); ironing2: next level minus current.
    const int fine = m_free_dy ? check_level(level) + 1 : 8;
    std::vector<Param> out;
    const int nx = 1 << fine;
    for (const Param& p : grid(fine)) {
      const long ix = std::lround(p(0) / m_upper(0) * nx);
      long iy = 0;
      if (m_free_dy) iy = std::lround((p(1) - m_lower(1)) / (m_upper(1) - m_lower(1)) * nx);
      if (ix % 2 == 1 || iy % 2 == 1) out.push_back(p);
    }
    return out;
  }

 private:
  int check_level(int level) const {
    const int max_level = m_free_dy ? 7 : 12;
    if (level < 1 || level > max_level)
      throw InputError(m_name + " level " + std::to_string(level) + " invalid; expected 1.." + std::to_string(max_level));
    return level;
  }
  std::vector<Param> grid(int level) const {
    const int n = 1 << level;
    std::vector<Param> out;
    for (int i = 0; i <= n; ++i) {
      const double dx = m_upper(0) * i / n;
      if (!m_free_dy) {
        out.push_back(Eigen::VectorXd::Constant(1, dx));
        continue;
      }
      for (int j = 0; j <= n; ++j) out.push_back(Eigen::Vector2d(dx, m_lower(1) + (m_upper(1) - m_lower(1)) * j / n));
    }
    return out;
  }
  bool m_free_dy;
  double m_dy;
};

/// 1D elastic rope on [0,1] above an obstacle (paper appendix B):
/// energy ½∫ν(u')² + ∫ f u, u(0)=u(1)=0, u ≥ ψ(x) = −0.2(sin πx − sin 3πx) − 0.5,
/// ν = γ for x < 0.5 and 30 otherwise.
class RopeProblem final : public Problem {
 public:
  explicit RopeProblem(const ProblemOptions& opt) {
    const int ne = opt.rope_elements;
    if (ne < 2 || ne > 1000000) throw InputError("rope elements " + std::to_string(ne) + " invalid; expected 2..1000000");
    m_name = "rope";
    m_param_names = {"gamma"};
    m_lower = Eigen::VectorXd::Constant(1, 10.0);
    m_upper = Eigen::VectorXd::Constant(1, 50.0);
    m_dofs_per_node = 1;
    const int n = ne + 1;
    const double h = 1.0 / ne;
    m_rope_x = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
    std::vector<Eigen::Triplet<double>> left, right, gram;
    for (int e = 0; e < ne; ++e) {
      auto& t = (0.5 * (m_rope_x(e) + m_rope_x(e + 1)) < 0.5) ? left : right;
      const double k = 1.0 / h;
      t.insert(t.end(), {{e, e, k}, {e, e + 1, -k}, {e + 1, e, -k}, {e + 1, e + 1, k}});
      const double m = h / 6.0;  // H¹ Gram: mass + stiffness
      gram.insert(gram.end(), {{e, e, 2 * m + k}, {e, e + 1, m - k}, {e + 1, e, m - k}, {e + 1, e + 1, 2 * m + k}});
    }
    SparseMatrix kl(n, n), kr(n, n);
    kl.setFromTriplets(left.begin(), left.end());
    kr.setFromTriplets(right.begin(), right.end());
    m_k_terms = {kl, kr};
    m_h1.resize(n, n);
    m_h1.setFromTriplets(gram.begin(), gram.end());
    m_is_dirichlet.assign(n, 0);
    m_is_dirichlet.front() = m_is_dirichlet.back() = 1;
    finalize_dofs();
    Eigen::VectorXd w = Eigen::VectorXd::Constant(n, h);
    w(0) = w(n - 1) = 0.5 * h;
    Eigen::VectorXd psi(n);
    for (int i = 0; i < n; ++i) {
      const double x = m_rope_x(i);
      psi(i) = -0.2 * (std::sin(M_PI * x) - std::sin(3 * M_PI * x)) - 0.5;
    }
    m_contact = std::make_unique<ObstacleContact>(m_rope_x, psi, w);
    Eigen::VectorXd fext = -opt.rope_load * w;
    fext(0) = fext(n - 1) = 0.0;
    m_fext_terms = {fext};
    m_lift_terms = {Eigen::VectorXd::Zero(n)};
    m_u_scale = 0.5;
    m_fingerprint = hash_text("rope|" + std::to_string(ne) + "|" + format_number(opt.rope_load));
  }
  bool convex_parameter_independent_feasible_set() const override { return true; }
  Eigen::VectorXd stiffness_coefficients(const Param& mu) const override { return Eigen::Vector2d(mu(0), 30.0); }
  Eigen::VectorXd load_coefficients(const Param&) const override { return Eigen::VectorXd::Ones(1); }
  std::vector<Param> training_set(int) const override {
    std::vector<Param> out;
    for (int i = 0; i <= 8; ++i) out.push_back(Eigen::VectorXd::Constant(1, 10.0 + 5.0 * i));
    return out;
  }
  std::vector<Param> validation_set(int) const override {
    std::vector<Param> out;
    for (int i = 0; i < 8; ++i) out.push_back(Eigen::VectorXd::Constant(1, 12.5 + 5.0 * i));
    return out;
  }
};

}  // namespace

void Problem::finalize_dofs() {
  m_free_dofs.clear();
  for (int i = 0; i < num_dofs(); ++i)
    if (!m_is_dirichlet[i]) m_free_dofs.push_back(i);
}

void Problem::check_param(const Param& mu) const {
  if (mu.size() != num_params())
    throw InputError("problem '" + m_name + "' takes " + std::to_string(num_params()) + " parameter value(s) (" +
                     range_text() + "), got " + std::to_string(mu.size()));
  for (int i = 0; i < mu.size(); ++i) {
    const bool below = m_lower_open ? !(mu(i) > m_lower(i)) : !(mu(i) >= m_lower(i));
    if (below || !(mu(i) <= m_upper(i)) || !std::isfinite(mu(i)))
      throw InputError("parameter " + m_param_names[i] + " = " + format_number(mu(i)) + " is outside the range of '" +
                       m_name + "'; expected " + range_text());
  }
}

std::string Problem::range_text() const {
  std::string out;
  for (int i = 0; i < num_params(); ++i) {
    if (i) out += ", ";
    out += m_param_names[i] + " in " + (m_lower_open ? "(" : "[") + format_number(m_lower(i)) + ", " +
           format_number(m_upper(i)) + "]";
  }
  return out;
}

SparseMatrix Problem::stiffness(const Param& mu) const {
  const Eigen::VectorXd theta = stiffness_coefficients(mu);
  SparseMatrix k = theta(0) * m_k_terms[0];
  for (int q = 1; q < num_stiffness_terms(); ++q) k += theta(q) * m_k_terms[q];
  return k;
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
  f -= stiffness(mu) * lifting(mu);
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

const std::vector<std::string>& problem_names() {
  static const std::vector<std::string> names = {"rope", "hertz", "ironing", "ironing2"};
  return names;
}

std::unique_ptr<Problem> make_problem(const std::string& name, const ProblemOptions& options) {
  if (name == "rope") return std::make_unique<RopeProblem>(options);
  if (name == "hertz") return std::make_unique<HertzProblem>(options);
  if (name == "ironing") return std::make_unique<IroningProblem>(options, false);
  if (name == "ironing2") return std::make_unique<IroningProblem>(options, true);
  throw InputError("unknown problem '" + name + "'; expected one of: " + join(problem_names()));
}

Param parse_param(const Problem& problem, const std::string& text) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
    if (item.empty() || used != item.size())
      throw InputError("parameter value '" + item + "' is not a number; expected " + problem.range_text());
    values.push_back(v);
  }
  Param mu = Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  problem.check_param(mu);
  return mu;
}

}  // namespace contactrom::fom
