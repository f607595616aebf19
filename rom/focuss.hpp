#pragma once
/// \file focuss.hpp
/// \brief FOCUSS (paper, appendix A, Alg. FOCUSS) and its non-negative variant
/// nnFOCUSS (relaxation step of appendix A, started from NNLS).
///
/// References: I. F. Gorodnitsky, B. D. Rao, "Sparse signal reconstruction from
/// limited data using FOCUSS: a re-weighted minimum norm algorithm", IEEE Trans.
/// Signal Process. 45 (1997); nnFOCUSS: R. Lauzeral, D. Borzacchiello, F. Chinesta
/// (2019) and M. Manucci et al. (2022), as cited by the paper. Math and the choices
/// made here are in docs/sparse_kernels.md.
#include <Eigen/Dense>
#include <functional>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/nnls.hpp>

namespace contactrom::rom {

/// \brief Called after the start (iteration 0) and after every iteration k with the
/// iterate \f$\alpha^k\f$ (after pruning and, for nnFOCUSS, relaxation).
using FocussCallback = std::function<void(int iteration, const Eigen::VectorXd& alpha)>;

/// \brief Settings of Focuss and NnFocuss.
struct FocussOptions {
  /// Cap on the number of re-weighted minimum-norm solves. Reaching it gives
  /// Status::NoConvergence and the last iterate. Default 100.
  int max_iterations = 100;
  /// Convergence tolerance (dimensionless): stop when
  /// \f$\|\alpha^k - \alpha^{k-1}\|_2 \le \mathrm{tolerance}\cdot\|\alpha^k\|_2\f$
  /// after a full (unrelaxed) step. Default 1e-10.
  double tolerance = 1e-10;
  /// Pruning threshold (dimensionless): after each iteration, every coefficient with
  /// \f$|\alpha_i| \le \mathrm{prune\_tolerance}\cdot\max_j|\alpha_j|\f$ is set to
  /// exactly 0 and leaves the support for good (its weight would be 0 anyway; pruning
  /// saves the work of carrying collapsing entries). Default 1e-8.
  double prune_tolerance = 1e-8;
  /// Rank threshold of the complete orthogonal decomposition used for the
  /// minimum-norm solves, relative to the largest pivot; 0 selects Eigen's default
  /// (\f$\varepsilon\cdot\min(m, |S|)\f$). Default 0.
  double rank_tolerance = 0.0;
};

/// \brief FOCUSS, the re-weighted minimum-norm iteration
/// \f[ W^k = \mathrm{diag}(\alpha^{k-1}),\qquad \alpha^k = W^k (D W^k)^\dagger x, \f]
/// started from the minimum-norm solution \f$\alpha^0 = D^\dagger x\f$ (or a given
/// \f$\alpha^0\f$). Entries of \f$\alpha^{k-1}\f$ that are zero stay zero, so every
/// step is computed on the current support S only: \f$q = (D_S W_S)^\dagger x\f$ by
/// a complete orthogonal decomposition (Eigen's CompleteOrthogonalDecomposition,
/// which yields the exact minimum-norm least-squares solution, also when
/// \f$D_S W_S\f$ is rank-deficient, e.g. for duplicated columns), then
/// \f$\alpha_S = W_S q\f$. No regularisation parameter is involved.
///
/// For an under-determined D (m < n) the iteration collapses onto a sparse
/// solution of \f$D\alpha = x\f$; once \f$|S| \le m\f$ with independent columns the
/// step is the least-squares solution on S and the iteration stops.
class Focuss {
 public:
  using Options = FocussOptions;

  Focuss() = default;
  explicit Focuss(const Options& options) : m_options(options) {}

  /// \brief Stores D and factorises it (complete orthogonal decomposition) for the
  /// starting point \f$D^\dagger x\f$. info() is InvalidInput if D has a non-finite
  /// entry.
  Focuss& compute(const Eigen::MatrixXd& dictionary);

  /// \brief Runs FOCUSS from \f$\alpha^0 = D^\dagger x\f$.
  /// \returns \f$\alpha\f$ (size cols(D)); zeros if info() is InvalidInput.
  Eigen::VectorXd solve(const Eigen::VectorXd& x);

  /// \brief Runs FOCUSS from a given \f$\alpha^0\f$ (size cols(D); its zero entries
  /// are excluded from the support for good).
  Eigen::VectorXd solve(const Eigen::VectorXd& x, const Eigen::VectorXd& alpha0);

  /// \brief Installs a per-iteration observer (pass {} to remove it).
  Focuss& set_callback(FocussCallback callback) {
    m_callback = std::move(callback);
    return *this;
  }

