#include <contactrom/rom/support_rows.hpp>

#include <algorithm>
#include <utility>

namespace contactrom::rom {

namespace {

/// out (r) = (Assign) or += scale · Σ_e value[e] Φ_s.row(inner[e]) over one
/// compressed row of C_R, by plain loops (the vectors are short: expression set-up
/// per entry would cost as much as the arithmetic); a node-to-segment row (six
/// entries) in one pass.
template <bool Assign>
void row_times_basis(double scale, const double* value, const int* inner, int nnz, const RowMajorMatrix& phi_s,
                     double* out) {
  const Eigen::Index r = phi_s.cols();
  if (nnz == 6) {
    const double* q[6];
    double v[6];
    for (int f = 0; f < 6; ++f) q[f] = phi_s.data() + static_cast<Eigen::Index>(inner[f]) * r, v[f] = scale * value[f];
    for (Eigen::Index t = 0; t < r; ++t) {
      const double sum = v[0] * q[0][t] + v[1] * q[1][t] + v[2] * q[2][t] + v[3] * q[3][t] + v[4] * q[4][t] + v[5] * q[5][t];
      out[t] = Assign ? sum : out[t] + sum;
    }
    return;
  }
  if (Assign) std::fill(out, out + r, 0.0);
  for (int f = 0; f < nnz; ++f) {
    const double a = scale * value[f];
    const double* row = phi_s.data() + static_cast<Eigen::Index>(inner[f]) * r;
    for (Eigen::Index t = 0; t < r; ++t) out[t] += a * row[t];
  }
}

}  // namespace

SupportRows::SupportRows(const Eigen::MatrixXd& w) {
  for (Eigen::Index s = 0; s < w.rows(); ++s)
    if ((w.row(s).array() != 0.0).any()) rows.push_back(static_cast<int>(s));
  basis.resize(static_cast<Eigen::Index>(rows.size()), w.cols());
  for (size_t i = 0; i < rows.size(); ++i) basis.row(static_cast<Eigen::Index>(i)) = w.row(rows[i]);
  column_support.resize(static_cast<size_t>(w.cols()));
  for (Eigen::Index p = 0; p < w.cols(); ++p)
    for (Eigen::Index i = 0; i < basis.rows(); ++i)
      if (basis(i, p) != 0.0) column_support[static_cast<size_t>(p)].push_back(static_cast<int>(i));
  m_values.resize(column_support.size());
  for (size_t p = 0; p < column_support.size(); ++p)
    for (int i : column_support[p]) m_values[p].push_back(basis(i, static_cast<Eigen::Index>(p)));
}

void SupportRows::transpose_times(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> out) const {
  for (size_t p = 0; p < column_support.size(); ++p) {
    const std::vector<int>& at = column_support[p];
    const std::vector<double>& w = m_values[p];
    double acc = 0.0;
    for (size_t e = 0; e < at.size(); ++e) acc += w[e] * v(at[e]);
    out(static_cast<Eigen::Index>(p)) = acc;
  }
}

void SupportRows::violation(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                            const Eigen::VectorXd& u_surface, Eigen::VectorXd& gap, Eigen::VectorXd& out) const {
  gap.resize(static_cast<Eigen::Index>(rows.size()));
  for (Eigen::Index i = 0; i < gap.size(); ++i) {
    double acc = -g_r(i);
    for (fom::ConstraintMatrix::InnerIterator it(c_r, i); it; ++it) acc += it.value() * u_surface(it.col());
    gap(i) = acc;
  }
  out.resize(basis.cols());
  transpose_times(gap, out);
}

fom::ContactResiduals SupportRows::residuals(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                                             const Eigen::VectorXd& u_surface, const std::vector<int>& columns,
                                             const Eigen::Ref<const Eigen::VectorXd>& coefficients,
                                             const Eigen::VectorXd& contact_weights, double scale,
                                             ResidualsScratch& s) const {
  violation(c_r, g_r, u_surface, s.gap, s.violation);  // s.gap = C_R u_s − g_R
  const auto nr = static_cast<Eigen::Index>(rows.size());
  s.weights.resize(nr);
  s.pressure.setZero(nr);
  for (Eigen::Index i = 0; i < nr; ++i) {
    s.weights(i) = contact_weights(rows[static_cast<size_t>(i)]);
    for (size_t j = 0; j < columns.size(); ++j) s.pressure(i) += basis(i, columns[j]) * coefficients(static_cast<Eigen::Index>(j));
  }
  return fom::contact_residuals_of_gaps(s.gap, s.weights, s.pressure, scale);
}

void SupportRows::gap_operator(const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                               const RowMajorMatrix& phi_s, const Eigen::VectorXd& off_s, RowMajorMatrix& a,
                               Eigen::VectorXd& b) const {
  const Eigen::Index r = phi_s.cols(), nr = c_r.rows();
  a.resize(nr, r);
  b.resize(nr);
  const int* outer = c_r.outerIndexPtr();
  const int* inner = c_r.innerIndexPtr();
  const double* value = c_r.valuePtr();
  for (Eigen::Index i = 0; i < nr; ++i) {
    row_times_basis<true>(1.0, value + outer[i], inner + outer[i], outer[i + 1] - outer[i], phi_s, a.data() + i * r);
    double acc = -g_r(i);
    for (int e = outer[i]; e < outer[i + 1]; ++e) acc += value[e] * off_s(inner[e]);
    b(i) = acc;
  }
}

double SupportRows::reduced_row(int p, const fom::ConstraintMatrix& c_r, const Eigen::VectorXd& g_r,
                                const RowMajorMatrix& phi_s, const Eigen::VectorXd& off_s,
                                Eigen::Ref<Eigen::RowVectorXd> c_hat) const {
  c_hat.setZero();
  const int* outer = c_r.outerIndexPtr();
  const int* inner = c_r.innerIndexPtr();
  const double* value = c_r.valuePtr();
  double g_hat = 0.0;
  for (int i : column_support[static_cast<size_t>(p)]) {
    const double wi = basis(i, p);
    row_times_basis<false>(wi, value + outer[i], inner + outer[i], outer[i + 1] - outer[i], phi_s, c_hat.data());
    double acc = g_r(i);
    for (int e = outer[i]; e < outer[i + 1]; ++e) acc -= value[e] * off_s(inner[e]);
    g_hat += wi * acc;
  }
  return g_hat;
}

void SupportRows::reduced_rows(const std::vector<int>& columns, const fom::ConstraintMatrix& c_r,
                               const Eigen::VectorXd& g_r, const RowMajorMatrix& phi_s, const Eigen::VectorXd& off_s,
                               RowMajorMatrix& c_hat, Eigen::VectorXd& g_hat, RowsScratch& scratch) const {
  const Eigen::Index r = phi_s.cols(), nr = static_cast<Eigen::Index>(rows.size());
  if (columns.size() < 2) {  // nothing to share
    for (size_t i = 0; i < columns.size(); ++i) {
      const auto at = static_cast<Eigen::Index>(i);
      g_hat(at) = reduced_row(columns[i], c_r, g_r, phi_s, off_s, c_hat.row(at));
    }
    return;
  }
  if (scratch.a.rows() != nr || scratch.a.cols() != r) {
    scratch.a.resize(nr, r), scratch.b.resize(nr);
    scratch.stamp.assign(static_cast<size_t>(nr), 0), scratch.call = 0;
  }
  if (++scratch.call == 0) std::fill(scratch.stamp.begin(), scratch.stamp.end(), 0), scratch.call = 1;
  const int* outer = c_r.outerIndexPtr();
  const int* inner = c_r.innerIndexPtr();
  const double* value = c_r.valuePtr();
  for (size_t i = 0; i < columns.size(); ++i) {
    const int p = columns[i];
    const auto at = static_cast<Eigen::Index>(i);
    double* out = c_hat.row(at).data();
    std::fill(out, out + r, 0.0);
    double g_hat_p = 0.0;
    for (int k : column_support[static_cast<size_t>(p)]) {
      double* a_k = scratch.a.data() + static_cast<Eigen::Index>(k) * r;
      if (scratch.stamp[static_cast<size_t>(k)] != scratch.call) {  // first use of row k in this call
        scratch.stamp[static_cast<size_t>(k)] = scratch.call;
        row_times_basis<true>(1.0, value + outer[k], inner + outer[k], outer[k + 1] - outer[k], phi_s, a_k);
        double acc = g_r(k);
        for (int e = outer[k]; e < outer[k + 1]; ++e) acc -= value[e] * off_s(inner[e]);
        scratch.b(k) = acc;
      }
      const double wk = basis(k, p);
      for (Eigen::Index t = 0; t < r; ++t) out[t] += wk * a_k[t];
      g_hat_p += wk * scratch.b(k);
    }
    g_hat(at) = g_hat_p;
  }
}

void SupportOperators::reset(bool partial) {
  m_partial = partial;
  pairing.segment.clear();
  m_memory.centre.clear();  // the next search lays the memory out anew, in the same storage
  m_memory.certified = m_memory.searched = 0;
}

void SupportOperators::rebuild(const fom::ContactModel& contact, const SupportRows& support,
                               const Eigen::VectorXd& u_surface) {
  if (m_partial)  // an empty hint is ignored
    contact.search_rows(u_surface, &support.rows, &pairing, m_memory, m_next);
  else
    contact.search_rows(u_surface, &support.rows, &pairing, m_next);
  std::swap(pairing, m_next);
  contact.assemble_rows(pairing, support.rows, c, g);
}

void SupportOperators::seed(const fom::SearchMemory& memory) {
  if (!m_partial) return;
  const int certified = m_memory.certified, searched = m_memory.searched;
  m_memory = memory;  // reuses the storage of an earlier query's memory
  m_memory.certified = certified, m_memory.searched = searched;
}

}  // namespace contactrom::rom
