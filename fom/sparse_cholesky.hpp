#pragma once
/// \file sparse_cholesky.hpp
/// \brief Sparse Cholesky factorisation (CHOLMOD, supernodal) that eliminates a
/// chosen set of unknowns last, so that the block of the inverse on that set comes
/// out of the factor without any solve.
///
/// With the permutation \f$ P \f$ ordering the other unknowns first (fill-reducing
/// ordering of their block) and the chosen set \f$ s \f$ last, in the given order,
/// \f[ P A P^T = L L^T, \qquad L = \begin{pmatrix} L_{11} & 0 \\ L_{21} & L_{22} \end{pmatrix}, \f]
/// \f$ L_{22} L_{22}^T \f$ is the Schur complement of the other unknowns, hence
/// \f[ (A^{-1})_{ss} = L_{22}^{-T} L_{22}^{-1} . \f]
/// Its cost is that of the dense \f$ n_s \times n_s \f$ block (less when it is block
/// diagonal, e.g. one block per body), not \f$ n \times n_s \f$ solves: no dense
/// matrix with a row per unknown is ever formed.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <memory>
#include <vector>

#include <contactrom/core/errors.hpp>

namespace contactrom::fom {

/// \brief Supernodal CHOLMOD Cholesky factor with a trailing set; see the file comment.
///
/// compute() is not thread-safe; solve(), solve_trailing() and inverse_block() are const and may be
/// called concurrently from several threads (each call has its own CHOLMOD workspace).
class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// \brief Factorises the symmetric positive definite `a` (both triangles stored),
  /// eliminating the unknowns `last` last, in that order.
  /// \param a symmetric matrix, n x n
  /// \param last distinct indices in [0, n) (may be empty)
  /// \returns *this; check info(): NumericalIssue if `a` is not positive definite,
  ///   InvalidInput if the sizes or indices are inconsistent.
  SparseCholesky& compute(const Eigen::SparseMatrix<double>& a, const std::vector<int>& last);

  /// \brief Same with a given elimination order (e.g. permutation() of an earlier
  /// factor of a matrix with the same pattern), which skips the ordering step: the
  /// factor of a parameter-dependent matrix then costs symbolic analysis and
  /// numeric factorisation only. InvalidInput unless `order` is a permutation of
  /// 0..n−1 ending with `last`.
  SparseCholesky& compute(const Eigen::SparseMatrix<double>& a, const std::vector<int>& last,
                          const std::vector<int>& order);

  /// The elimination order of the last successful compute() (new position k holds
  /// unknown order[k]); it ends with `last`.
  const std::vector<int>& permutation() const { return m_order; }

  /// Status of the last compute().
  Status info() const { return m_info; }
  /// Number of unknowns n of the factorised matrix.
  int size() const { return m_n; }
  /// Size of the trailing set `last` of compute().
  int trailing_size() const { return m_trailing; }

  /// \brief \f$ A^{-1} b \f$ for one or several right-hand sides (n x k).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;

  /// \brief \f$ A^{-1} E_s f \f$ for loads `f` (|last| x k) on the trailing set
  /// (\f$ E_s \f$: injection of the set `last` of compute()); half the cost of
  /// solve(), as the forward substitution only touches \f$ L_{22} \f$.
  Eigen::MatrixXd solve_trailing(const Eigen::MatrixXd& f) const;

  /// \brief \f$ (A^{-1})_{ss} \f$ for the set `last` of compute(), in its order
  /// (|last| x |last|, symmetric), from the trailing block of the factor.
  Eigen::MatrixXd inverse_block() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
  Status m_info = Status::InvalidInput;
  int m_n = 0;
  int m_trailing = 0;
  std::vector<int> m_order;
};

}  // namespace contactrom::fom
