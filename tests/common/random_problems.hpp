#pragma once
// Seeded random test data shared by the sparse-kernel tests (NNLS, OMP, FOCUSS,
// CHLS and the `contactrom sparse` CLI): Gaussian matrices, dictionaries with
// spread column norms and planted sparse coefficient vectors.
#include <Eigen/Dense>
#include <algorithm>
#include <cstddef>
#include <random>
#include <set>
#include <vector>

namespace contactrom::test {

/// rows × cols matrix of independent standard normal entries.
inline Eigen::MatrixXd gaussian(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& gen) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(rows, cols);
  for (Eigen::Index i = 0; i < a.size(); ++i) a(i) = normal(gen);
  return a;
}

/// Gaussian dictionary whose columns are scaled by factors in [0.5, 2], so that
/// returned coefficients must be those of the original (unnormalised) columns.
inline Eigen::MatrixXd scaled_dictionary(Eigen::Index m, Eigen::Index n, std::mt19937_64& gen) {
  std::uniform_real_distribution<double> scale(0.5, 2.0);
  Eigen::MatrixXd d = gaussian(m, n, gen);
  for (Eigen::Index j = 0; j < n; ++j) d.col(j) *= scale(gen);
  return d;
}

/// k-sparse vector of size n with magnitudes in [1, 2] on a random support (written
/// to `support`); random signs unless `non_negative`.
inline Eigen::VectorXd planted(Eigen::Index n, Eigen::Index k, bool non_negative, std::mt19937_64& gen,
                               std::set<Eigen::Index>& support) {
  std::vector<Eigen::Index> columns(static_cast<std::size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j) columns[static_cast<std::size_t>(j)] = j;
  std::shuffle(columns.begin(), columns.end(), gen);
  std::uniform_real_distribution<double> magnitude(1.0, 2.0);
  std::bernoulli_distribution sign;
  Eigen::VectorXd a = Eigen::VectorXd::Zero(n);
  support.clear();
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::Index j = columns[static_cast<std::size_t>(i)];
    a(j) = (non_negative || sign(gen)) ? magnitude(gen) : -magnitude(gen);
    support.insert(j);
  }
  return a;
}

/// The entries of `v` as a set (support comparisons).
inline std::set<Eigen::Index> as_set(const std::vector<Eigen::Index>& v) {
  return std::set<Eigen::Index>(v.begin(), v.end());
}

}  // namespace contactrom::test
