#include "rom/pod.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

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

Pod& Pod::compute(const Eigen::MatrixXd& snapshots) {
  m_basis.resize(snapshots.rows(), 0);
  m_sigma.resize(0);
  m_kept_energy = 1.0;
  if (!(m_options.delta >= 0.0) || !snapshots.allFinite()) {
    m_info = Status::InvalidInput;
    return *this;
  }
  if (snapshots.size() == 0) {
    m_sigma = Eigen::VectorXd::Zero(std::min(snapshots.rows(), snapshots.cols()));
    m_info = Status::Success;
    return *this;
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(snapshots, Eigen::ComputeThinU);
  if (svd.info() != Eigen::Success) {
    m_info = Status::NumericalIssue;
    return *this;
  }
  m_sigma = svd.singularValues();
  const double eps = std::numeric_limits<double>::epsilon();
  const double floor =
      m_sigma.size() ? static_cast<double>(std::max(snapshots.rows(), snapshots.cols())) * eps * m_sigma(0) : 0.0;
  int r = pod_truncation_rank(m_sigma, m_options.delta, floor);
  if (m_options.max_rank > 0) r = std::min(r, m_options.max_rank);
  m_basis = svd.matrixU().leftCols(r);
  const double total = m_sigma.squaredNorm();
  m_kept_energy = total > 0.0 ? m_sigma.head(r).squaredNorm() / total : 1.0;
  m_info = Status::Success;
  return *this;
}

}  // namespace contactrom::rom
