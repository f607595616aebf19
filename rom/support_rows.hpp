#pragma once
/// \file support_rows.hpp
/// \brief A dual basis (dictionary, CPG basis, ...) restricted to the contact rows
/// where it is non-zero. Only those rows enter the reduced operators
/// \f$ W^T C \Phi \f$ and the reduced violation \f$ W^T (C u - g) \f$, so the online
/// contact search, the assembly and the violation need nothing else.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/contact_residuals.hpp>

namespace contactrom::rom {

/// Row-major dense matrix (Φ_s by rows, A = C_R Φ_s).
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// \brief Support rows R of a dual basis W (n_c × m) and W restricted to them.
///
/// The online kernels work on the compact operators of R: C_R (|R| × surface dofs)
/// and g_R, as ContactModel::assemble_rows(pairing, rows, ...) gives them.
struct SupportRows {
  SupportRows() = default;  ///< no rows
  explicit SupportRows(const Eigen::MatrixXd& w);

  std::vector<int> rows;  ///< contact rows where some column of W is non-zero, ascending
  Eigen::MatrixXd basis;  ///< W[rows, :] (|R| × m)
  /// Per column p, the positions i in `rows` where W[rows[i], p] is not zero.
  std::vector<std::vector<int>> column_support;
  /// \brief out = W[rows, :]ᵀ v (size m) for v on the support rows (size |R|), over
  /// the non-zero entries of W[rows, :] only (a dictionary's columns are local:
  /// a few rows each).
  void transpose_times(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> out) const;

  /// \brief \f$ W^T (C u_s - g) \f$ for every column of W, from C_R and g_R.
  /// \param gap work vector, left holding \f$ (C_R u_s - g_R) \f$
  void violation(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r, const Eigen::VectorXd& u_surface,
                 Eigen::VectorXd& gap, Eigen::VectorXd& out) const;

  /// Work storage of residuals(), reused from one call to the next.
  struct ResidualsScratch {
    Eigen::VectorXd gap, violation, weights, pressure;
  };
  /// \brief The full-order contact residuals on the support rows
  /// (fom::contact_residuals_of_gaps) of the surface displacement u_s and the pressure
  /// \f$ \lambda = W[:, columns]\,c \f$, with C_R and g_R built at u_s (its own pairing).
  /// \param columns positions in W of the `coefficients` c (one each)
  /// \param contact_weights the contact rows' weights (ContactModel::weights(), all rows)
  /// \param scale the displacement scale U
  fom::ContactResiduals residuals(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                                  const Eigen::VectorXd& u_surface, const std::vector<int>& columns,
                                  const Eigen::Ref<const Eigen::VectorXd>& coefficients,
                                  const Eigen::VectorXd& contact_weights, double scale, ResidualsScratch& s) const;

  /// \brief \f$ A = C_R \Phi_s \f$ (|R| × r) and \f$ b = C_R u_{off,s} - g_R \f$, so that
  /// \f$ A\hat u + b \f$ is the gap on R at \f$ \hat u \f$. O(nnz(C_R) · r).
  void gap_operator(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r, const RowMajorMatrix& phi_s,
                    const Eigen::VectorXd& off_s, RowMajorMatrix& a, Eigen::VectorXd& b) const;

  /// \brief Row p of the reduced operators from C_R and g_R:
  /// \f$ \hat C_p = w_p^T C_R \Phi_s \f$ into `c_hat` (size r) and the return value
  /// \f$ \hat g_p = w_p^T (g_R - C_R u_{off,s}) \f$. O(nnz(w_p) · 6 · r).
  double reduced_row(int p, const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r, const RowMajorMatrix& phi_s,
                     const Eigen::VectorXd& off_s, Eigen::Ref<Eigen::RowVectorXd> c_hat) const;

  /// Storage of reduced_rows(), reused from one call to the next.
  struct RowsScratch {
    RowMajorMatrix a;         ///< rows of C_R Φ_s formed in the current call
    Eigen::VectorXd b;        ///< the matching entries of g_R − C_R u_off,s
    std::vector<unsigned> stamp;  ///< per support row: the call that formed it
    unsigned call = 0;
  };
  /// \brief reduced_row() for several columns at once: row i of `c_hat` (r columns,
  /// at least |columns| rows) and `g_hat(i)` for column columns[i]. The rows of
  /// \f$ C_R \Phi_s \f$ on the union of the columns' supports are formed once and
  /// combined per column, O(|∪ supp| · 6 · r + Σ |supp_p| · r) instead of
  /// O(Σ |supp_p| · 6 · r): the supports of neighbouring training snapshots overlap.
  void reduced_rows(const std::vector<int>& columns, const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                    const RowMajorMatrix& phi_s, const Eigen::VectorXd& off_s, RowMajorMatrix& c_hat,
                    Eigen::VectorXd& g_hat, RowsScratch& scratch) const;

 private:
  std::vector<std::vector<double>> m_values;  // per column p, W[rows[i], p] for i in column_support[p]
};

/// \brief Contact operators of the support rows at the current iterate, rebuilt in
/// place by the online loops: the pairing (the previous one seeds the next search)
/// and C_R, g_R, in storage reused from one rebuild to the next.
struct SupportOperators {
  /// \param partial search with a memory of the previous rebuilds (fom::SearchMemory):
  /// rows whose nodes moved too little to change segment are settled without the
  /// search of the whole master chain. Same operators either way; false searches
  /// every row in full at every rebuild.
  explicit SupportOperators(bool partial = true) : m_partial(partial) {}
  fom::Pairing pairing;     ///< of the last rebuild (empty before the first)
  fom::ConstraintMatrix c;  ///< C_R
  Eigen::VectorXd g;        ///< g_R
  /// Searches the support rows at u_s, seeded by the current pairing, and assembles
  /// C_R and g_R there.
  void rebuild(const fom::ContactModel& contact, const SupportRows& support, const Eigen::VectorXd& u_surface);
  /// Starts the memory from `memory` (e.g. ReducedModel::snapshot_search_memory of
  /// the training snapshot nearest to the query) instead of nothing, so that the
  /// first rebuild settles the rows that cannot have changed segment since. The
  /// operators are those of a full search either way. Ignored without `partial`.
  void seed(const fom::SearchMemory& memory);
  /// Forgets the pairing and the memory (keeping their storage), for a new query;
  /// `partial` as in the constructor.
  void reset(bool partial);
  /// Rows settled by the memory and rows searched in full, over the rebuilds so far.
  int certified_rows() const { return m_memory.certified; }
  int searched_rows() const { return m_memory.searched; }

 private:
  bool m_partial;
  fom::SearchMemory m_memory;
  fom::Pairing m_next;  // the search writes here, then it becomes `pairing`
};

}  // namespace contactrom::rom