  /// \brief Status of the last compute() or solve().
  Status info() const { return m_info; }
  /// \brief Number of re-weighted solves of the last solve().
  int iterations() const { return m_iterations; }
  /// \brief Indices of the non-zero coefficients of the last solve(), ascending.
  const std::vector<Eigen::Index>& support() const { return m_support; }

  /// \brief The settings in use.
  const Options& options() const { return m_options; }
  /// \brief Replaces the settings; returns *this for chaining.
  Focuss& set_options(const Options& options) {
    m_options = options;
    return *this;
  }

 private:
  Options m_options;
  FocussCallback m_callback;
  Eigen::MatrixXd m_dictionary;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> m_cod;  ///< of D, or of D^T when D is wide
  bool m_cod_transposed = false;
  bool m_computed = false;
  Status m_info = Status::InvalidInput;
  int m_iterations = 0;
  std::vector<Eigen::Index> m_support;
};

/// \brief nnFOCUSS: FOCUSS with a relaxation that keeps every iterate
/// non-negative, started from the NNLS solution \f$\alpha^0 = \arg\min_{\alpha\ge0}
/// \|D\alpha - x\|\f$ (Lawson–Hanson, see Nnls) or from a given
/// \f$\alpha^0 \ge 0\f$.
///
/// Relaxation (appendix A): when the FOCUSS step \f$\tilde\alpha^k\f$ has a negative
/// entry, the iterate moves from \f$\alpha^{k-1}\f$ along
/// \f$\Delta = \tilde\alpha^k - \alpha^{k-1}\f$ by the largest step that keeps it
/// non-negative,
/// \f[ \alpha^k = \alpha^{k-1} + t\,\Delta,\qquad
///     t = \min_{i:\,\Delta_i<0} \frac{\alpha^{k-1}_i}{-\Delta_i} \in (0, 1), \f]
/// and the blocking entry becomes exactly 0 (leaving the support). The paper writes
/// the same step with \f$\Delta\alpha = -(\tilde\alpha^k-\alpha^{k-1})^-\f$ in the
/// ratio; we read it as this ratio test along the FOCUSS increment. Convergence is
/// only declared after an unrelaxed step, because a relaxed step can be short
/// without the iteration having settled.
class NnFocuss {
 public:
  using Options = FocussOptions;

  NnFocuss() = default;
  explicit NnFocuss(const Options& options, const NnlsOptions& nnls_options = {})
      : m_options(options), m_nnls(nnls_options) {}

  /// \brief Stores D and prepares the NNLS start (forms \f$D^TD\f$ once). info() is
  /// InvalidInput if D has a non-finite entry.
  NnFocuss& compute(const Eigen::MatrixXd& dictionary);

  /// \brief Runs nnFOCUSS from the NNLS solution.
  /// \returns \f$\alpha \ge 0\f$ (size cols(D)); zeros if info() is InvalidInput.
  Eigen::VectorXd solve(const Eigen::VectorXd& x);

  /// \brief Runs nnFOCUSS from a given \f$\alpha^0\f$; InvalidInput unless
  /// \f$\alpha^0 \ge 0\f$ and finite.
  Eigen::VectorXd solve(const Eigen::VectorXd& x, const Eigen::VectorXd& alpha0);

  /// \brief Installs a per-iteration observer (pass {} to remove it).
  NnFocuss& set_callback(FocussCallback callback) {
    m_callback = std::move(callback);
    return *this;
  }

  /// \brief Status of the last compute() or solve().
  Status info() const { return m_info; }
  /// \brief Number of re-weighted solves of the last solve() (NNLS not counted).
  int iterations() const { return m_iterations; }
  /// \brief Number of relaxed (shortened) steps in the last solve().
  int relaxations() const { return m_relaxations; }
  /// \brief Indices of the non-zero coefficients of the last solve(), ascending.
  const std::vector<Eigen::Index>& support() const { return m_support; }
  /// \brief The NNLS solver used for the start (its status and iteration count
  /// refer to the last solve(x)).
  const Nnls& nnls() const { return m_nnls; }

  /// \brief The settings in use.
  const Options& options() const { return m_options; }
  /// \brief Replaces the settings; returns *this for chaining.
  NnFocuss& set_options(const Options& options) {
    m_options = options;
    return *this;
  }

 private:
  Options m_options;
  Nnls m_nnls;
  FocussCallback m_callback;
  Eigen::MatrixXd m_dictionary;
  bool m_computed = false;
  Status m_info = Status::InvalidInput;
  int m_iterations = 0;
  int m_relaxations = 0;
  std::vector<Eigen::Index> m_support;
};

}  // namespace contactrom::rom
