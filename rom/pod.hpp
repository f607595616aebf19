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
/// Two algorithms, chosen by PodOptions::algorithm (by default by size):
///
/// - **SVD**: Eigen's BDCSVD of S itself. The singular values are accurate to
///   \f$ \varepsilon\sigma_1 \f$, whatever their size, but S must be in memory
///   and the cost, \f$ O(n m^2) \f$ on one thread, grows fast (minutes at
///   31k × 2000).
/// - **Method of snapshots with a Rayleigh–Ritz step** (Sirovich 1987, with the
///   refinement of randomised range finders, Halko–Martinsson–Tropp 2011 §5):
///   S is read by blocks of rows (rom/snapshot_blocks.hpp), never whole:
///   1. the Gram matrix \f$ G = S^T S = \sum_b S_b^T S_b \f$ (one pass; threads
///      share the panels of G; MPI ranks sum their rows' share);
///   2. \f$ G = V \Lambda V^T \f$; k = the modes the energy criterion could keep at
///      \f$ 10^{-4}\delta \f$, plus a few, at most those with
///      \f$ \lambda_i > 16\,m\,\varepsilon\,\lambda_1 \f$ (below that G resolves nothing);
///   3. \f$ B = S V_k \Lambda_k^{-1/2} \f$ (second pass), orthonormalised by
///      Cholesky QR twice: Q;
///   4. \f$ Y = Q^T S \f$ (third pass, k × m) and its SVD \f$ Y = \tilde U \Sigma W^T \f$;
///      \f$ \Phi = Q \tilde U_r \f$.
///   The Gram route alone squares the condition number (a mode with
///   \f$ \sigma_i = 10^{-5}\sigma_1 \f$, kept at δ = 1e-10, would get only about six
///   correct digits); step 4 computes the singular values of the projection of S
///   itself, so they are accurate to \f$ \varepsilon\sigma_1 \f$ like the SVD's, and
///   the modes as well. The values beyond k (not kept at δ) are \f$ \sqrt{\lambda_i} \f$,
///   accurate to about \f$ \sqrt{m\varepsilon}\,\sigma_1 \f$: enough for the discarded
///   energy, not for δ below about 1e-12 (use the SVD there). Cost: \f$ n m^2 \f$ for
///   G (half a GEMM), \f$ 2nmk \f$ for passes 2–3; memory m² + one block.
///
/// The discarded energy is summed from the smallest singular value up, so the
/// criterion is evaluated accurately even for δ close to machine precision.
///
/// Singular values below the numerical rank threshold
/// \f$ \max(n, m)\,\varepsilon\,\sigma_1 \f$ are never kept (they are rounding
/// noise, and their singular vectors are arbitrary), so δ = 0 gives the
/// numerical rank.
#include <Eigen/Dense>
#include <cstdint>

#include <contactrom/core/errors.hpp>
#include <contactrom/rom/snapshot_blocks.hpp>

namespace contactrom::rom {

/// \brief Which algorithm Pod uses (file comment).
enum class PodAlgorithm {
  Auto,       ///< SVD when n·m ≤ PodOptions::svd_max_entries or m ≥ n, else method of snapshots
  Svd,        ///< BDCSVD of the whole matrix (read into memory)
  Snapshots   ///< method of snapshots with a Rayleigh–Ritz step, by blocks of rows
};

/// \brief Sums partial results over the processes that share one POD, each holding
/// a range of the snapshot matrix's rows (MPI ranks: rom/pod_mpi.hpp). The method of
/// snapshots calls it collectively; the SVD cannot be shared.
class PodReduction {
 public:
  virtual ~PodReduction() = default;
  /// Index of this process (0 ≤ rank < size).
  virtual int rank() const = 0;
  /// Number of processes.
  virtual int size() const = 0;
  /// Replaces `m` by the sum of every process' `m` (same size everywhere).
  virtual void sum(Eigen::MatrixXd& m) const = 0;
  /// Rows of every process stacked in rank order, on rank 0 (an empty matrix elsewhere).
  virtual Eigen::MatrixXd gather_rows(const Eigen::MatrixXd& local) const = 0;
};

/// \brief Settings of Pod.
struct PodOptions {
  /// Energy tolerance δ ≥ 0: discarded energy ≤ δ × total energy (dimensionless).
  /// Default 1e-8.
  double delta = 1e-8;
  /// Upper bound on the rank (≤ 0: no bound). Default 0.
  int max_rank = 0;
  /// Algorithm. Default Auto.
  PodAlgorithm algorithm = PodAlgorithm::Auto;
  /// Largest snapshot matrix (entries n·m) that Auto gives to the SVD. Default 2²⁴
  /// (128 MB): the shipped meshes' databases keep the SVD's results exactly. A wide
  /// set (m ≥ n snapshots) goes to the SVD at any size: its m × m Gram matrix would be
  /// no smaller than the data.
  std::int64_t svd_max_entries = std::int64_t{1} << 24;
  /// Bytes of snapshot data read per block by the method of snapshots. Default 64 MiB.
  std::int64_t block_bytes = std::int64_t{64} << 20;
  /// Worker threads of the method of snapshots (≤ 0: hardware concurrency). Default 0.
  int threads = 0;
  /// The processes sharing the rows (nullptr: this process holds them all). Default nullptr.
  const PodReduction* reduction = nullptr;
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

  /// \brief The same for a matrix read by blocks (the method of snapshots never holds
  /// it whole). With PodOptions::reduction the call is collective: every process
  /// passes the whole matrix's source and reads its share of the rows (row_share);
  /// basis() then holds the whole basis on rank 0 and this process' rows elsewhere.
  Pod& compute(const SnapshotBlocks& snapshots);

  /// \brief Whether compute() of an n × m matrix takes the SVD.
  bool uses_svd(Eigen::Index n, Eigen::Index m) const;

  /// \brief \f$ \Phi^T S \f$ (rank() × m), the snapshots' coordinates in the basis
  /// (method of snapshots: from its last pass; SVD: \f$ \Sigma_r V_r^T \f$).
  const Eigen::MatrixXd& coordinates() const { return m_coords; }

  /// \brief Orthonormal basis \f$ \Phi \f$ (n × rank()).
  const Eigen::MatrixXd& basis() const { return m_basis; }
  /// \brief All singular values of the snapshot matrix, decreasing (min(n, m)).
  const Eigen::VectorXd& singular_values() const { return m_sigma; }
  /// \brief Number of kept modes r.
  int rank() const { return static_cast<int>(m_coords.rows()); }
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
  void compute_svd(const Eigen::MatrixXd& snapshots);
  void compute_by_snapshots(const SnapshotBlocks& snapshots);
  void truncate(Eigen::Index n, Eigen::Index m, int resolved);  // sets m_truncation, m_kept_energy
  int rank_of_truncation() const { return m_truncation; }

  Eigen::MatrixXd m_basis, m_coords;
  Eigen::VectorXd m_sigma;
  double m_kept_energy = 1.0;
  int m_truncation = 0;
  Status m_info = Status::InvalidInput;
};

}  // namespace contactrom::rom
