#pragma once
/// \file nnls.hpp
/// \brief Non-negative least squares (Lawson–Hanson active-set method) in two
/// forms: on a matrix, \f$\min_x \|Ax-b\|_2\f$ s.t. \f$x \ge 0\f$ (Nnls), and on a
/// quadratic programme given by its Gram matrix,
/// \f$\min_x \tfrac12 x^T G x - c^T x\f$ s.t. \f$x \ge 0\f$ (NnlsQp).
///
/// This is the one NNLS of contactrom: the sparse kernels (OMP, nnFOCUSS, CPG's cone
/// projections) use the matrix form; the dual contact QP of the FOM
/// (fom::DualQpSolver) falls back to the Gram form when its primal–dual active-set
/// iteration cycles.
///
/// Reference: C. L. Lawson and R. J. Hanson, *Solving Least Squares Problems*,
/// Prentice-Hall 1974 (SIAM 1995), chapter 23, algorithm NNLS. The math, the
/// stopping rule and the update strategy are described in docs/sparse_kernels.md.
///
/// Both forms share one implementation: the passive (free) set P is kept with an
/// upper-triangular Cholesky factor \f$R^T R = G_{PP}\f$ that is updated when a
/// column is freed (one triangular solve, \f$O(|P|^2)\f$) or bound again (Givens
/// rotations, \f$O(|P|^2)\f$); no step refactorises from scratch. The matrix form
/// builds \f$G = A^T A\f$ once in compute(), so each later solve() costs
/// \f$O(mn)\f$ for \f$A^T b\f$ plus the active-set iterations.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom {

/// \brief Settings of Nnls and NnlsQp.
struct NnlsOptions {
  /// Cap on the number of active-set changes (each change frees or binds one
  /// variable). A value \f$\le 0\f$ selects \f$3n\f$, n the number of unknowns (the
  /// default of SciPy's `nnls`). Reaching the cap gives Status::NoConvergence and
  /// the last (feasible) iterate. Default 0 (that is, \f$3n\f$).
  int max_iterations = 0;
  /// Relative optimality tolerance (dimensionless). The solve stops when every bound
  /// variable j has \f$w_j = (c - Gx)_j \le \mathrm{tolerance}\cdot
  /// \max(\|c\|_\infty, \|Gx\|_\infty)\f$, w being minus the gradient. For the matrix
  /// form that scale is at most \f$\max_j\|a_j\|\,\|b\|\f$. Default 1e-12.
  double tolerance = 1e-12;
  /// Relative pivot (dimensionless) under which a variable is treated as linearly
  /// dependent on the free ones and is not freed: its new Cholesky pivot
  /// \f$d^2 = G_{jj} - \|R^{-T}G_{Pj}\|^2\f$ must exceed
  /// \f$\mathrm{dependence\_tolerance}\cdot G_{jj}\f$ (for \f$G = A^TA\f$ the ratio is
  /// the squared sine of the angle between \f$a_j\f$ and \f$\mathrm{span}(A_P)\f$).
  /// Default 1e-12.
  double dependence_tolerance = 1e-12;
};

/// \brief Gram matrix \f$A^TA\f$ of the columns of A (symmetric, both triangles
/// filled), formed with a symmetric rank update (half the flops of a full product).
Eigen::MatrixXd gram_matrix(const Eigen::MatrixXd& a);

/// \brief Upper-triangular Cholesky factor \f$R^T R = G_{II}\f$ of the principal
/// submatrix of a Gram matrix G on an ordered index set I, updated in place when an
/// index is appended or removed. Shared by NnlsQp (append/remove) and Omp (append).
///
/// Storage is allocated once for `capacity` indices; append and remove cost
/// \f$O(|I|^2)\f$ flops.
class GramCholesky {
 public:
  /// \brief Empty factor with room for `capacity` indices.
  explicit GramCholesky(Eigen::Index capacity = 0);

  /// \brief Forgets every index and makes room for `capacity` of them (reallocates
  /// only when the capacity grows).
  void reset(Eigen::Index capacity);

