#pragma once
/// \file dual_qp.hpp
/// \brief Bound-constrained dual contact QP
/// \f[ \min_{\lambda \ge 0} \tfrac12 \lambda^T G \lambda - h^T \lambda , \f]
/// equivalently the LCP \f$ \lambda \ge 0,\ w = G\lambda - h \ge 0,\ \lambda^T w = 0 \f$,
/// where \f$ G = C K^{-1} C^T \f$ is the (dense, small) Delassus matrix of the
/// contact surface and \f$ -w \f$ is the gap of the primal solution.
///
/// Solved by the primal–dual active-set method (Hintermüller, Ito, Kunisch 2003,
/// "The primal-dual active set strategy as a semismooth Newton method"): the
/// active set is \f$ \{ i : \lambda_i - c\,w_i > 0 \} \f$; each iteration solves
/// one dense SPD system on the active set. PDAS converges superlinearly and
/// terminates finitely for M-matrices but may cycle otherwise; a repeated active
/// set switches to the Lawson–Hanson primal active-set method (NnlsQp,
/// core/nnls.hpp, on the rows that may become active), which terminates for any
/// positive semi-definite G. So does a stable active set whose rows keep a gap
/// (G singular on it, dependent rows: PDAS's least-squares step cannot close it).
#include <Eigen/Dense>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom::fom {

/// \brief Options of DualQpSolver.
struct DualQpOptions {
  int max_iterations = 500;        ///< cap on active-set changes (PDAS + fallback), default 500
  double relative_tolerance = 1e-13;  ///< gap/multiplier sign tolerance relative to |h|∞ and |G|, default 1e-13
};

/// \brief Solver of the dual contact QP; see the file comment.
class DualQpSolver {
 public:
  explicit DualQpSolver(DualQpOptions options = {}) : m_options(options) {}

  /// \brief Solves the QP.
  /// \param g Delassus matrix (n x n, symmetric positive semi-definite)
  /// \param h right-hand side (n)
  /// \param eligible rows that may become active (size n; empty: all)
  /// \param warm_start previous multipliers whose support seeds the active set (may be empty)
  /// \returns multipliers λ (n), zero outside the active set
  Eigen::VectorXd solve(const Eigen::MatrixXd& g, const Eigen::VectorXd& h, const std::vector<char>& eligible,
                        const Eigen::VectorXd& warm_start);

  Status info() const { return m_info; }
  /// Number of active-set iterations of the last solve.
  int iterations() const { return m_iterations; }
  /// Whether the last solve fell back to Lawson–Hanson after PDAS cycled.
  bool used_fallback() const { return m_fallback; }

 private:
  bool solve_on(const Eigen::MatrixXd& g, const Eigen::VectorXd& h, const std::vector<int>& set, Eigen::VectorXd& z);
  bool active_gaps_close(const Eigen::VectorXd& w, const Eigen::VectorXd& h, const std::vector<char>& active,
                         double scale) const;
  Eigen::VectorXd lawson_hanson(const Eigen::MatrixXd& g, const Eigen::VectorXd& h, const std::vector<char>& eligible);

  DualQpOptions m_options;
  Status m_info = Status::Success;
  int m_iterations = 0;
  bool m_fallback = false;
  // Working arrays of solve(), kept between solves.
  std::vector<char> m_eligible, m_active, m_next, m_seen;
  std::vector<int> m_set;
  Eigen::MatrixXd m_gs;
  Eigen::VectorXd m_hs, m_z, m_w;
  Eigen::LLT<Eigen::MatrixXd> m_llt;
};

}  // namespace contactrom::fom
