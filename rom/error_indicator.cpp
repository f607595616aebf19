#include <contactrom/rom/error_indicator.hpp>

#include <algorithm>
#include <cmath>

#include <contactrom/core/stopwatch.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::rom {
namespace {

/// Surface dofs solved per block when forming E_sᵀ K⁻¹ H K⁻¹ E_s: bounds the dense
/// n_free × block work space.
constexpr int kSurfaceBlock = 64;

/// Rows of a free-dof matrix at the surface dofs (zero rows for Dirichlet ones).
Eigen::MatrixXd surface_rows(const Eigen::MatrixXd& x_free, const std::vector<int>& surface, const std::vector<int>& free_index) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(surface.size()), x_free.cols());
  for (size_t j = 0; j < surface.size(); ++j)
    if (free_index[surface[j]] >= 0) out.row(static_cast<Eigen::Index>(j)) = x_free.row(free_index[surface[j]]);
  return out;
}

/// K_ff⁻¹ (M)_free for a matrix M on all dofs: the free rows of M, one solve per column.
Eigen::MatrixXd solve_free(const fom::SparseCholesky& factor, const Eigen::MatrixXd& m, const std::vector<int>& free) {
  Eigen::MatrixXd rhs(static_cast<Eigen::Index>(free.size()), m.cols());
  for (size_t i = 0; i < free.size(); ++i) rhs.row(static_cast<Eigen::Index>(i)) = m.row(free[i]);
  return factor.solve(rhs);
}

}  // namespace

std::string no_error_estimate_reason(const fom::Problem& problem) {
  if (problem.stiffness_is_constant()) return {};
  return "the stiffness of problem " + quoted(problem.name(), 200) + " depends on its parameters";
}

ErrorIndicator::ErrorIndicator(const ReducedModel& model, ErrorIndicatorOptions options)
    : m_problem(model.problem()), m_rank(model.primal_rank()), m_options(std::move(options)) {
  const auto t0 = std::chrono::steady_clock::now();
  if (no_error_estimate_reason(m_problem).empty()) build(model);
  m_setup_time = seconds_since(t0);
}

ErrorIndicator::~ErrorIndicator() = default;

void ErrorIndicator::build(const ReducedModel& model) {
  const fom::Problem& problem = m_problem;
  const fom::Param mid = 0.5 * (problem.param_lower() + problem.param_upper());
  if (!fom::condense(problem, mid, m_cond)) return;
  const int n = problem.num_dofs(), r = m_rank, nt = problem.num_load_terms();
  const std::vector<int>& free = problem.free_dofs();
  const std::vector<int>& surf = problem.contact().surface_dofs();
  const int ns = static_cast<int>(surf.size());
  std::vector<int> free_index(static_cast<size_t>(n), -1);
  for (size_t i = 0; i < free.size(); ++i) free_index[free[i]] = static_cast<int>(i);
  const fom::SparseMatrix& h = problem.h1_gram();

  // V = [Φ, L̃ − Z]: the answer is V (û, φ(μ)) + z(μ), with z(μ) = Z φ(μ).
  const Eigen::MatrixXd& z = m_cond.z_load;
  Eigen::MatrixXd v(n, r + nt);
  v.leftCols(r) = model.basis();
  for (int k = 0; k < nt; ++k) v.col(r + k) = model.offset_terms()[static_cast<size_t>(k)] - z.col(k);
  const Eigen::MatrixXd hv = h * v, hz = h * z;
  m_vhv = v.transpose() * hv;
  m_zhz = z.transpose() * hz;
  m_vhs = surface_rows(solve_free(*m_cond.factor, hv, free), surf, free_index).transpose();
  m_zhs = surface_rows(solve_free(*m_cond.factor, hz, free), surf, free_index).transpose();

  // E_sᵀ K⁻¹ H K⁻¹ E_s by blocks of surface dofs: X = K⁻¹ E_b, then K⁻¹ H X.
  m_shs = Eigen::MatrixXd::Zero(ns, ns);
  for (int first = 0; first < ns; first += kSurfaceBlock) {
    const int count = std::min(kSurfaceBlock, ns - first);
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(n, count);
    for (int j = 0; j < count; ++j)
      if (free_index[surf[first + j]] >= 0) unit(surf[first + j], j) = 1.0;
    const Eigen::MatrixXd x_free = solve_free(*m_cond.factor, unit, free);
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, count);
    for (size_t i = 0; i < free.size(); ++i) x.row(free[i]) = x_free.row(static_cast<Eigen::Index>(i));
    m_shs.middleCols(first, count) = surface_rows(solve_free(*m_cond.factor, h * x, free), surf, free_index);
  }
  m_shs = (0.5 * (m_shs + m_shs.transpose())).eval();
  if (model.has_primal_snapshots()) {  // m + T more solves, for combinations of snapshots
    const Eigen::MatrixXd& p = model.primal_snapshots();
    const Eigen::Index m = p.cols();
    Eigen::MatrixXd w(n, m + nt);
    w.leftCols(m) = p;
    for (int k = 0; k < nt; ++k) w.col(m + k) = problem.lifting_terms()[static_cast<size_t>(k)] - z.col(k);
    const Eigen::MatrixXd hw = h * w;
    m_whw = w.transpose() * hw;
    m_whs = surface_rows(solve_free(*m_cond.factor, hw, free), surf, free_index).transpose();
  }
  m_z_s = Eigen::MatrixXd(ns, nt);
  for (int j = 0; j < ns; ++j) m_z_s.row(j) = z.row(surf[j]);
  m_cond.factor.reset();  // every query needs S only

  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  m_near_zero = fom::kNearZeroReference * problem.displacement_scale() * std::sqrt(std::max(ones.dot(h * ones), 0.0));
  m_available = m_vhv.allFinite() && m_vhs.allFinite() && m_shs.allFinite() && m_zhs.allFinite();
}

