#pragma once
/// \file delassus.hpp
/// \brief The Delassus products of the FOM's QPs (internal to contactrom_fom): for a
/// surface compliance S and constraint rows C (compressed, row-major, a few entries
/// per row), S Cᵀ and C S Cᵀ, written for the 2D and 3D node-to-surface rows.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/fom/contact_model.hpp>

namespace contactrom::fom {

/// \brief S C_Wᵀ (n x |W|) for the rows W of `c` (n = s.rows()): column a is the sum
/// of the columns of the symmetric S picked by row W[a]'s entries, taken in the
/// row's order, eight at a time. `sct` is resized (its storage kept when it fits).
void delassus_parts(const ConstraintMatrix& c, const std::vector<int>& rows, const Eigen::MatrixXd& s,
                    Eigen::MatrixXd& sct);

/// \brief G_W = C_W S C_Wᵀ (|W| x |W|) from S C_Wᵀ: entry (a, b) is row W[a] applied
/// to column b of S C_Wᵀ, its terms added in the row's order.
Eigen::MatrixXd delassus(const ConstraintMatrix& c, const std::vector<int>& rows, const Eigen::MatrixXd& sct);

/// \brief The lower triangle of C S Cᵀ (all rows of `c`, in order) from S Cᵀ into
/// `g` (resized; the strict upper triangle is left as it was).
void delassus_lower(const ConstraintMatrix& c, const Eigen::MatrixXd& sct, Eigen::MatrixXd& g);

}  // namespace contactrom::fom
