#include <contactrom/fom/rope.hpp>

#include <cmath>
#include <string>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_model.hpp>

namespace contactrom::fom {
namespace {

/// The problem file's equivalent: name, parameter γ ∈ [10, 50], the training and
/// validation lists of the paper, the convex hull accepted.
ProblemDefinition rope_definition() {
  ProblemDefinition def;
  def.name = "rope";
  def.builtin = "rope";
  def.parameters.add("gamma", 10.0, 50.0);
  def.training.kind = SamplingPlan::Kind::List;
  for (int i = 0; i <= 8; ++i) def.training.points.push_back(Eigen::VectorXd::Constant(1, 10.0 + 5.0 * i));
  def.validation.kind = SamplingPlan::Kind::List;
  for (int i = 0; i < 8; ++i) def.validation.points.push_back(Eigen::VectorXd::Constant(1, 12.5 + 5.0 * i));
  def.rom.convex_hull = true;
  return def;
}

/// K = γ K_left + 30 K_right (elements left and right of x = 0.5) and the H¹ Gram
/// matrix (mass + stiffness), P1 on the nodes x.
void assemble_rope(const Eigen::VectorXd& x, ProblemParts& p) {
  const int n = static_cast<int>(x.size()), ne = n - 1;
  const double h = 1.0 / ne;
  std::vector<Eigen::Triplet<double>> left, right, gram;
  for (int e = 0; e < ne; ++e) {
    auto& t = (0.5 * (x(e) + x(e + 1)) < 0.5) ? left : right;
    const double k = 1.0 / h;
    t.insert(t.end(), {{e, e, k}, {e, e + 1, -k}, {e + 1, e, -k}, {e + 1, e + 1, k}});
    const double m = h / 6.0;
    gram.insert(gram.end(), {{e, e, 2 * m + k}, {e, e + 1, m - k}, {e + 1, e, m - k}, {e + 1, e + 1, 2 * m + k}});
  }
  SparseMatrix kl(n, n), kr(n, n);
  kl.setFromTriplets(left.begin(), left.end());
  kr.setFromTriplets(right.begin(), right.end());
  p.stiffness_terms = {kl, kr};
  AffineExpression gamma = AffineExpression::constant_value(0.0, 1);
  gamma.coefficients(0) = 1.0;
  p.stiffness_coefficients = {gamma, AffineExpression::constant_value(30.0, 1)};
  p.h1_gram.resize(n, n);
  p.h1_gram.setFromTriplets(gram.begin(), gram.end());
}

}  // namespace

Eigen::VectorXd rope_nodes(const Problem& rope) { return Eigen::VectorXd::LinSpaced(rope.num_dofs(), 0.0, 1.0); }

std::unique_ptr<Problem> make_rope_problem(const RopeOptions& options) {
  const int ne = options.elements;
  if (ne < 2 || ne > 1000000) throw InputError("rope elements " + std::to_string(ne) + " invalid; expected 2..1000000");
  const int n = ne + 1;
  const double h = 1.0 / ne;
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
  ProblemParts p;
  p.definition = rope_definition();
  p.dofs_per_node = 1;
  assemble_rope(x, p);
  p.is_dirichlet.assign(static_cast<size_t>(n), 0);
  p.is_dirichlet.front() = p.is_dirichlet.back() = 1;
  // The obstacle at every node, with tributary lengths as weights; the load on the free nodes.
  Eigen::VectorXd w = Eigen::VectorXd::Constant(n, h);
  w(0) = w(n - 1) = 0.5 * h;
  Eigen::VectorXd psi(n);
  for (int i = 0; i < n; ++i) psi(i) = -0.2 * (std::sin(M_PI * x(i)) - std::sin(3 * M_PI * x(i))) - 0.5;
  p.contact = std::make_unique<ObstacleContact>(x, psi, w);
  Eigen::VectorXd fext = -options.load * w;
  fext(0) = fext(n - 1) = 0.0;
  p.external_load_terms = {fext};
  p.lifting_terms = {Eigen::VectorXd::Zero(n)};
  p.load_coefficients = {AffineExpression::constant_value(1.0, 1)};
  p.displacement_scale = 0.5;
  p.fingerprint = text_fingerprint("rope|" + std::to_string(ne) + "|" + format_number(options.load));
  return std::make_unique<Problem>(std::move(p));
}

}  // namespace contactrom::fom
