#pragma once
/// \file pod.hpp
/// \brief Proper orthogonal decomposition with an energy criterion.
///
/// Given snapshots \f$ S = [s_1, \dots, s_m] \in \mathbb{R}^{n\times m} \f$ with
/// thin SVD \f$ S = U \Sigma V^T \f$, the POD basis of tolerance δ is
/// \f$ \Phi = U[:, 1..r] \f$ with the smallest r such that the discarded energy
/// satisfies \f$ \sum_{i>r} \sigma_i^2 \le \delta \sum_i \sigma_i^2 \f$, i.e. the
/// kept energy is at least 1 − δ (paper §3, "svd(D_p, δ)").
///
/// Implementation choice (docs/rom.md): Eigen's BDCSVD of S itself, not an
/// eigen-decomposition of the Gram matrix \f$ S^T S \f$: the Gram route squares
/// the condition number, so modes with \f$ \sigma_i/\sigma_1 \lesssim 10^{-8} \f$
/// (needed for δ = 1e-10 … 1e-16) lose their orthogonality, whereas the SVD
/// delivers them to working accuracy. The cost (\f$ O(n m^2) \f$ for n ≫ m) is an
/// offline cost of milliseconds for the problems of this project. The discarded
/// energy is summed from the smallest singular value up, so the criterion is
/// evaluated accurately even for δ close to machine precision.
///
/// Singular values below the numerical rank threshold
/// \f$ \max(n, m)\,\varepsilon\,\sigma_1 \f$ are never kept (they are rounding
/// noise, and their singular vectors are arbitrary), so δ = 0 gives the
/// numerical rank.
#include <Eigen/Dense>

#include "core/errors.hpp"

namespace contactrom::rom {

/// \brief Settings of Pod.
struct PodOptions {
  /// Energy tolerance δ ≥ 0: discarded energy ≤ δ × total energy (dimensionless).
  /// Default 1e-8.
  double delta = 1e-8;
  /// Upper bound on the rank (≤ 0: no bound). Default 0.
  int max_rank = 0;
};

/// \brief Smallest r with \f$ \sum_{i \ge r} \sigma_i^2 \le \delta \sum_i \sigma_i^2 \f$
/// (0-based sum over the discarded values), given singular values in decreasing
/// order; values below the numerical-rank threshold `floor` are never counted as kept.
int pod_truncation_rank(const Eigen::VectorXd& singular_values, double delta, double floor = 0.0);

/// \brief POD of a snapshot matrix; see the file comment.
///
/// \code
///   contactrom::rom::PodOptions options;
///   options.delta = 1e-10;
///   contactrom::rom::Pod pod(options);
///   pod.compute(S);                  // S: n × m snapshots (columns)
///   const Eigen::MatrixXd& phi = pod.basis();   // n × r, orthonormal columns
/// \endcode
class Pod {
 public:
  using Options = PodOptions;

  Pod() = default;
  explicit Pod(const Options& options) : m_options(options) {}

  /// \brief Computes the SVD of `snapshots` (n × m, snapshots as columns) and the
  /// truncated basis. info() is InvalidInput for a negative δ or non-finite data,
  /// NumericalIssue if the SVD fails.
  Pod& compute(const Eigen::MatrixXd& snapshots);

  /// \brief Orthonormal basis \f$ \Phi \f$ (n × rank()).
  const Eigen::MatrixXd& basis() const { return m_basis; }
  /// \brief All singular values of the snapshot matrix, decreasing (min(n, m)).
  const Eigen::VectorXd& singular_values() const { return m_sigma; }
  /// \brief Number of kept modes r.
  int rank() const { return static_cast<int>(m_basis.cols()); }
  /// \brief Fraction of the energy kept, \f$ \sum_{i<r}\sigma_i^2 / \sum_i \sigma_i^2 \f$
  /// (1 for a zero snapshot matrix).
  double kept_energy() const { return m_kept_energy; }
  /// \brief Outcome of the last compute().
  Status info() const { return m_info; }

  const Options& options() const { return m_options; }
  /// \brief Replaces the settings; returns *this for chaining.
  Pod& set_options(const Options& options) {
    m_options = options;
    return *this;
  }

 private:
  Options m_options;
  Eigen::MatrixXd m_basis;
  Eigen::VectorXd m_sigma;
  double m_kept_energy = 1.0;
  Status m_info = Status::InvalidInput;
};

}  // namespace contactrom::rom
