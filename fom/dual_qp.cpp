#include <contactrom/fom/dual_qp.hpp>

#include <algorithm>
#include <cmath>

#include <contactrom/core/nnls.hpp>

namespace contactrom::fom {

bool DualQpSolver::solve_on(const Eigen::MatrixXd& g, const Eigen::VectorXd& h, const std::vector<int>& set,
                            Eigen::VectorXd& z) {
  const Eigen::Index k = static_cast<Eigen::Index>(set.size());
  m_gs.resize(k, k);
  m_hs.resize(k);
  for (Eigen::Index b = 0; b < k; ++b) {
    for (Eigen::Index a = 0; a < k; ++a) m_gs(a, b) = g(set[a], set[b]);
    m_hs(b) = h(set[b]);
  }
  m_llt.compute(m_gs);
  if (m_llt.info() == Eigen::Success) {
    z = m_llt.solve(m_hs);
  } else {
    // Semi-definite on this set (dependent rows): least-norm solution.
    z = m_gs.completeOrthogonalDecomposition().solve(m_hs);
  }
  return z.allFinite();
}

Eigen::VectorXd DualQpSolver::solve(const Eigen::MatrixXd& g, const Eigen::VectorXd& h,
                                    const std::vector<char>& eligible_in, const Eigen::VectorXd& warm_start) {
  const int n = static_cast<int>(h.size());
  m_iterations = 0;
  m_fallback = false;
  m_info = Status::Success;
  // The working arrays are members: repeated solves of the pairing loops do not allocate.
  std::vector<char>& eligible = m_eligible;
  if (eligible_in.empty())
    eligible.assign(static_cast<size_t>(n), 1);
  else
    eligible = eligible_in;
  if (g.rows() != n || g.cols() != n || static_cast<int>(eligible.size()) != n || !g.allFinite() || !h.allFinite()) {
    m_info = Status::InvalidInput;
    return Eigen::VectorXd::Zero(n);
  }
  if (n == 0) return Eigen::VectorXd();
  for (int i = 0; i < n; ++i)
    if (!(g(i, i) > 0.0)) eligible[i] = 0;
  const double scale = std::max(h.cwiseAbs().maxCoeff(), 1e-300);
  const double tol = m_options.relative_tolerance * scale;

  // Initial active set: warm start support, else rows penetrating at λ = 0.
  std::vector<char>& active = m_active;
  std::vector<char>& next = m_next;
  active.assign(static_cast<size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    const bool seed = warm_start.size() == n ? warm_start(i) > 0.0 : h(i) > tol;
    active[i] = eligible[i] && seed;
  }
  // The active sets seen so far, one after the other (a cycle returns to one).
  m_seen.clear();
  const auto seen = [&](const std::vector<char>& set) {
    for (size_t start = 0; start < m_seen.size(); start += static_cast<size_t>(n))
      if (std::equal(set.begin(), set.end(), m_seen.begin() + static_cast<std::ptrdiff_t>(start))) return true;
    return false;
  };
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n);
  while (m_iterations < m_options.max_iterations) {
    ++m_iterations;
    if (!seen(active)) m_seen.insert(m_seen.end(), active.begin(), active.end());
    m_set.clear();
    for (int i = 0; i < n; ++i)
      if (active[i]) m_set.push_back(i);
    lambda.setZero();
    if (!m_set.empty()) {
      if (!solve_on(g, h, m_set, m_z)) {
        m_info = Status::NumericalIssue;
        return lambda;
      }
      for (size_t a = 0; a < m_set.size(); ++a) lambda(m_set[a]) = m_z(static_cast<Eigen::Index>(a));
    }
    m_w.noalias() = g * lambda;
    m_w -= h;
    next.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) next[i] = eligible[i] && (active[i] ? lambda(i) > -tol : m_w(i) < -tol);
    if (next == active && active_gaps_close(m_w, h, active, scale)) {
      // Converged: clean round-off negatives (|λ_i| <= tol) on the active set.
      lambda = lambda.cwiseMax(0.0);
      return lambda;
    }
    // A stable active set whose rows still have a gap was solved in the least-squares
    // sense (G singular on it: dependent rows); PDAS cannot improve on it, and
    // Lawson–Hanson solves the QP exactly, like a cycle.
    if (next == active || seen(next)) {
      m_fallback = true;
      return lawson_hanson(g, h, eligible);
    }
    std::swap(active, next);
  }
  m_info = Status::NoConvergence;
  return lambda;
}

// Complementarity on the active set: w_i = (Gλ − h)_i vanishes on every active row,
// to a tolerance above the round-off of a Cholesky solve (relative_tolerance ×
// kGapSlack, against max(|h|∞, |Gλ|∞), with Gλ = w + h). Only a least-squares solve
// on a singular subsystem misses it.
bool DualQpSolver::active_gaps_close(const Eigen::VectorXd& w, const Eigen::VectorXd& h,
                                     const std::vector<char>& active, double scale) const {
  constexpr double kGapSlack = 1e3;
  const double tol = kGapSlack * m_options.relative_tolerance * std::max(scale, (w + h).cwiseAbs().maxCoeff());
  for (int i = 0; i < static_cast<int>(w.size()); ++i)
    if (active[i] && std::abs(w(i)) > tol) return false;
  return true;
}

// Lawson–Hanson on the rows that may become active (NnlsQp, core/nnls.hpp), started
// from λ = 0; it terminates for any positive semi-definite G. Its optimality test
// uses the same relative tolerance, against max(|h|∞, |Gλ|∞).
Eigen::VectorXd DualQpSolver::lawson_hanson(const Eigen::MatrixXd& g, const Eigen::VectorXd& h,
                                            const std::vector<char>& eligible) {
  const int n = static_cast<int>(h.size());
  std::vector<int> rows;
  for (int i = 0; i < n; ++i)
    if (eligible[i]) rows.push_back(i);
  const int m = static_cast<int>(rows.size());
  const Eigen::MatrixXd g_e = g(rows, rows);
  const Eigen::VectorXd h_e = h(rows);
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n);
  const int budget = m_options.max_iterations - m_iterations;
  if (budget <= 0) {
    m_info = Status::NoConvergence;
    return lambda;
  }
  NnlsOptions options;
  options.max_iterations = budget;
  options.tolerance = m_options.relative_tolerance;
  NnlsQp nnls(options);
  const Eigen::VectorXd lambda_e = nnls.compute(g_e).solve(h_e);
  m_iterations += nnls.iterations();
  m_info = nnls.info();
  for (int a = 0; a < m; ++a) lambda(rows[a]) = lambda_e(a);
  return lambda;
}

}  // namespace contactrom::fom
