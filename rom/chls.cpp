#include <contactrom/rom/chls.hpp>

#include <contactrom/core/lawson_hanson.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace contactrom::rom {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// Least squares on the affine set {z : 1ᵀz = 1} restricted to the columns
/// `passive` of a: the last passive coefficient is eliminated,
/// z_last = 1 − Σ y, so that the constraint holds by construction, and the
/// remaining unconstrained problem min ‖(A_P' − a_last 1ᵀ) y − (b − a_last)‖ is
/// solved by a complete orthogonal decomposition (minimum-norm y when the passive
/// columns are affinely dependent).
VectorXd affine_least_squares(const MatrixXd& a, const VectorXd& b, const std::vector<Index>& passive) {
  const auto k = static_cast<Index>(passive.size());
  VectorXd z(k);
  if (k == 1) {
    z(0) = 1.0;
    return z;
  }
  const Index last = passive.back();
  MatrixXd m(a.rows(), k - 1);
  for (Index i = 0; i + 1 < k; ++i) m.col(i) = a.col(passive[static_cast<std::size_t>(i)]) - a.col(last);
  const VectorXd rhs = b - a.col(last);
  const VectorXd y = m.completeOrthogonalDecomposition().solve(rhs);
  z.head(k - 1) = y;
  z(k - 1) = 1.0 - y.sum();
  return z;
}

/// Least squares on the simplex as a Lawson–Hanson problem: the passive set keeps
/// 1ᵀα = 1 (eliminated in affine_least_squares), so the descent of a bound column
/// is measured against the common value of w = Aᵀ(b − Aα) on the passive set (its
/// multiplier).
class SimplexProblem final : public LawsonHansonProblem {
 public:
  SimplexProblem(const MatrixXd& a, const VectorXd& b, Index start, double tolerance)
      : m_a(a), m_b(b), m_passive{start},
        m_tolerance_scale(tolerance * a.colwise().norm().maxCoeff()), m_b_norm(b.norm()) {}

  const std::vector<Index>& passive() const override { return m_passive; }

  /// w_j − w_P with w = Aᵀ(b − Aα) and w_P its mean on the passive set; the threshold
  /// is tolerance · max_i‖a_i‖ · max(‖b‖, ‖Aα‖).
  double descent(const VectorXd& alpha, VectorXd& w) override {
    m_ax.noalias() = m_a * alpha;
    w.noalias() = m_a.transpose() * (m_b - m_ax);
    double w_passive = 0.0;
    for (const Index p : m_passive) w_passive += w(p);
    w_passive /= static_cast<double>(m_passive.size());
    w.array() -= w_passive;
    return m_tolerance_scale * std::max(m_b_norm, m_ax.norm());
  }

  bool free(Index j) override {
    m_passive.push_back(j);
    return true;
  }
  void bind(Index position) override { m_passive.erase(m_passive.begin() + position); }

  bool solve_passive(VectorXd& z) override {
    if (m_passive.empty()) return false;  // cannot happen in exact arithmetic (α sums to 1)
    z = affine_least_squares(m_a, m_b, m_passive);
    return z.allFinite();
  }

 private:
  const MatrixXd& m_a;
  const VectorXd& m_b;
  std::vector<Index> m_passive;
  const double m_tolerance_scale;
  const double m_b_norm;
  VectorXd m_ax;
};

}  // namespace

SimplexLeastSquares& SimplexLeastSquares::compute(const MatrixXd& a) {
  m_computed = false;
  m_info = Status::InvalidInput;
  if (a.cols() == 0 || a.rows() == 0 || !a.allFinite()) return *this;
  m_a = a;
  m_computed = true;
  m_info = Status::Success;
  return *this;
}

