#include <contactrom/fom/dual_qp.hpp>

#include <algorithm>
#include <cmath>
#include <set>

#include <contactrom/core/nnls.hpp>

namespace contactrom::fom {

bool DualQpSolver::solve_on(const Eigen::MatrixXd& g, const Eigen::VectorXd& h, const std::vector<int>& set,
                            Eigen::VectorXd& z) const {
  const Eigen::MatrixXd gs = g(set, set);
  const Eigen::VectorXd hs = h(set);
  Eigen::LLT<Eigen::MatrixXd> llt(gs);
  if (llt.info() == Eigen::Success) {
    z = llt.solve(hs);
  } else {
    // Semi-definite on this set (dependent rows): least-norm solution.
    z = gs.completeOrthogonalDecomposition().solve(hs);
  }
  return z.allFinite();
}

Eigen::VectorXd DualQpSolver::solve(const Eigen::MatrixXd& g, const Eigen::VectorXd& h,
                                    const std::vector<char>& eligible_in, const Eigen::VectorXd& warm_start) {
  const int n = static_cast<int>(h.size());
  m_iterations = 0;
  m_fallback = false;
  m_info = Status::Success;
  std::vector<char> eligible = eligible_in.empty() ? std::vector<char>(n, 1) : eligible_in;
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
  std::vector<char> active(n, 0);
  for (int i = 0; i < n; ++i) {
    const bool seed = warm_start.size() == n ? warm_start(i) > 0.0 : h(i) > tol;
    active[i] = eligible[i] && seed;
  }
  std::set<std::vector<char>> seen;
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n);
  while (m_iterations < m_options.max_iterations) {
    ++m_iterations;
    seen.insert(active);
    std::vector<int> set;
    for (int i = 0; i < n; ++i)
      if (active[i]) set.push_back(i);
    Eigen::VectorXd z;
    lambda.setZero();
    if (!set.empty()) {
      if (!solve_on(g, h, set, z)) {
        m_info = Status::NumericalIssue;
        return lambda;
      }
      for (size_t a = 0; a < set.size(); ++a) lambda(set[a]) = z(a);
    }
    const Eigen::VectorXd w = g * lambda - h;
    std::vector<char> next(n, 0);
    for (int i = 0; i < n; ++i) next[i] = eligible[i] && (active[i] ? lambda(i) > -tol : w(i) < -tol);
    if (next == active && active_gaps_close(w, h, active, scale)) {
      // Converged: clean round-off negatives (|λ_i| <= tol) on the active set.
      lambda = lambda.cwiseMax(0.0);
      return lambda;
    }
    // A stable active set whose rows still have a gap was solved in the least-squares
    // sense (G singular on it: dependent rows); PDAS cannot improve on it, and
    // Lawson–Hanson solves the QP exactly, like a cycle.
    if (next == active || seen.count(next)) {
      m_fallback = true;
      return lawson_hanson(g, h, eligible);
    }
    active = next;
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
