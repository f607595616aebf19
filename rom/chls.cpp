#include <contactrom/rom/chls.hpp>

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

  const VectorXd col_norms = a->colwise().norm();
  const double max_col_norm = col_norms.maxCoeff();
  const double b_norm = b->norm();
  const int cap = m_options.max_iterations > 0 ? m_options.max_iterations : static_cast<int>(3 * n + 10);

  // Start at the nearest vertex of the simplex.
  Index j0 = 0;
  double best = std::numeric_limits<double>::infinity();
  for (Index j = 0; j < n; ++j) {
    const double d = (a->col(j) - *b).squaredNorm();
    if (d < best) best = d, j0 = j;
  }
  VectorXd alpha = VectorXd::Zero(n);
  alpha(j0) = 1.0;
  std::vector<Index> passive{j0};
  std::vector<char> in_passive(static_cast<std::size_t>(n), 0), excluded(static_cast<std::size_t>(n), 0);
  in_passive[static_cast<std::size_t>(j0)] = 1;

  m_info = Status::Success;
  VectorXd w, ax, z;
  while (true) {
    ax.noalias() = *a * alpha;
    w.noalias() = a->transpose() * (*b - ax);
    double w_passive = 0.0;
    for (Index p : passive) w_passive += w(p);
    w_passive /= static_cast<double>(passive.size());
    const double threshold = m_options.tolerance * max_col_norm * std::max(b_norm, ax.norm());

    Index enter = -1;
    double gain = threshold;
    for (Index j = 0; j < n; ++j) {
      const auto js = static_cast<std::size_t>(j);
      if (!in_passive[js] && !excluded[js] && w(j) - w_passive > gain) gain = w(j) - w_passive, enter = j;
    }
    if (enter < 0) break;  // KKT: no bound column lowers the objective
    if (m_iterations >= cap) {
      m_info = Status::NoConvergence;
      break;
    }
    ++m_iterations;
    passive.push_back(enter);
    in_passive[static_cast<std::size_t>(enter)] = 1;

    bool first = true;
    while (true) {
      z = affine_least_squares(*a, *b, passive);
      if (!z.allFinite()) {
        m_info = Status::NumericalIssue;
        break;
      }
      if ((z.array() > 0.0).all()) {
        alpha.setZero();
        for (std::size_t i = 0; i < passive.size(); ++i) alpha(passive[i]) = z(static_cast<Index>(i));
        std::fill(excluded.begin(), excluded.end(), 0);
        break;
      }
      if (first && z(z.size() - 1) <= 0.0) {
        // The entering column does not come out positive: only rounding can do this
        // (e.g. an affinely dependent column); do not try it again from this iterate.
        passive.pop_back();
        in_passive[static_cast<std::size_t>(enter)] = 0;
        excluded[static_cast<std::size_t>(enter)] = 1;
        break;
      }
      first = false;
      // Step from α towards z as far as α ≥ 0 allows; the blocking coefficients leave P.
      double t = 1.0;
      Index blocking = -1;
      for (std::size_t i = 0; i < passive.size(); ++i) {
        const double zi = z(static_cast<Index>(i)), ai = alpha(passive[i]);
        if (zi <= 0.0 && ai / (ai - zi) < t) t = ai / (ai - zi), blocking = passive[i];
      }
      for (std::size_t i = 0; i < passive.size(); ++i)
        alpha(passive[i]) += t * (z(static_cast<Index>(i)) - alpha(passive[i]));
      std::vector<Index> kept;
      for (Index p : passive) {
        // The blocking coefficient, and any left at rounding level (α is on the
        // simplex, so 1e-15 is relative), are bound.
        if (p == blocking || alpha(p) <= 1e-15) {
          alpha(p) = 0.0;
          in_passive[static_cast<std::size_t>(p)] = 0;
          ++m_iterations;
        } else {
          kept.push_back(p);
        }
      }
      if (kept.empty()) {  // cannot happen in exact arithmetic (α keeps summing to 1)
        m_info = Status::NumericalIssue;
        break;
      }
      passive.swap(kept);
      if (m_iterations >= cap) {
        m_info = Status::NoConvergence;
        break;
      }
    }
    if (m_info != Status::Success) break;
  }

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
