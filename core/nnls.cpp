#include <contactrom/core/nnls.hpp>

#include <contactrom/core/lawson_hanson.hpp>

#include <algorithm>
#include <cmath>

namespace contactrom {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

MatrixXd gram_matrix(const MatrixXd& a) {
  MatrixXd gram = MatrixXd::Zero(a.cols(), a.cols());
  if (a.size() == 0) return gram;  // no rows or no columns (Eigen's kernel must not see null data)
  gram.selfadjointView<Eigen::Lower>().rankUpdate(a.transpose());
  gram.triangularView<Eigen::StrictlyUpper>() = gram.transpose();
  return gram;
}

// ---------------------------------------------------------------------------
// GramCholesky
// ---------------------------------------------------------------------------

GramCholesky::GramCholesky(Index capacity) { reset(capacity); }

void GramCholesky::reset(Index capacity) {
  if (m_r.rows() < capacity) m_r.resize(capacity, capacity);
  m_indices.clear();
  m_indices.reserve(static_cast<std::size_t>(capacity));
}

bool GramCholesky::append(const MatrixXd& gram, Index j, double dependence_tolerance) {
  const Index k = size();
  if (k >= m_r.rows()) {
    // More indices than announced: grow geometrically, keeping R.
    const Index capacity = std::max<Index>(2 * m_r.rows(), k + 1);
    m_r.conservativeResize(capacity, capacity);
  }
  const double g_jj = gram(j, j);
  if (!(g_jj > 0.0)) return false;  // zero (or invalid) column: never part of a basis

  // New last column of R: R^T r = G_Ij; new pivot d^2 = G_jj - |r|^2.
  auto r = m_r.col(k).head(k);
  for (Index i = 0; i < k; ++i) r(i) = gram(m_indices[static_cast<std::size_t>(i)], j);
  m_r.topLeftCorner(k, k).triangularView<Eigen::Upper>().transpose().solveInPlace(r);
  const double pivot_squared = g_jj - r.squaredNorm();
  // d^2 / G_jj is the squared sine of the angle between column j and the span of
  // the held columns; below the threshold the column is a combination of them and
  // R would become (numerically) singular.
  if (!(pivot_squared > dependence_tolerance * g_jj)) return false;
  m_r(k, k) = std::sqrt(pivot_squared);
  m_indices.push_back(j);
  return true;
}

void GramCholesky::remove(Index position) {
  const Index k = size();
  // Deleting column `position` of R leaves an upper-Hessenberg tail; shift the
  // later columns left, then zero the subdiagonal with one Givens rotation per
  // column (rows c, c+1), as in Golub & Van Loan, Matrix Computations, §6.5.2.
  for (Index c = position; c + 1 < k; ++c) m_r.col(c).head(c + 2) = m_r.col(c + 1).head(c + 2);
  for (Index c = position; c + 1 < k; ++c) {
    const double a = m_r(c, c);
    const double b = m_r(c + 1, c);  // > 0: it was the diagonal of the removed order
    const double h = std::hypot(a, b);
    const double cs = a / h;
    const double sn = b / h;
    m_r(c, c) = h;
    m_r(c + 1, c) = 0.0;
    for (Index col = c + 1; col + 1 < k; ++col) {
      const double t1 = m_r(c, col);
      const double t2 = m_r(c + 1, col);
      m_r(c, col) = cs * t1 + sn * t2;
      m_r(c + 1, col) = -sn * t1 + cs * t2;
    }
  }
  m_indices.erase(m_indices.begin() + position);
}

void GramCholesky::solve_in_place(VectorXd& rhs) const {
  const Index k = size();
  const auto r = m_r.topLeftCorner(k, k).triangularView<Eigen::Upper>();
  r.transpose().solveInPlace(rhs);
  r.solveInPlace(rhs);
}

// ---------------------------------------------------------------------------
// NnlsQp
// ---------------------------------------------------------------------------

NnlsQp& NnlsQp::compute(const MatrixXd& gram) {
  if (gram.rows() != gram.cols()) {
    m_gram.resize(0, 0);
    m_computed = false;
    m_info = Status::InvalidInput;
    return *this;
  }
  MatrixXd full = gram.selfadjointView<Eigen::Upper>();
  return compute_from_owned(std::move(full));
}

NnlsQp& NnlsQp::compute_from_owned(MatrixXd&& gram) {
  m_gram = std::move(gram);
  m_iterations = 0;
  const bool valid = m_gram.allFinite() && (m_gram.size() == 0 || m_gram.diagonal().minCoeff() >= 0.0);
  m_computed = valid;
  m_info = valid ? Status::Success : Status::InvalidInput;
  m_factor.reset(m_gram.cols());
  return *this;
}

VectorXd NnlsQp::solve(const VectorXd& c) { return run(c, nullptr); }

VectorXd NnlsQp::solve(const VectorXd& c, const VectorXd& x0) { return run(c, &x0); }

namespace {

/// The Gram-form QP min ½xᵀGx − cᵀx, x ≥ 0, as a Lawson–Hanson problem: the passive
/// set is held by the updated Cholesky factor of G_PP.
class GramQpProblem final : public LawsonHansonProblem {
 public:
  GramQpProblem(const MatrixXd& gram, const VectorXd& c, GramCholesky& factor, const NnlsOptions& options)
      : m_gram(gram), m_c(c), m_factor(factor), m_options(options), m_c_scale(c.lpNorm<Eigen::Infinity>()) {}

