#include "rom/support_rows.hpp"

#include <algorithm>

namespace contactrom::rom {

SupportRows::SupportRows(const Eigen::MatrixXd& w) {
  for (Eigen::Index s = 0; s < w.rows(); ++s)
    if ((w.row(s).array() != 0.0).any()) rows.push_back(static_cast<int>(s));
  basis.resize(static_cast<Eigen::Index>(rows.size()), w.cols());
  for (size_t i = 0; i < rows.size(); ++i) basis.row(static_cast<Eigen::Index>(i)) = w.row(rows[i]);
  column_support.resize(static_cast<size_t>(w.cols()));
  for (Eigen::Index p = 0; p < w.cols(); ++p)
    for (Eigen::Index i = 0; i < basis.rows(); ++i)
      if (basis(i, p) != 0.0) column_support[static_cast<size_t>(p)].push_back(static_cast<int>(i));
}

void SupportRows::violation(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                            const Eigen::VectorXd& u_surface, Eigen::VectorXd& gap, Eigen::VectorXd& out) const {
  gap.resize(static_cast<Eigen::Index>(rows.size()));
  for (Eigen::Index i = 0; i < gap.size(); ++i) {
    double acc = -g_r(i);
    for (fom::ConstraintMatrix::InnerIterator it(c_r, i); it; ++it) acc += it.value() * u_surface(it.col());
    gap(i) = acc;
  }
  out.noalias() = basis.transpose() * gap;
}

void SupportRows::gap_operator(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                               const RowMajorMatrix& phi_s, const Eigen::VectorXd& lift_s, RowMajorMatrix& a,
                               Eigen::VectorXd& b) const {
  // Plain loops, as in reduced_row().
  const Eigen::Index r = phi_s.cols(), nr = c_r.rows();
  a.setZero(nr, r);
  b.resize(nr);
  const int* outer = c_r.outerIndexPtr();
  const int* inner = c_r.innerIndexPtr();
  const double* value = c_r.valuePtr();
  for (Eigen::Index i = 0; i < nr; ++i) {
    double* out = a.data() + i * r;
    double acc = -g_r(i);
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      const double* row = phi_s.data() + static_cast<Eigen::Index>(inner[e]) * r;
      for (Eigen::Index t = 0; t < r; ++t) out[t] += value[e] * row[t];
      acc += value[e] * lift_s(inner[e]);
    }
    b(i) = acc;
  }
}

double SupportRows::reduced_row(int p, const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                                const RowMajorMatrix& phi_s, const Eigen::VectorXd& lift_s,
                                Eigen::Ref<Eigen::RowVectorXd> c_hat) const {
  // Plain loops over the compressed rows: the vectors are short (r), where the
  // set-up of an expression per entry would cost as much as the arithmetic.
  const Eigen::Index r = phi_s.cols();
  double* out = c_hat.data();
  std::fill(out, out + r, 0.0);
  const int* outer = c_r.outerIndexPtr();
  const int* inner = c_r.innerIndexPtr();
  const double* value = c_r.valuePtr();
  double g_hat = 0.0;
  for (int i : column_support[static_cast<size_t>(p)]) {
    const double wi = basis(i, p);
    double acc = g_r(i);
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      const double a = wi * value[e];
      const double* row = phi_s.data() + static_cast<Eigen::Index>(inner[e]) * r;
      for (Eigen::Index t = 0; t < r; ++t) out[t] += a * row[t];
      acc -= value[e] * lift_s(inner[e]);
    }
    g_hat += wi * acc;
  }
  return g_hat;
}

}  // namespace contactrom::rom
