#pragma once
/// \file omp.hpp
/// \brief Orthogonal Matching Pursuit (paper, appendix A) in its batch form:
/// greedy selection of dictionary atoms by their correlation with the residual,
/// with the least-squares coefficients on the selected set kept through an
/// incrementally updated Cholesky factor of the atoms' Gram matrix.
///
/// References: Y. C. Pati, R. Rezaiifar, P. S. Krishnaprasad, "Orthogonal matching
/// pursuit", Asilomar 1993; R. Rubinstein, M. Zibulevsky, M. Elad, "Efficient
/// implementation of the K-SVD algorithm using batch orthogonal matching pursuit",
/// Technion CS-2008-08 (batch-OMP). Details in docs/sparse_kernels.md.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/nnls.hpp>

namespace contactrom::rom {

/// \brief Settings of Omp.
struct OmpOptions {
  /// Largest number of atoms selected. A negative value means min(rows, cols) of the
  /// dictionary (enough for an exact fit of any signal in its range); stopping at
  /// that automatic limit without meeting the tolerance counts as NoProgress, while
  /// reaching a limit set here counts as AtomLimit (success). Default -1.
  int max_atoms = -1;
  /// Relative residual tolerance (dimensionless): OMP stops as soon as
  /// \f$\|x - D\alpha\|_2 \le \mathrm{tolerance}\cdot\|x\|_2\f$. Default 1e-8.
  double tolerance = 1e-8;
  /// An atom whose Cholesky pivot \f$1 - \|L^{-1}G_{Ij}\|^2\f$ (squared sine of its
  /// angle to the span of the selected, normalised atoms) is at most this value is
  /// linearly dependent on them; OMP then stops without selecting it. Default 1e-12.
  double dependence_tolerance = 1e-12;
};

/// \brief Why the last Omp::solve() stopped.
enum class OmpStop {
  NotRun,             ///< no solve yet, or invalid input
  ResidualTolerance,  ///< \f$\|r\| \le \mathrm{tol}\,\|x\|\f$ (Status::Success)
  AtomLimit,          ///< the max_atoms set by the user reached (Status::Success)
  NoProgress          ///< no atom can reduce the residual any more: every remaining
                      ///< atom is zero, uncorrelated or linearly dependent on the
                      ///< selected ones (Status::NoConvergence: tolerance not met)
};

/// \brief The name of a stop reason, as `contactrom sparse --json` and Python's
/// SparseResult.stop_reason give it: not_run, residual_tolerance, atom_limit, no_progress.
inline const char* to_string(OmpStop stop) {
  switch (stop) {
    case OmpStop::NotRun: return "not_run";
    case OmpStop::ResidualTolerance: return "residual_tolerance";
    case OmpStop::AtomLimit: return "atom_limit";
    case OmpStop::NoProgress: return "no_progress";
  }
  return "not_run";
}

/// \brief Orthogonal Matching Pursuit, batch form:
/// \f[ \mathcal I \gets \mathcal I \cup \arg\max_j |\hat d_j^T(x - D\alpha)|,\qquad
///     \alpha_{\mathcal I} = (\hat D_{\mathcal I}^T \hat D_{\mathcal I})^{-1}
///     \hat D_{\mathcal I}^T x, \f]
/// with \f$\hat d_j = d_j/\|d_j\|\f$ the normalised columns.
///
/// compute(D) normalises the columns and forms the Gram matrix
/// \f$\hat G = \hat D^T\hat D\f$ (\f$O(mn^2)\f$ flops, \f$n^2\f$ memory), once per
/// dictionary. Each solve(x) then costs one product \f$\hat D^T x\f$ plus, per
/// selected atom, a triangular solve and one product with \f$|\mathcal I|\f$ Gram
/// columns — no least-squares problem is solved from scratch and the residual
/// vector is not formed in the loop (its norm is tracked from the Gram quantities
/// and confirmed exactly near the tolerance).
///
/// The returned coefficients refer to the ORIGINAL (unnormalised) columns:
/// \f$D\alpha \approx x\f$. Zero columns are never selected (coefficient 0); of
/// duplicated columns at most one is selected.
///
/// \code
///   contactrom::rom::OmpOptions options;
///   options.max_atoms = 10;
///   contactrom::rom::Omp omp(options);
///   omp.compute(D);
///   Eigen::VectorXd alpha = omp.solve(x);  // at most 10 non-zeros
/// \endcode
class Omp {
 public:
  using Options = OmpOptions;

  Omp() = default;
  explicit Omp(const Options& options) : m_options(options) {}

  /// \brief Normalises the columns of D and forms their Gram matrix. info() is
  /// InvalidInput if D has a non-finite entry.
  Omp& compute(const Eigen::MatrixXd& dictionary);

  /// \brief Sparse coefficients of x.
  /// \param x signal, size rows(D).
  /// \returns \f$\alpha\f$ (size cols(D)) for the original columns; zeros if info()
  ///          is InvalidInput (wrong size, non-finite x, compute() not successful).
  Eigen::VectorXd solve(const Eigen::VectorXd& x);

  /// \brief Status of the last compute() or solve(): Success when the tolerance or
  /// the atom limit stopped the selection, NoConvergence when no atom could reduce
  /// the residual before the tolerance was met (see stop_reason()).
  Status info() const { return m_info; }
  /// \brief Number of atoms selected by the last solve() (one per iteration).
  int iterations() const { return static_cast<int>(m_support.size()); }
  /// \brief Indices of the selected atoms, in the order of selection.
  const std::vector<Eigen::Index>& support() const { return m_support; }
  /// \brief \f$\|x - D\alpha\|_2\f$ of the last solve(), computed exactly.
  double residual_norm() const { return m_residual_norm; }
  /// \brief Why the last solve() stopped.
  OmpStop stop_reason() const { return m_stop; }

  /// \brief The settings in use.
  const Options& options() const { return m_options; }
  /// \brief Replaces the settings; returns *this for chaining.
  Omp& set_options(const Options& options) {
    m_options = options;
    return *this;
  }

 private:
  /// Batch-OMP's state in solve(): the atoms' correlations with x and with the
  /// residual, the coefficients of the selected (normalised) atoms, |x|² and the
  /// estimate of |r|².
  struct Batch {
    Eigen::VectorXd corr0, corr, gamma, corr0_selected;
    double x_norm2 = 0.0, residual2 = 0.0;
  };
  /// Least squares on the selected atoms after one was appended to the factor.
  void update_least_squares(Batch& b) const;
  /// Support, coefficients of the original columns, residual norm and status.
  Eigen::VectorXd finish(const Eigen::VectorXd& x, const Batch& b, double target2);

  Options m_options;
  Eigen::MatrixXd m_normalised;  ///< \f$\hat D\f$ (zero columns stay zero)
  Eigen::VectorXd m_norms;       ///< \f$\|d_j\|_2\f$
  Eigen::MatrixXd m_gram;        ///< \f$\hat D^T \hat D\f$
  GramCholesky m_factor;
  bool m_computed = false;
  Status m_info = Status::InvalidInput;
  OmpStop m_stop = OmpStop::NotRun;
  std::vector<Eigen::Index> m_support;
  double m_residual_norm = 0.0;
};

}  // namespace contactrom::rom
