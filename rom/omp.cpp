#include <contactrom/rom/omp.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace contactrom::rom {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

Omp& Omp::compute(const MatrixXd& dictionary) {
  m_support.clear();
  m_stop = OmpStop::NotRun;
  m_residual_norm = 0.0;
  m_computed = dictionary.allFinite();
  if (!m_computed) {
    m_normalised = MatrixXd::Zero(dictionary.rows(), dictionary.cols());
    m_norms = VectorXd::Zero(dictionary.cols());
    m_gram.resize(0, 0);
    m_info = Status::InvalidInput;
    return *this;
  }
  m_norms = dictionary.colwise().norm().transpose();
  m_normalised = dictionary;
  for (Index j = 0; j < dictionary.cols(); ++j) {
    // A zero column stays zero: its correlation is always 0 and it is never selected.
    if (m_norms(j) > 0.0) m_normalised.col(j) /= m_norms(j);
  }
  m_gram = gram_matrix(m_normalised);
  m_info = Status::Success;
  return *this;
}

namespace {

/// The unselected atom of largest |correlation| with the residual; −1 if none is
/// correlated (a zero column never is).
Index most_correlated_atom(const VectorXd& corr, const VectorXd& norms, const std::vector<char>& selected) {
  Index best = -1;
  double best_corr = 0.0;
  for (Index j = 0; j < corr.size(); ++j) {
    if (selected[static_cast<std::size_t>(j)] || !(norms(j) > 0.0)) continue;
    const double cj = std::abs(corr(j));
    if (cj > best_corr) {
      best_corr = cj;
      best = j;
    }
  }
  return best;
}

/// ‖x − D̂_I γ‖², formed from the atoms (O(m|I|)).
double exact_residual2(const VectorXd& x, const MatrixXd& normalised, const GramCholesky& factor, const VectorXd& gamma) {
  VectorXd r = x;
  for (Index i = 0; i < factor.size(); ++i) r.noalias() -= normalised.col(factor.indices()[i]) * gamma(i);
  return r.squaredNorm();
}

}  // namespace

VectorXd Omp::solve(const VectorXd& x) {
  m_support.clear();
  m_residual_norm = 0.0;
  m_stop = OmpStop::NotRun;
  const Index n = m_normalised.cols();
  if (!m_computed || x.size() != m_normalised.rows() || !x.allFinite()) {
    m_info = Status::InvalidInput;
    return VectorXd::Zero(n);
  }
  const bool user_cap = m_options.max_atoms >= 0;
  const Index cap = user_cap ? std::min<Index>(m_options.max_atoms, n) : std::min(m_normalised.rows(), n);
  m_factor.reset(cap);
  Batch b;
  b.corr0 = m_normalised.transpose() * x;
  b.corr = b.corr0;
  b.x_norm2 = b.residual2 = x.squaredNorm();
  std::vector<char> selected(static_cast<std::size_t>(n), 0);
  const double target2 = std::pow(m_options.tolerance, 2) * b.x_norm2;
  // Batch-OMP tracks |r|^2 = |x|^2 - gamma^T corr0_I without forming r. That
  // difference loses about eps·cond(G_II)·|x|^2 to cancellation, so once the
  // estimate is within sqrt(eps)·|x|^2 of the target (safe up to cond ~ 1e8) the
  // residual is formed exactly before deciding to stop.
  const double estimate_band = std::sqrt(std::numeric_limits<double>::epsilon()) * b.x_norm2;

  while (true) {
    const Index k = m_factor.size();
    if (b.residual2 <= target2 + estimate_band) {
      b.residual2 = k == 0 ? b.x_norm2 : exact_residual2(x, m_normalised, m_factor, b.gamma);
      if (b.residual2 <= target2) {
        m_stop = OmpStop::ResidualTolerance;
        break;
      }
    }
    if (k >= cap) {
      m_stop = user_cap && k == m_options.max_atoms ? OmpStop::AtomLimit : OmpStop::NoProgress;
      break;
    }
    // Greedy selection: the atom least orthogonal to the residual. None correlated,
    // or the best one a combination of the selected atoms (e.g. a duplicate): the
    // residual cannot be reduced further.
    const Index best = most_correlated_atom(b.corr, m_norms, selected);
    if (best < 0 || !m_factor.append(m_gram, best, m_options.dependence_tolerance)) {
      m_stop = OmpStop::NoProgress;
      break;
    }
    selected[static_cast<std::size_t>(best)] = 1;
    update_least_squares(b);
  }
  return finish(x, b, target2);
}

void Omp::update_least_squares(Batch& b) const {
  // Least squares on the selected set through the updated Cholesky factor:
  // G_II gamma = corr0_I, then corr = corr0 - G_{:,I} gamma.
  const Index size = m_factor.size();
  b.corr0_selected.resize(size);
  for (Index i = 0; i < size; ++i) b.corr0_selected(i) = b.corr0(m_factor.indices()[i]);
  b.gamma = b.corr0_selected;
  m_factor.solve_in_place(b.gamma);
  b.corr = b.corr0;
  for (Index i = 0; i < size; ++i) b.corr.noalias() -= m_gram.col(m_factor.indices()[i]) * b.gamma(i);
  b.residual2 = std::max(0.0, b.x_norm2 - b.gamma.dot(b.corr0_selected));
}

VectorXd Omp::finish(const VectorXd& x, const Batch& b, double target2) {
  VectorXd alpha = VectorXd::Zero(m_normalised.cols());
  m_support = m_factor.indices();
  for (Index i = 0; i < static_cast<Index>(m_support.size()); ++i) alpha(m_support[i]) = b.gamma(i) / m_norms(m_support[i]);
  m_residual_norm = std::sqrt(m_support.empty() ? b.x_norm2 : exact_residual2(x, m_normalised, m_factor, b.gamma));
  if (m_stop == OmpStop::NoProgress && m_residual_norm * m_residual_norm <= target2) m_stop = OmpStop::ResidualTolerance;
  m_info = m_stop == OmpStop::NoProgress ? Status::NoConvergence : Status::Success;
  return alpha;
}

}  // namespace contactrom::rom
