#pragma once
/// \file support_rows.hpp
/// \brief A dual basis (dictionary, CPG basis, ...) restricted to the contact rows
/// where it is non-zero. Only those rows enter the reduced operators
/// \f$ W^T C \Phi \f$ and the reduced violation \f$ W^T (C u - g) \f$, so the online
/// contact search and the violation need nothing else.
#include <Eigen/Dense>
#include <vector>

#include "fom/contact_model.hpp"

namespace contactrom::rom {

/// \brief Support rows of a dual basis W (n_c × m) and W restricted to them.
struct SupportRows {
  SupportRows() = default;  ///< no rows
  explicit SupportRows(const Eigen::MatrixXd& w);

  std::vector<int> rows;  ///< contact rows where some column of W is non-zero, ascending
  Eigen::MatrixXd basis;  ///< W[rows, :] (|rows| × m)

  /// \brief \f$ W^T (C u_s - g) \f$ for every column of W, from the support rows only.
  /// \param gap work vector, left holding \f$ (C u_s - g) \f$ on the support rows
  void violation(const fom::ConstraintMatrix& c, const Eigen::VectorXd& g, const Eigen::VectorXd& u_surface,
                 Eigen::VectorXd& gap, Eigen::VectorXd& out) const;
};

}  // namespace contactrom::rom
