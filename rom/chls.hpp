#pragma once
/// \file chls.hpp
/// \brief Convex-hull least squares: the distance of a vector to the convex hull
/// of the columns of a matrix,
/// \f[ \min_\alpha \|A\alpha - b\|_2 \quad\text{s.t.}\quad \alpha \ge 0,\; \mathbf 1^T\alpha = 1, \f]
/// solved exactly by an active-set method (SimplexLeastSquares), and the
/// leave-one-out CHLS test of the paper's Convex Subset hypothesis (appendix B):
/// every snapshot is approximated by the convex hull of the others,
/// \f[ \epsilon_{CHLS}[k] = \min_{\alpha \ge 0,\ \mathbf 1^T\alpha = 1}
///     \frac{\|\tilde D_p\,\alpha - d_k\|_2}{\|d_k\|_2}. \f]
///
/// Exact command line (docs/convex_hull.md):
/// \code
///   contactrom chls --db rope.h5 --out rope_chls.csv --json
/// \endcode
///
/// Why an exact solver rather than NNLS with a heavily weighted row
/// \f$ \omega\mathbf 1^T\alpha = \omega \f$: the weighted row enforces the
/// sum only to \f$ O(\|r\|/\omega^2) \f$, and the Gram form of NNLS squares the
/// conditioning that a large ω creates. Here the equality is eliminated
/// (\f$ \alpha_{last} = 1 - \sum_{i \ne last}\alpha_i \f$ on the passive set), so
/// \f$ \mathbf 1^T\alpha = 1 \f$ holds to rounding (\f$ \sim 10^{-16} \f$) by
/// construction, and each passive-set solve is a Householder least-squares solve
/// on the matrix itself (backward stable: the residual is accurate to
/// \f$ \sim\varepsilon\|A\|\|\alpha\| \f$, so a point of the hull has error
/// \f$ \lesssim 10^{-14} \f$). The math is in docs/convex_hull.md.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom::rom {

/// \brief Settings of SimplexLeastSquares.
struct SimplexLeastSquaresOptions {
  /// Cap on the number of active-set changes (each frees or binds one
  /// coefficient); ≤ 0 selects 3n + 10, n the number of columns. Reaching it gives
  /// Status::NoConvergence and the last (feasible) iterate. Default 0.
  int max_iterations = 0;
  /// Relative optimality tolerance (dimensionless): the solve stops when no bound
  /// column j improves the objective, \f$ w_j - w_P \le
  /// \mathrm{tolerance}\cdot\max_i\|a_i\|\,\max(\|b\|, \|A\alpha\|) \f$, with
  /// \f$ w = A^T(b - A\alpha) \f$ and \f$ w_P \f$ its (common) value on the
  /// passive set. Default 1e-12.
  double tolerance = 1e-12;
};

/// \brief Least squares on the probability simplex; see the file comment.
///
/// Algorithm (primal active set in the manner of Lawson–Hanson, with the equality
/// constraint kept on the passive set P): start at the vertex
/// \f$ \alpha = e_{j_0} \f$, \f$ j_0 = \arg\min_j \|a_j - b\| \f$; repeat
///  1. \f$ w = A^T(b - A\alpha) \f$, \f$ w_P = \f$ mean of w on P (KKT: equal on P);
///  2. stop if \f$ \max_{j\notin P} w_j - w_P \le \mathrm{tol} \f$; else free the maximiser;
///  3. solve the equality-constrained least squares on P (eliminated form, COD, so
///     affinely dependent columns give the minimum-norm solution); if a coefficient
///     is not positive, step from α towards the solution as far as feasibility
///     allows and bind the blocking coefficients; repeat 3.
/// A column whose first passive solve does not come out positive (possible only
/// through rounding, e.g. an affinely dependent column) is not freed again in that
/// outer iteration.
///
/// When A has more rows than columns + 1, solve() first reduces the problem to
/// \f$ (n+1) \f$ rows with a Householder QR of \f$ [A\; b] \f$ (norms of
/// residuals are preserved exactly), so every later step costs \f$ O(n^3) \f$
/// however tall A is.
///
/// \code
///   contactrom::rom::SimplexLeastSquares ls;
///   Eigen::VectorXd alpha = ls.compute(A).solve(b);   // alpha >= 0, sum = 1
///   double distance = ls.residual_norm();
/// \endcode
class SimplexLeastSquares {
 public:
  using Options = SimplexLeastSquaresOptions;

  SimplexLeastSquares() = default;
  explicit SimplexLeastSquares(const Options& options) : m_options(options) {}

  /// \brief Stores A (m × n, n ≥ 1). info() is InvalidInput for an empty or
  /// non-finite A.
  SimplexLeastSquares& compute(const Eigen::MatrixXd& a);

  /// \brief Solves the problem for b (size m).
  /// \returns α (size n, α ≥ 0, 1ᵀα = 1); zeros if info() is InvalidInput.
  Eigen::VectorXd solve(const Eigen::VectorXd& b);

  /// \brief Status of the last compute() or solve().
  Status info() const { return m_info; }
  /// \brief Active-set changes of the last solve().
  int iterations() const { return m_iterations; }
  /// \brief \f$ \|A\alpha - b\|_2 \f$ at the returned α.
  double residual_norm() const { return m_residual; }
  /// \brief Passive set (α_j > 0) of the last solve, ascending.
  const std::vector<Eigen::Index>& support() const { return m_support; }

  const Options& options() const { return m_options; }
  /// \brief Replaces the settings; returns *this for chaining.
  SimplexLeastSquares& set_options(const Options& options) {
    m_options = options;
    return *this;
  }

 private:
  Options m_options;
  Eigen::MatrixXd m_a;
  bool m_computed = false;
  Status m_info = Status::InvalidInput;
  int m_iterations = 0;
  double m_residual = 0.0;
  std::vector<Eigen::Index> m_support;
};

/// \brief Settings of chls_leave_one_out.
struct ChlsOptions {
  SimplexLeastSquaresOptions solver;  ///< settings of every simplex least-squares solve
};

/// \brief Outcome of the leave-one-out CHLS test over m snapshots.
struct ChlsResult {
  /// \f$ \epsilon_{CHLS}[k] \f$, relative to \f$ \|d_k\| \f$ (absolute distance
  /// when \f$ d_k = 0 \f$).
  Eigen::VectorXd errors;
  /// Column k: coefficients over all m snapshots (entry k is 0), α ≥ 0, 1ᵀα = 1.
  Eigen::MatrixXd coefficients;
  std::vector<Status> status;  ///< solver status of each snapshot
  std::vector<int> iterations; ///< active-set changes of each snapshot
  double max_error = 0.0;
  double mean_error = 0.0;
  double time_s = 0.0;  ///< wall time of the whole test
};

/// \brief Leave-one-out CHLS of the columns of `snapshots` (n × m, m ≥ 2); see the
/// file comment. One Householder QR of the snapshot matrix is shared by the m
/// solves, which then work on m-row triangular data.
/// \throws InputError if m < 2 or the snapshots are not finite.
ChlsResult chls_leave_one_out(const Eigen::MatrixXd& snapshots, const ChlsOptions& options = {});

}  // namespace contactrom::rom