VectorXd SimplexLeastSquares::solve(const VectorXd& b_in) {
  m_iterations = 0;
  m_residual = 0.0;
  m_support.clear();
  if (!m_computed || b_in.size() != m_a.rows() || !b_in.allFinite()) {
    m_info = Status::InvalidInput;
    return VectorXd::Zero(m_a.cols());
  }
  const Index n = m_a.cols();

  // Tall problems: ‖Aα − b‖ = ‖R_A α − r_b‖ with [R_A r_b] the triangular factor
  // of [A b] (the rows of Qᵀ[A b] below n + 1 vanish), so work on n + 1 rows.
  MatrixXd reduced_a;
  VectorXd reduced_b;
  const MatrixXd* a = &m_a;
  const VectorXd* b = &b_in;
  if (m_a.rows() > n + 1) {
    MatrixXd ab(m_a.rows(), n + 1);
    ab << m_a, b_in;
    Eigen::HouseholderQR<MatrixXd> qr(ab);
    const MatrixXd r = qr.matrixQR().topRows(n + 1).triangularView<Eigen::Upper>();
    reduced_a = r.leftCols(n);
    reduced_b = r.col(n);
    a = &reduced_a;
    b = &reduced_b;
  }

  // Start at the nearest vertex of the simplex.
  Index j0 = 0;
  double best = std::numeric_limits<double>::infinity();
  for (Index j = 0; j < n; ++j) {
    const double d = (a->col(j) - *b).squaredNorm();
    if (d < best) best = d, j0 = j;
  }
  VectorXd alpha = VectorXd::Zero(n);
  alpha(j0) = 1.0;

  SimplexProblem problem(*a, *b, j0, m_options.tolerance);
  LawsonHansonOptions loop;
  loop.max_iterations = m_options.max_iterations > 0 ? m_options.max_iterations : static_cast<int>(3 * n + 10);
  // α lies on the simplex, so a coefficient at rounding level is relative to its sum.
  loop.bind_tolerance = 1e-15;
  const LawsonHansonResult result = lawson_hanson(problem, alpha, loop);
  m_info = result.status;
  m_iterations = result.iterations;

  // Renormalise the (already exact up to rounding) sum after the ratio steps, which
  // accumulate rounding in α; then report the residual.
  alpha = alpha.cwiseMax(0.0);
  const double sum = alpha.sum();
  if (sum > 0.0) alpha /= sum;
  for (Index j = 0; j < n; ++j)
    if (alpha(j) > 0.0) m_support.push_back(j);
  m_residual = (*a * alpha - *b).norm();
  return alpha;
}

ChlsResult chls_leave_one_out(const MatrixXd& snapshots, const ChlsOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const Index m = snapshots.cols();
  if (m < 2)
    throw InputError("CHLS needs at least 2 snapshots (leave one out); got " + std::to_string(m));
  if (!snapshots.allFinite()) throw InputError("CHLS: the snapshots contain a non-finite value");

  // One QR shared by the m solves: ‖D̃α − d_k‖ = ‖R̃α − r_k‖, R = triangular factor of D.
  MatrixXd data;
  if (snapshots.rows() > m) {
    Eigen::HouseholderQR<MatrixXd> qr(snapshots);
    data = qr.matrixQR().topRows(m).triangularView<Eigen::Upper>();
  } else {
    data = snapshots;
  }

  ChlsResult result;
  result.errors.resize(m);
  result.coefficients = MatrixXd::Zero(m, m);
  SimplexLeastSquares solver(options.solver);
  MatrixXd others(data.rows(), m - 1);
  for (Index k = 0; k < m; ++k) {
    for (Index j = 0, c = 0; j < m; ++j)
      if (j != k) others.col(c++) = data.col(j);
    const VectorXd alpha = solver.compute(others).solve(data.col(k));
    const double norm = data.col(k).norm();
    result.errors(k) = norm > 0.0 ? solver.residual_norm() / norm : solver.residual_norm();
    for (Index j = 0, c = 0; j < m; ++j)
      if (j != k) result.coefficients(j, k) = alpha(c++);
    result.status.push_back(solver.info());
    result.iterations.push_back(solver.iterations());
  }
  result.max_error = result.errors.maxCoeff();
  result.mean_error = result.errors.mean();
  result.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace contactrom::rom