  const std::vector<Index>& passive() const override { return m_factor.indices(); }

  /// w = c − Gx; the threshold is tolerance · max(‖c‖∞, ‖Gx‖∞).
  double descent(const VectorXd& x, VectorXd& w) override {
    m_gx.setZero(m_gram.cols());
    for (const Index j : m_factor.indices()) m_gx.noalias() += m_gram.col(j) * x(j);
    w = m_c - m_gx;
    m_scale = std::max(m_c_scale, m_gx.lpNorm<Eigen::Infinity>());
    return m_options.tolerance * m_scale;
  }

  bool free(Index j) override { return m_factor.append(m_gram, j, m_options.dependence_tolerance); }
  void bind(Index position) override { m_factor.remove(position); }

  bool solve_passive(VectorXd& z) override {
    const auto& free_set = m_factor.indices();
    z.resize(m_factor.size());
    for (Index i = 0; i < z.size(); ++i) z(i) = m_c(free_set[static_cast<std::size_t>(i)]);
    m_factor.solve_in_place(z);
    return z.allFinite();
  }

  /// Converged, unless a refused variable still descends far above rounding level:
  /// c then has a component outside range(G) that cannot be reached.
  Status converged(const VectorXd& w, const std::vector<char>& refused) override {
    const double unbounded_threshold = std::sqrt(m_options.tolerance) * m_scale;
    for (Index j = 0; j < w.size(); ++j) {
      if (refused[static_cast<std::size_t>(j)] && w(j) > unbounded_threshold) return Status::NumericalIssue;
    }
    return Status::Success;
  }

 private:
  const MatrixXd& m_gram;
  const VectorXd& m_c;
  GramCholesky& m_factor;
  const NnlsOptions& m_options;
  const double m_c_scale;
  double m_scale = 0.0;  ///< max(‖c‖∞, ‖Gx‖∞) at the last descent()
  VectorXd m_gx;
};

}  // namespace

VectorXd NnlsQp::run(const VectorXd& c, const VectorXd* x0) {
  const Index n = m_gram.cols();
  m_iterations = 0;
  m_factor.reset(n);
  VectorXd x = VectorXd::Zero(n);
  if (!m_computed || c.size() != n || !c.allFinite() || (x0 && (x0->size() != n || !x0->allFinite()))) {
    m_info = Status::InvalidInput;
    return x;
  }
  m_info = Status::Success;
  if (n == 0) return x;

  LawsonHansonOptions loop;
  loop.max_iterations = m_options.max_iterations > 0 ? m_options.max_iterations : static_cast<int>(3 * n);
  // Warm start: free the positive entries of x0 that are independent of the
  // previously freed ones; x stays feasible (x >= 0) throughout.
  if (x0) {
    for (Index j = 0; j < n; ++j) {
      if ((*x0)(j) > 0.0 && m_factor.append(m_gram, j, m_options.dependence_tolerance)) x(j) = (*x0)(j);
    }
    loop.start_with_passive_solve = m_factor.size() > 0;
  }
  GramQpProblem problem(m_gram, c, m_factor, m_options);
  const LawsonHansonResult result = lawson_hanson(problem, x, loop);
  m_info = result.status;
  m_iterations = result.iterations;
  return x;
}

// ---------------------------------------------------------------------------
// Nnls
// ---------------------------------------------------------------------------

Nnls& Nnls::compute(const MatrixXd& a) {
  m_a = a;
  m_computed = a.allFinite();
  if (!m_computed) {
    m_qp.compute_from_owned(MatrixXd::Zero(a.cols(), a.cols()));
    m_qp.m_computed = false;
    m_qp.m_info = Status::InvalidInput;
    m_info = Status::InvalidInput;
    return *this;
  }
  m_qp.compute_from_owned(gram_matrix(a));
  m_info = m_qp.info();
  return *this;
}

VectorXd Nnls::solve(const VectorXd& b) { return run(b, nullptr); }

VectorXd Nnls::solve(const VectorXd& b, const VectorXd& x0) { return run(b, &x0); }

VectorXd Nnls::run(const VectorXd& b, const VectorXd* x0) {
  if (!m_computed || b.size() != m_a.rows() || !b.allFinite() || (x0 && x0->size() != m_a.cols())) {
    m_info = Status::InvalidInput;
    return VectorXd::Zero(m_a.cols());
  }
  const VectorXd c = m_a.transpose() * b;
  VectorXd x = x0 ? m_qp.solve(c, *x0) : m_qp.solve(c);
  m_info = m_qp.info();
  return x;
}

}  // namespace contactrom
