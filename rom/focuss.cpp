#include <contactrom/rom/focuss.hpp>

#include <algorithm>
#include <cmath>

namespace contactrom::rom {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

struct IterationResult {
  Status status = Status::Success;
  int iterations = 0;
  int relaxations = 0;
};

/// Factorises a for minimum-norm least-squares solves. For a wide a the complete
/// orthogonal decomposition of a^T is cheaper (its column-pivoted QR runs over the
/// short dimension) and its transposed solve gives the same minimum-norm solution;
/// returns whether a^T was factorised.
bool factorise(Eigen::CompleteOrthogonalDecomposition<MatrixXd>& cod, const MatrixXd& a) {
  if (a.size() == 0) return false;
  if (a.cols() > a.rows()) {
    cod.compute(a.transpose());
    return true;
  }
  cod.compute(a);
  return false;
}

/// Minimum-norm least-squares solution y of a y = rhs, a factorised by factorise().
VectorXd minimum_norm_solve(const Eigen::CompleteOrthogonalDecomposition<MatrixXd>& cod, bool transposed,
                            const MatrixXd& a, const VectorXd& rhs) {
  if (a.size() == 0) return VectorXd::Zero(a.cols());  // no equations or no unknowns
  if (transposed) return cod.transpose().solve(rhs);
  return cod.solve(rhs);
}

/// Sets to exactly zero every entry with |alpha_i| <= tolerance * max|alpha|.
void prune(VectorXd& alpha, double tolerance) {
  if (alpha.size() == 0) return;
  const double threshold = tolerance * alpha.cwiseAbs().maxCoeff();
  for (Index i = 0; i < alpha.size(); ++i) {
    if (std::abs(alpha(i)) <= threshold) alpha(i) = 0.0;
  }
}

std::vector<Index> nonzero_indices(const VectorXd& alpha) {
  std::vector<Index> support;
  for (Index i = 0; i < alpha.size(); ++i) {
    if (alpha(i) != 0.0) support.push_back(i);
  }
  return support;
}

/// The re-weighted minimum-norm iteration shared by FOCUSS and nnFOCUSS; alpha
/// holds the start on entry and the last iterate on return.
IterationResult iterate(const MatrixXd& d, const VectorXd& x, VectorXd& alpha, const FocussOptions& options,
                        bool nonnegative, const FocussCallback& callback) {
  IterationResult result;
  prune(alpha, options.prune_tolerance);
  if (callback) callback(0, alpha);

  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod;
  if (options.rank_tolerance > 0.0) {
    cod.setThreshold(options.rank_tolerance);
  } else {
    cod.setThreshold(Eigen::Default);
  }
  MatrixXd dw;
  VectorXd next(alpha.size());
  for (int k = 1; k <= options.max_iterations; ++k) {
    const std::vector<Index> support = nonzero_indices(alpha);
    if (support.empty()) return result;  // alpha = 0 is a fixed point of the iteration
    const auto s = static_cast<Index>(support.size());

    // Step on the support only: q = (D_S W_S)^+ x (minimum norm), alpha_S = W_S q.
    dw.resize(d.rows(), s);
    for (Index i = 0; i < s; ++i) dw.col(i) = d.col(support[i]) * alpha(support[i]);
    const bool transposed = factorise(cod, dw);
    const VectorXd q = minimum_norm_solve(cod, transposed, dw, x);
    next.setZero();
    for (Index i = 0; i < s; ++i) next(support[i]) = alpha(support[i]) * q(i);
    if (!next.allFinite()) {
      result.status = Status::NumericalIssue;  // alpha keeps the last finite iterate
      return result;
    }
    result.iterations = k;

    bool relaxed = false;
    if (nonnegative && next.minCoeff() < 0.0) {
      // Largest step t along next - alpha keeping alpha >= 0 (alpha_S > 0, so t > 0;
      // some entry of next is negative, so t < 1).
      double step = 1.0;
      Index blocking = -1;
      for (const Index i : support) {
        const double delta = next(i) - alpha(i);
        if (delta >= 0.0) continue;
        const double ratio = alpha(i) / -delta;
        if (blocking < 0 || ratio < step) {
          step = ratio;
          blocking = i;
        }
      }
      next = alpha + step * (next - alpha);
      next = next.cwiseMax(0.0);
      next(blocking) = 0.0;
      relaxed = true;
      ++result.relaxations;
    }
    prune(next, options.prune_tolerance);
    const double change = (next - alpha).norm();
    alpha = next;
    if (callback) callback(k, alpha);
    if (!relaxed && change <= options.tolerance * alpha.norm()) return result;
  }
  result.status = Status::NoConvergence;
  return result;
}

}  // namespace

