#include "rom/support_rows.hpp"

namespace contactrom::rom {

SupportRows::SupportRows(const Eigen::MatrixXd& w) {
  for (Eigen::Index s = 0; s < w.rows(); ++s)
    if ((w.row(s).array() != 0.0).any()) rows.push_back(static_cast<int>(s));
  basis.resize(static_cast<Eigen::Index>(rows.size()), w.cols());
  for (size_t i = 0; i < rows.size(); ++i) basis.row(static_cast<Eigen::Index>(i)) = w.row(rows[i]);
}

void SupportRows::violation(const fom::ConstraintMatrix& c, const Eigen::VectorXd& g,
                            const Eigen::VectorXd& u_surface, Eigen::VectorXd& gap, Eigen::VectorXd& out) const {
  gap.resize(static_cast<Eigen::Index>(rows.size()));
  for (size_t i = 0; i < rows.size(); ++i) {
    double acc = -g(rows[i]);
    for (fom::ConstraintMatrix::InnerIterator it(c, rows[i]); it; ++it) acc += it.value() * u_surface(it.col());
    gap(static_cast<Eigen::Index>(i)) = acc;
  }
  out.noalias() = basis.transpose() * gap;
}

}  // namespace contactrom::rom