ErrorEstimate ErrorIndicator::estimate(const fom::Param& mu, const Eigen::VectorXd& u_hat, const Eigen::VectorXd& lambda,
                                       const fom::Pairing& pairing, const Eigen::VectorXd& u_surface,
                                       int pairings, const fom::SearchMemory* memory,
                                       const SnapshotCombination* combination) const {
  const auto t0 = std::chrono::steady_clock::now();
  ErrorEstimate e;
  const fom::Problem& problem = m_problem;
  const fom::ContactModel& contact = problem.contact();
  if (!m_available || u_hat.size() != m_rank || lambda.size() != contact.num_constraints()) return e;
  const Eigen::VectorXd phi = problem.load_coefficients(mu);

  // 1. The FOM's condensed problem from the answer: at its pairing, then re-paired
  // by the FOM's pairing loop until the correction's forces and gaps settle.
  const Eigen::VectorXd z_s = m_z_s * phi;
  const Eigen::VectorXd lambda_start = lambda.cwiseMax(0.0);
  thread_local fom::ConstraintMatrix c;
  thread_local Eigen::VectorXd g;
  fom::PairedSolution sol;
  const int cap = pairings > 0 ? pairings : m_options.pairing_iterations;
  if (cap <= 1 || !contact.has_pairing()) {
    contact.assemble(pairing, c, g);
    sol = fom::solve_at_pairing(problem, m_cond, m_options.fom, z_s, pairing, c, g, u_surface, lambda_start,
                                e.qp_iterations);
    e.pairings = 1;
  } else {
    fom::PairingFixedPointOptions fixed_point = fom::pairing_options(m_options.fom);
    fixed_point.max_iterations = cap;
    fixed_point.tolerance = m_options.pairing_tolerance;
    fom::PairingFixedPointResult fp = fom::solve_pairing_loop(problem, m_cond, m_options.fom, fixed_point, z_s,
                                                              u_surface, pairing, lambda_start, e.qp_iterations,
                                                              memory);
    sol = std::move(fp.solution);
    c = std::move(fp.c);
    e.pairings = fp.iterations;
  }
  if (sol.status != Status::Success) {
    e.status = Status::NumericalIssue;
    e.time_s = seconds_since(t0);
    return e;
  }

  // 2. Norms of u_r − u_c = V a + K⁻¹ E_s y and of u_c = Z φ − K⁻¹ E_s y, y = Cᵀ λ_c,
  // from the offline products, on the support of y only.
  const Eigen::VectorXd y = c.transpose() * sol.lambda;
  // The answer is V a + z(μ), a = (û, φ); or, a combination of snapshots, W a + z(μ),
  // a = (α, φ) with α over all the dictionary's columns.
  const bool combined = combination && m_whw.size() > 0;
  const Eigen::MatrixXd& vhv = combined ? m_whw : m_vhv;
  const Eigen::MatrixXd& vhs = combined ? m_whs : m_vhs;
  Eigen::VectorXd a = Eigen::VectorXd::Zero(vhv.rows());
  if (combined) {
    for (size_t i = 0; i < combination->columns.size(); ++i)
      a(combination->columns[i]) += combination->coefficients(static_cast<Eigen::Index>(i));
    a.tail(phi.size()) = phi;
  } else {
    a << u_hat, phi;
  }
  Eigen::VectorXd vy = Eigen::VectorXd::Zero(a.size()), zy = Eigen::VectorXd::Zero(phi.size());
  double yqy = 0.0;
  thread_local std::vector<int> support;
  support.clear();
  for (Eigen::Index j = 0; j < y.size(); ++j)
    if (y(j) != 0.0) support.push_back(static_cast<int>(j));
  for (size_t b = 0; b < support.size(); ++b) {  // yᵀ Q y over the lower triangle (Q symmetric)
    const int j = support[b];
    vy.noalias() += y(j) * vhs.col(j);
    zy.noalias() += y(j) * m_zhs.col(j);
    const double* q_j = m_shs.data() + static_cast<Eigen::Index>(j) * m_shs.rows();
    double row = 0.0;
    for (size_t a = 0; a < b; ++a) row += q_j[support[a]] * y(support[a]);
    yqy += y(j) * (2.0 * row + q_j[j] * y(j));
  }
  const double error2 = a.dot(vhv * a) + 2.0 * a.dot(vy) + yqy;
  const double norm2 = phi.dot(m_zhz * phi) - 2.0 * phi.dot(zy) + yqy;
  const double norm = std::sqrt(std::max(norm2, 0.0));
  e.absolute = norm < m_near_zero;
  e.primal = std::sqrt(std::max(error2, 0.0)) / (e.absolute || norm == 0.0 ? 1.0 : norm);

  // 3. The pressure against the correction's, in L²(Γc).
  const Eigen::VectorXd& w = contact.weights();
  const double dual2 = w.dot((lambda - sol.lambda).cwiseAbs2()), ref2 = w.dot(sol.lambda.cwiseAbs2());
  e.dual = std::sqrt(dual2 / (e.absolute || ref2 == 0.0 ? 1.0 : ref2));
  e.status = Status::Success;
  e.time_s = seconds_since(t0);
  return e;
}

}  // namespace contactrom::rom