  /// \brief Appends index j of the symmetric matrix `gram`.
  /// \param dependence_tolerance relative pivot threshold (see
  ///        NnlsOptions::dependence_tolerance).
  /// \returns false, leaving the factor unchanged, if \f$G_{jj} \le 0\f$ or the new
  ///          pivot is \f$\le \mathrm{dependence\_tolerance}\cdot G_{jj}\f$ (j is then
  ///          numerically a combination of the indices already held).
  bool append(const Eigen::MatrixXd& gram, Eigen::Index j, double dependence_tolerance);

  /// \brief Removes the index held at `position` (0-based, in insertion order) and
  /// restores the triangular form with Givens rotations.
  void remove(Eigen::Index position);

  /// \brief Solves \f$G_{II} z = \mathrm{rhs}\f$ in place (rhs ordered as indices()).
  void solve_in_place(Eigen::VectorXd& rhs) const;

  /// \brief The indices held, in insertion order.
  const std::vector<Eigen::Index>& indices() const { return m_indices; }
  /// \brief Number of indices held.
  Eigen::Index size() const { return static_cast<Eigen::Index>(m_indices.size()); }

 private:
  Eigen::MatrixXd m_r;  ///< top-left size()×size() block holds R (upper triangle)
  std::vector<Eigen::Index> m_indices;
};

/// \brief Lawson–Hanson NNLS on a quadratic programme in Gram form:
/// \f[ \min_{x \ge 0} \tfrac12 x^T G x - c^T x, \f]
/// G symmetric positive semi-definite (n×n). With \f$G = A^T A\f$ and
/// \f$c = A^T b\f$ this is \f$\min_{x\ge 0}\|Ax-b\|_2\f$ up to the constant
/// \f$\tfrac12\|b\|^2\f$. Use it when the problem is naturally a QP (dual contact
/// QP with the Delassus matrix, projection onto a cone spanned by columns of B with
/// \f$G = B^TB\f$, \f$c = B^Ty\f$) or when G is reused for many right-hand sides.
///
/// The problem is bounded below when c lies in the range of G (always true for
/// \f$G = A^TA\f$, \f$c = A^Tb\f$). If it is not, the method can meet a variable
/// that is linearly dependent on the free ones (pivot below dependence_tolerance) yet
/// still has \f$w_j > \mathrm{tol}\cdot s\f$; it cannot free it and stops with
/// Status::NumericalIssue, returning the last feasible iterate.
///
/// KKT conditions satisfied on Status::Success, with \f$w = c - Gx\f$ and
/// \f$s = \max(\|c\|_\infty,\|Gx\|_\infty)\f$: \f$x \ge 0\f$;
/// \f$w_j \le \mathrm{tol}\cdot s\f$ where \f$x_j = 0\f$; \f$w_j \approx 0\f$ (to
/// rounding) where \f$x_j > 0\f$.
///
/// \code
///   contactrom::NnlsQp qp;
///   qp.compute(G);                       // stores G (upper triangle is read)
///   Eigen::VectorXd x = qp.solve(c);     // Lawson–Hanson from x = 0
///   if (qp.info() != contactrom::Status::Success) { ... }
/// \endcode
class NnlsQp {
 public:
  using Options = NnlsOptions;

  NnlsQp() = default;
  explicit NnlsQp(const Options& options) : m_options(options) {}

  /// \brief Stores G (only its upper triangle is read; the lower is mirrored).
  /// Sets info() to InvalidInput if G is not square, has a non-finite entry or a
  /// negative diagonal entry.
  NnlsQp& compute(const Eigen::MatrixXd& gram);

  /// \brief Solves the QP from x = 0.
  /// \param c linear term (size n).
  /// \returns x (size n); zeros if info() is InvalidInput (size mismatch,
  ///          non-finite c, or compute() not called successfully).
  Eigen::VectorXd solve(const Eigen::VectorXd& c);