// ---------------------------------------------------------------------------
// Focuss
// ---------------------------------------------------------------------------

Focuss& Focuss::compute(const MatrixXd& dictionary) {
  m_iterations = 0;
  m_support.clear();
  m_dictionary = dictionary;
  m_computed = dictionary.allFinite();
  if (!m_computed) {
    m_info = Status::InvalidInput;
    return *this;
  }
  if (m_options.rank_tolerance > 0.0) {
    m_cod.setThreshold(m_options.rank_tolerance);
  } else {
    m_cod.setThreshold(Eigen::Default);
  }
  m_cod_transposed = factorise(m_cod, m_dictionary);
  m_info = Status::Success;
  return *this;
}

VectorXd Focuss::solve(const VectorXd& x) {
  if (!m_computed || x.size() != m_dictionary.rows() || !x.allFinite()) {
    m_iterations = 0;
    m_support.clear();
    m_info = Status::InvalidInput;
    return VectorXd::Zero(m_dictionary.cols());
  }
  // Minimum-norm start alpha0 = D^+ x (Gorodnitsky & Rao).
  const VectorXd alpha0 = minimum_norm_solve(m_cod, m_cod_transposed, m_dictionary, x);
  return solve(x, alpha0);
}

VectorXd Focuss::solve(const VectorXd& x, const VectorXd& alpha0) {
  m_iterations = 0;
  m_support.clear();
  const Index n = m_dictionary.cols();
  if (!m_computed || x.size() != m_dictionary.rows() || !x.allFinite() || alpha0.size() != n ||
      !alpha0.allFinite()) {
    m_info = Status::InvalidInput;
    return VectorXd::Zero(n);
  }
  VectorXd alpha = alpha0;
  const IterationResult result = iterate(m_dictionary, x, alpha, m_options, false, m_callback);
  m_info = result.status;
  m_iterations = result.iterations;
  m_support = nonzero_indices(alpha);
  return alpha;
}

// ---------------------------------------------------------------------------
// NnFocuss
// ---------------------------------------------------------------------------

NnFocuss& NnFocuss::compute(const MatrixXd& dictionary) {
  m_iterations = 0;
  m_relaxations = 0;
  m_support.clear();
  m_dictionary = dictionary;
  m_nnls.compute(dictionary);
  m_computed = m_nnls.info() == Status::Success;
  m_info = m_computed ? Status::Success : Status::InvalidInput;
  return *this;
}

VectorXd NnFocuss::solve(const VectorXd& x) {
  if (!m_computed || x.size() != m_dictionary.rows() || !x.allFinite()) {
    m_iterations = 0;
    m_relaxations = 0;
    m_support.clear();
    m_info = Status::InvalidInput;
    return VectorXd::Zero(m_dictionary.cols());
  }
  // The NNLS solution is feasible (>= 0) whatever its status; a NoConvergence of
  // the start only means it is not the NNLS optimum, so the iteration proceeds.
  const VectorXd alpha0 = m_nnls.solve(x);
  return solve(x, alpha0);
}

VectorXd NnFocuss::solve(const VectorXd& x, const VectorXd& alpha0) {
  m_iterations = 0;
  m_relaxations = 0;
  m_support.clear();
  const Index n = m_dictionary.cols();
  if (!m_computed || x.size() != m_dictionary.rows() || !x.allFinite() || alpha0.size() != n ||
      !alpha0.allFinite() || (n > 0 && alpha0.minCoeff() < 0.0)) {
    m_info = Status::InvalidInput;
    return VectorXd::Zero(n);
  }
  VectorXd alpha = alpha0;
  const IterationResult result = iterate(m_dictionary, x, alpha, m_options, true, m_callback);
  m_info = result.status;
  m_iterations = result.iterations;
  m_relaxations = result.relaxations;
  m_support = nonzero_indices(alpha);
  return alpha;
}

}  // namespace contactrom::rom
