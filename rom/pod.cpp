#include <contactrom/rom/pod.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <contactrom/core/parallel_for.hpp>

namespace contactrom::rom {

int pod_truncation_rank(const Eigen::VectorXd& sigma, double delta, double floor) {
  const int m = static_cast<int>(sigma.size());
  // Numerical rank: never keep singular values at or below the floor.
  int numerical = 0;
  while (numerical < m && sigma(numerical) > floor) ++numerical;
  if (numerical == 0) return 0;
  // Energies summed from the smallest value up, so that the discarded energy
  // (a small number compared with the total) is formed without cancellation.
  Eigen::VectorXd tail(m + 1);  // tail(r) = Σ_{i ≥ r} σ_i²
  tail(m) = 0.0;
  for (int i = m - 1; i >= 0; --i) tail(i) = tail(i + 1) + sigma(i) * sigma(i);
  const double total = tail(0);
  for (int r = 0; r < numerical; ++r)
    if (tail(r) <= delta * total) return r;
  return numerical;
}

namespace {

/// Width of the column panels that threads share (fixed, so that results do not
/// depend on the thread count).
constexpr Eigen::Index kPanel = 64;
/// Rows per task of the second pass.
constexpr Eigen::Index kRowChunk = 512;
/// The Ritz subspace is sized for this fraction of δ, plus kOversample modes.
constexpr double kRitzDeltaFactor = 1e-4;
constexpr int kOversample = 8;
/// Rayleigh–Ritz rounds (see compute_by_snapshots).
constexpr int kRitzRounds = 2;
/// Gram eigenvalues below kGramResolution · m · ε · λ₁ carry no information.
constexpr double kGramResolution = 16.0;

int panels(Eigen::Index m) { return static_cast<int>((m + kPanel - 1) / kPanel); }

/// Lower triangle of g += xᵀx, panel by panel on `threads` threads.
void gram_update(Eigen::MatrixXd& g, const Eigen::MatrixXd& x, int threads) {
  const Eigen::Index m = x.cols();
  parallel_for(panels(m), threads, [&](int p) {
    const Eigen::Index j0 = p * kPanel, w = std::min(kPanel, m - j0);
    g.block(j0, j0, m - j0, w).noalias() += x.rightCols(m - j0).transpose() * x.middleCols(j0, w);
  });
}

}  // namespace

bool Pod::uses_svd(Eigen::Index n, Eigen::Index m) const {
  if (m_options.reduction && m_options.reduction->size() > 1) return false;
  switch (m_options.algorithm) {
    case PodAlgorithm::Svd: return true;
    case PodAlgorithm::Snapshots: return false;
    case PodAlgorithm::Auto: break;
  }
  // A wide set: the method of snapshots' m × m Gram matrix would be no smaller than
  // the data, and its eigen-decomposition costs O(m³) against the SVD's O(n² m).
  if (m >= n) return true;
  return static_cast<double>(n) * static_cast<double>(m) <= static_cast<double>(m_options.svd_max_entries);
}

Pod& Pod::compute(const Eigen::MatrixXd& snapshots) {
  if (!snapshots.allFinite()) {
    m_basis.resize(snapshots.rows(), 0);
    m_sigma.resize(0);
    m_coords.resize(0, snapshots.cols());
    m_info = Status::InvalidInput;
    return *this;
  }
  return compute(MatrixBlocks(snapshots));
}

Pod& Pod::compute(const SnapshotBlocks& snapshots) {
  const Eigen::Index n = snapshots.rows(), m = snapshots.cols();
  m_basis.resize(n, 0);
  m_coords.resize(0, m);
  m_sigma.resize(0);
  m_kept_energy = 1.0;
  if (!(m_options.delta >= 0.0) ||
      (m_options.algorithm == PodAlgorithm::Svd && m_options.reduction && m_options.reduction->size() > 1)) {
    m_info = Status::InvalidInput;
    return *this;
  }
  m_info = Status::Success;
  if (uses_svd(n, m)) {
    const Eigen::MatrixXd x = snapshots.read_all();
    if (!x.allFinite()) {
      m_info = Status::InvalidInput;
      return *this;
    }
    compute_svd(x);
  } else {
    compute_by_snapshots(snapshots);
  }
  return *this;
}

void Pod::compute_svd(const Eigen::MatrixXd& snapshots) {
  if (snapshots.size() == 0) {
    m_sigma = Eigen::VectorXd::Zero(std::min(snapshots.rows(), snapshots.cols()));
    return;
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(snapshots, Eigen::ComputeThinU);
  if (svd.info() != Eigen::Success) {
    m_info = Status::NumericalIssue;
    return;
  }
  m_sigma = svd.singularValues();
  truncate(snapshots.rows(), snapshots.cols(), static_cast<int>(m_sigma.size()));
  m_basis = svd.matrixU().leftCols(rank_of_truncation());
  m_coords = m_basis.transpose() * snapshots;
}

void Pod::compute_by_snapshots(const SnapshotBlocks& whole) {
  const PodReduction* red = m_options.reduction && m_options.reduction->size() > 1 ? m_options.reduction : nullptr;
  // With a reduction, this process reads its share of the rows only.
  const auto [begin, end] = red ? row_share(whole.rows(), red->rank(), red->size())
                                : std::pair<Eigen::Index, Eigen::Index>{0, whole.rows()};
  const RowRangeBlocks x(whole, begin, end - begin);
  const Eigen::Index n = x.rows(), m = x.cols();
  Eigen::MatrixXd total_rows = Eigen::MatrixXd::Constant(1, 1, static_cast<double>(n));
  if (red) red->sum(total_rows);
  const auto n_global = static_cast<Eigen::Index>(total_rows(0, 0));
  if (n_global == 0 || m == 0) {
    m_sigma = Eigen::VectorXd::Zero(std::min(n_global, m));
    return;
  }
  const int threads = resolve_threads(m_options.threads);
  const Eigen::Index block = std::clamp<Eigen::Index>(
      static_cast<Eigen::Index>(m_options.block_bytes / static_cast<std::int64_t>(sizeof(double) * m)), 1,
      std::max<Eigen::Index>(n, 1));
  bool finite = true;
  Eigen::MatrixXd xb;
  const auto each_block = [&](const std::function<void(Eigen::Index first)>& use) {
    for (Eigen::Index first = 0; first < n; first += block) {
      x.read_rows(first, std::min(block, n - first), xb);
      finite = finite && xb.allFinite();
      use(first);
    }
  };

  // Pass 1: the Gram matrix and its eigenpairs, largest first.
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(m, m);
  each_block([&](Eigen::Index) { gram_update(g, xb, threads); });
  if (red) red->sum(g);
  if (!finite) {
    m_info = Status::InvalidInput;
    return;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(g, Eigen::ComputeEigenvectors);  // reads the lower triangle
  if (eig.info() != Eigen::Success) {
    m_info = Status::NumericalIssue;
    return;
  }
  g.resize(0, 0);
  const Eigen::VectorXd lambda = eig.eigenvalues().reverse().cwiseMax(0.0);
  const Eigen::MatrixXd v = eig.eigenvectors().rowwise().reverse();
  m_sigma = lambda.head(std::min(n_global, m)).cwiseSqrt();
  if (lambda(0) <= 0.0) return;  // a zero matrix

  // The Ritz subspace: what the criterion could keep at a smaller δ, within what G resolves.
  const double resolution = kGramResolution * static_cast<double>(m) * std::numeric_limits<double>::epsilon() * lambda(0);
  int resolved = 0;
  while (resolved < m_sigma.size() && lambda(resolved) > resolution) ++resolved;
  const int k = std::min(resolved, pod_truncation_rank(m_sigma, kRitzDeltaFactor * m_options.delta,
                                                       std::sqrt(resolution)) + kOversample);

  // Rayleigh–Ritz rounds: B = S W (first W = V_k Λ_k^{-1/2}, then the right singular
  // vectors of the previous round's Y over its singular values), orthonormalised by
  // Cholesky QR twice (Q), then Y = Qᵀ S and its SVD. The first round inherits the
  // Gram matrix's errors in V (directions of S beyond k leak into B by about
  // ε λ₁/λ_i · σ_j/σ_i); the second starts from vectors computed from S itself.
  Eigen::MatrixXd w = v.leftCols(k) * lambda.head(k).cwiseSqrt().cwiseInverse().asDiagonal();
  Eigen::MatrixXd q, y;
  Eigen::BDCSVD<Eigen::MatrixXd> svd;
  for (int round = 0; round < kRitzRounds; ++round) {
    const Eigen::Index kw = w.cols();
    q.resize(n, kw);
    each_block([&](Eigen::Index first) {  // B = S W
      const Eigen::Index rows = xb.rows();
      parallel_for(static_cast<int>((rows + kRowChunk - 1) / kRowChunk), threads, [&](int c) {
        const Eigen::Index i0 = c * kRowChunk, h = std::min(kRowChunk, rows - i0);
        q.middleRows(first + i0, h).noalias() = xb.middleRows(i0, h) * w;
      });
    });
    for (int pass = 0; pass < 2; ++pass) {  // Cholesky QR, twice
      Eigen::MatrixXd c = Eigen::MatrixXd::Zero(kw, kw);
      for (Eigen::Index first = 0; first < n; first += block)
        gram_update(c, q.middleRows(first, std::min(block, n - first)), threads);
      if (red) red->sum(c);
      const Eigen::LLT<Eigen::MatrixXd> llt(c);
      if (llt.info() != Eigen::Success) {
        m_info = Status::NumericalIssue;
        return;
      }
      const Eigen::MatrixXd r_inv = llt.matrixU().solve(Eigen::MatrixXd::Identity(kw, kw));
      parallel_for(static_cast<int>((n + kRowChunk - 1) / kRowChunk), threads, [&](int c) {
        const Eigen::Index first = c * kRowChunk, h = std::min(kRowChunk, n - first);
        q.middleRows(first, h) = (q.middleRows(first, h) * r_inv).eval();
      });
    }
    y = Eigen::MatrixXd::Zero(kw, m);
    each_block([&](Eigen::Index first) {  // Y = Qᵀ S
      const auto qb = q.middleRows(first, xb.rows());
      parallel_for(panels(m), threads, [&](int p) {
        const Eigen::Index j0 = p * kPanel, wd = std::min(kPanel, m - j0);
        y.middleCols(j0, wd).noalias() += qb.transpose() * xb.middleCols(j0, wd);
      });
    });
    if (red) red->sum(y);
    svd.compute(y, Eigen::ComputeThinU | Eigen::ComputeThinV);
    if (svd.info() != Eigen::Success || !finite) {
      m_info = finite ? Status::NumericalIssue : Status::InvalidInput;
      return;
    }
    // The next round's W: the Ritz right vectors whose values G resolves.
    Eigen::Index kn = 0;
    while (kn < svd.singularValues().size() && svd.singularValues()(kn) > std::sqrt(resolution)) ++kn;
    w = svd.matrixV().leftCols(kn) * svd.singularValues().head(kn).cwiseInverse().asDiagonal();
  }
  const Eigen::Index ky = svd.singularValues().size();
  m_sigma.head(ky) = svd.singularValues();
  for (Eigen::Index i = ky; i < m_sigma.size(); ++i) m_sigma(i) = std::min(m_sigma(i), m_sigma(i - 1));
  truncate(n_global, m, static_cast<int>(ky));
  const int r = rank_of_truncation();
  m_basis = q * svd.matrixU().leftCols(r);  // q, y, svd: the last round's
  m_coords = svd.matrixU().leftCols(r).transpose() * y;
  if (red) {
    Eigen::MatrixXd all = red->gather_rows(m_basis);
    if (red->rank() == 0) m_basis = std::move(all);
  }
}

void Pod::truncate(Eigen::Index n, Eigen::Index m, int resolved) {
  const double eps = std::numeric_limits<double>::epsilon();
  const double floor = m_sigma.size() ? static_cast<double>(std::max(n, m)) * eps * m_sigma(0) : 0.0;
  int r = std::min(pod_truncation_rank(m_sigma, m_options.delta, floor), resolved);
  if (m_options.max_rank > 0) r = std::min(r, m_options.max_rank);
  m_truncation = r;
  const double total = m_sigma.squaredNorm();
  m_kept_energy = total > 0.0 ? m_sigma.head(r).squaredNorm() / total : 1.0;
}

}  // namespace contactrom::rom