  /// \brief Solves the QP warm-started from x0: the variables with
  /// \f$x0_j > 0\f$ start free (those numerically dependent on earlier ones start
  /// bound). Useful when a sequence of nearby problems is solved.
  /// \param x0 start (size n); negative entries count as 0.
  Eigen::VectorXd solve(const Eigen::VectorXd& c, const Eigen::VectorXd& x0);

  /// \brief Status of the last compute() or solve().
  Status info() const { return m_info; }
  /// \brief Number of active-set changes of the last solve().
  int iterations() const { return m_iterations; }
  /// \brief Free variables at the solution (x_j > 0), in the order they were freed.
  const std::vector<Eigen::Index>& passive_set() const { return m_factor.indices(); }
  /// \brief Number of unknowns n of the stored G (0 before compute()).
  Eigen::Index size() const { return m_gram.cols(); }

  /// \brief The settings in use.
  const Options& options() const { return m_options; }
  /// \brief Replaces the settings; returns *this for chaining.
  NnlsQp& set_options(const Options& options) {
    m_options = options;
    return *this;
  }

 private:
  friend class Nnls;
  NnlsQp& compute_from_owned(Eigen::MatrixXd&& gram);
  Eigen::VectorXd run(const Eigen::VectorXd& c, const Eigen::VectorXd* x0);

  Options m_options;
  Eigen::MatrixXd m_gram;
  GramCholesky m_factor;
  bool m_computed = false;
  Status m_info = Status::InvalidInput;
  int m_iterations = 0;
};

/// \brief Lawson–Hanson non-negative least squares
/// \f[ \min_{x \ge 0} \|Ax - b\|_2, \f]
/// A of size m×n (tall, wide or rank-deficient). compute(A) forms \f$A^TA\f$ once;
/// every solve(b) then runs NnlsQp on \f$(A^TA, A^Tb)\f$. Conditioning: the Gram
/// form squares the condition number of the free columns, which is harmless for the
/// KKT residual (backward stable) but limits the forward accuracy of x to about
/// \f$\varepsilon\,\kappa(A_P)^2\f$.
///
/// \code
///   contactrom::Nnls nnls;
///   nnls.compute(A);                      // O(m n^2), once per matrix
///   Eigen::VectorXd x = nnls.solve(b);    // many right-hand sides
/// \endcode
class Nnls {
 public:
  using Options = NnlsOptions;

  Nnls() = default;
  explicit Nnls(const Options& options) : m_qp(options) {}

  /// \brief Stores A and forms \f$G = A^TA\f$. info() is InvalidInput if A has a
  /// non-finite entry.
  Nnls& compute(const Eigen::MatrixXd& a);

  /// \brief Solves \f$\min_{x\ge0}\|Ax-b\|\f$ from x = 0.
  /// \returns x (size n); zeros if info() is InvalidInput (b of the wrong size or
  ///          non-finite, or compute() not called successfully).
  Eigen::VectorXd solve(const Eigen::VectorXd& b);

  /// \brief Same, warm-started from x0 (see NnlsQp::solve(c, x0)).
  Eigen::VectorXd solve(const Eigen::VectorXd& b, const Eigen::VectorXd& x0);

  /// \brief Status of the last compute() or solve().
  Status info() const { return m_info; }
  /// \brief Number of active-set changes of the last solve().
  int iterations() const { return m_qp.iterations(); }
  /// \brief Free columns at the solution, in the order they were freed.
  const std::vector<Eigen::Index>& passive_set() const { return m_qp.passive_set(); }
  /// \brief The underlying Gram-form solver (G = AᵀA).
  const NnlsQp& qp() const { return m_qp; }

  /// \brief The settings in use.
  const Options& options() const { return m_qp.options(); }
  /// \brief Replaces the settings; returns *this for chaining.
  Nnls& set_options(const Options& options) {
    m_qp.set_options(options);
    return *this;
  }

 private:
  Eigen::VectorXd run(const Eigen::VectorXd& b, const Eigen::VectorXd* x0);

  NnlsQp m_qp;
  Eigen::MatrixXd m_a;
  bool m_computed = false;
  Status m_info = Status::InvalidInput;
};


}  // namespace contactrom
