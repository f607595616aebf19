#include <contactrom/fom/contact_zone.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <contactrom/core/anderson.hpp>
#include <contactrom/fom/delassus.hpp>

namespace contactrom::fom {
namespace {

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// Zones of at most this many rows factorise G_AA with cholesky_lower(), larger ones
/// with Eigen's blocked LLT.
constexpr int kUnblocked = 64;

/// In place: the lower triangle of `g` becomes its Cholesky factor L (g = L Lᵀ);
/// false if g is not positive definite. For small matrices (a zone of a few dozen
/// rows), where this loop beats a blocked factorisation.
bool cholesky_lower(Eigen::MatrixXd& g) {
  const int m = static_cast<int>(g.rows());
  for (int j = 0; j < m; ++j) {
    double* cj = g.col(j).data();
    for (int k = 0; k < j; ++k) {
      const double* ck = g.col(k).data();
      const double ljk = ck[j];
      for (int i = j; i < m; ++i) cj[i] -= ljk * ck[i];
    }
    if (!(cj[j] > 0.0)) return false;
    const double d = std::sqrt(cj[j]);
    cj[j] = d;
    for (int i = j + 1; i < m; ++i) cj[i] /= d;
  }
  return true;
}

/// Solves L Lᵀ x = b in place with the factor of cholesky_lower().
void cholesky_solve(const Eigen::MatrixXd& l, double* b) {
  const int m = static_cast<int>(l.rows());
  for (int j = 0; j < m; ++j) {
    const double* c = l.col(j).data();
    const double y = b[j] / c[j];
    b[j] = y;
    for (int i = j + 1; i < m; ++i) b[i] -= c[i] * y;
  }
  for (int j = m - 1; j >= 0; --j) {
    const double* c = l.col(j).data();
    double sum = b[j];
    for (int i = j + 1; i < m; ++i) sum -= c[i] * b[i];
    b[j] = sum / c[j];
  }
}

/// `in` (compressed, row-major) with its columns renumbered by `position` into
/// `out` (nd columns); false if an entry's column is outside D (position −1).
template <class Sparse>
bool to_local(const Sparse& in, const std::vector<int>& position, int nd, Sparse& out) {
  const int rows = static_cast<int>(in.rows()), nnz = static_cast<int>(in.nonZeros());
  out.resize(rows, nd);
  out.resizeNonZeros(nnz);
  std::copy(in.outerIndexPtr(), in.outerIndexPtr() + rows + 1, out.outerIndexPtr());
  std::copy(in.valuePtr(), in.valuePtr() + nnz, out.valuePtr());
  for (int k = 0; k < nnz; ++k) {
    const int j = position[static_cast<size_t>(in.innerIndexPtr()[k])];
    if (j < 0) return false;
    out.innerIndexPtr()[k] = j;
  }
  return true;
}

/// The zone: its rows A, the dofs D its pairing reads, S and u0 on D, and the
/// workspace of its steps.
class Zone {
 public:
  Zone(const ContactModel& contact, const Eigen::MatrixXd& s, const Eigen::VectorXd& u0_s, double u_scale,
       const ContactZoneOptions& options)
      : m_contact(contact), m_s(s), m_u0_s(u0_s), m_u_scale(u_scale), m_options(options) {}

  /// Sets up the zone of the rows with λ > 0 at `start` (all paired) and the surface
  /// displacement `f`; false when there is none.
  bool set_up(const Eigen::VectorXd& lambda, const Pairing& start, const Eigen::VectorXd& f) {
    for (Eigen::Index r = 0; r < lambda.size(); ++r)
      if (lambda(r) > 0.0) m_rows.push_back(static_cast<int>(r));
    if (m_rows.empty() || static_cast<int>(m_rows.size()) > m_options.max_rows) return false;
    for (int r : m_rows)
      if (start.segment[static_cast<size_t>(r)] < 0) return false;
    if (!m_contact.pairing_support(start, m_rows, m_options.reach, m_dofs)) return false;
    m_start = &start;
    m = static_cast<int>(m_rows.size()), nd = static_cast<int>(m_dofs.size());
    m_position.assign(static_cast<size_t>(f.size()), -1);
    for (int i = 0; i < nd; ++i) m_position[static_cast<size_t>(m_dofs[static_cast<size_t>(i)])] = i;
    // S_DD, copied by runs of consecutive dofs (a zone's slave nodes and master
    // nodes are runs of the surface numbering).
    std::vector<std::pair<int, int>> runs;  // (first dof, length)
    for (int i = 0; i < nd; ++i) {
      const int d = m_dofs[static_cast<size_t>(i)];
      if (!runs.empty() && runs.back().first + runs.back().second == d)
        ++runs.back().second;
      else
        runs.emplace_back(d, 1);
    }
    m_s_dd.resize(nd, nd);
    for (int b = 0; b < nd; ++b) {
      const double* col = m_s.col(m_dofs[static_cast<size_t>(b)]).data();
      double* dst = m_s_dd.col(b).data();
      for (const auto& [first, length] : runs) dst = std::copy(col + first, col + first + length, dst);
    }
    m_u0_d.resize(nd);
    for (int i = 0; i < nd; ++i) m_u0_d(i) = m_u0_s(m_dofs[static_cast<size_t>(i)]);
    m_weights.resize(m);
    for (int i = 0; i < m; ++i) m_weights(i) = m_contact.weights()(m_rows[static_cast<size_t>(i)]);
    m_local.resize(static_cast<size_t>(m));
    for (int i = 0; i < m; ++i) m_local[static_cast<size_t>(i)] = i;
    m_full = f;
    return true;
  }

  const std::vector<int>& rows() const { return m_rows; }
  Eigen::VectorXd restrict(const Eigen::VectorXd& v) const {
    Eigen::VectorXd out(nd);
    for (int i = 0; i < nd; ++i) out(i) = v(m_dofs[static_cast<size_t>(i)]);
    return out;
  }

  /// The zone's rows of C and g at pairing p, columns on D (false: a row reaches outside D).
  bool assemble(const Pairing& p, ConstraintMatrix& c_local, Eigen::VectorXd& g) {
    m_contact.assemble_rows(p, m_rows, m_c, g);
    m_c.makeCompressed();
    return to_local(m_c, m_position, nd, c_local);
  }

  /// The solve at the zone's operator `c`, `g`: λ_A (false if G_AA is singular or a
  /// multiplier is not positive) and F on D; leaves G_AA's factor and S_DD C_Aᵀ.
  bool solve(const ConstraintMatrix& c, const Eigen::VectorXd& g, Eigen::VectorXd& lambda, Eigen::VectorXd& f_d) {
    delassus_parts(c, m_local, m_s_dd, m_sct);
    delassus_lower(c, m_sct, m_factor);
    if (m <= kUnblocked) {
      if (!cholesky_lower(m_factor)) return false;
    } else {  // a large zone (refined meshes): Eigen's blocked factorisation
      m_llt.compute(m_factor);
      if (m_llt.info() != Eigen::Success) return false;
      m_factor = m_llt.matrixLLT();  // L in the lower triangle, as cholesky_lower leaves it
    }
    lambda.noalias() = c * m_u0_d;
    lambda -= g;
    cholesky_solve(m_factor, lambda.data());
    if (!(lambda.array() > 0.0).all()) return false;
    f_d = m_u0_d;
    f_d.noalias() -= m_sct * lambda;
    return true;
  }

  /// The pairing of the zone's rows at the surface displacement whose D part is
  /// `x_d` (the rest is the loop's), into `out`; false when a row left the zone.
  bool search(const Eigen::VectorXd& x_d, const Pairing& hint, SearchMemory& memory, Pairing& out) {
    for (int i = 0; i < nd; ++i) m_full(m_dofs[static_cast<size_t>(i)]) = x_d(i);
    m_contact.search_rows(m_full, &m_rows, &hint, memory, out);
    for (int r : m_rows) {
      const int j = out.segment[static_cast<size_t>(r)], j0 = m_start->segment[static_cast<size_t>(r)];
      if (j < 0 || std::abs(j - j0) > m_options.reach) return false;
    }
    return true;
  }

  /// The fixed point's pairing_change() on the zone's rows: the solution (λ, F on D)
  /// at the operator c, g against the one at its re-pairing c', g'.
  double change(const ConstraintMatrix& c, const Eigen::VectorXd& g, const ConstraintMatrix& c_next,
                const Eigen::VectorXd& g_next, const Eigen::VectorXd& f_d, const Eigen::VectorXd& lambda) const {
    return pairing_change(c, g, c_next, g_next, f_d, lambda, m_weights, m_u_scale, m_options.tolerance, true);
  }

  double relative_move(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const {
    return (a - b).cwiseAbs().maxCoeff() / m_u_scale;
  }

  /// Factorises I − J of the Newton step from the solution (λ, F on D) of pairing
  /// `p`, whose re-pairing is `found` (see the file comment), into `lu`; false when
  /// the model has no linearisation or it reaches outside D.
  bool newton_system(const Pairing& p, const Pairing& found, const Eigen::VectorXd& lambda, const Eigen::VectorXd& f_d,
                     Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
    for (int i = 0; i < nd; ++i) m_full(m_dofs[static_cast<size_t>(i)]) = f_d(i);
    PairingLinearisation at, re;
    if (!m_contact.linearise_pairing(m_full, p, m_rows, at) || !m_contact.linearise_pairing(m_full, found, m_rows, re))
      return false;
    ConstraintMatrix dc;
    RowMatrix dq;
    if (!to_local(at.dc, m_position, nd, dc) || !to_local(re.dq_du, m_position, nd, dq)) return false;
    if (at.per_row != 2) return false;  // coordinates() and newton_step() read 2D coordinates
    const int k = at.per_row, nk = k * m;
    // dλ_A of coordinate j of row j / k, and S_DD dCᵀ.
    Eigen::MatrixXd dlambda = Eigen::MatrixXd::Zero(m, nk), sdc = Eigen::MatrixXd::Zero(nd, nk);
    for (int j = 0; j < nk; ++j) {
      const double lj = lambda(j / k);
      double moved = -at.dg(j);
      double* dl = dlambda.col(j).data();
      double* sj = sdc.col(j).data();
      for (ConstraintMatrix::InnerIterator e(dc, j); e; ++e) {
        const Eigen::Index col = e.col();
        const double v = e.value();
        moved += v * f_d(col);
        for (int a = 0; a < m; ++a) dl[a] -= lj * v * m_sct(col, a);
        const double* sc = m_s_dd.col(col).data();
        for (int i = 0; i < nd; ++i) sj[i] += v * sc[i];
      }
      dl[j / k] += moved;
      cholesky_solve(m_factor, dl);
    }
    // I − J = I + ∂q/∂u (S_DD C_Aᵀ dλ_A + S_DD dCᵀ diag(λ_r)).
    Eigen::MatrixXd dq_sct = Eigen::MatrixXd::Zero(nk, m), dq_sdc = Eigen::MatrixXd::Zero(nk, nk);
    for (int i = 0; i < nk; ++i)
      for (RowMatrix::InnerIterator e(dq, i); e; ++e) {
        const Eigen::Index col = e.col();
        const double v = e.value();
        for (int a = 0; a < m; ++a) dq_sct(i, a) += v * m_sct(col, a);
        for (int j = 0; j < nk; ++j) dq_sdc(i, j) += v * sdc(col, j);
      }
    Eigen::MatrixXd system = dq_sct * dlambda;
    for (int j = 0; j < nk; ++j) system.col(j) += lambda(j / k) * dq_sdc.col(j);
    system.diagonal().array() += 1.0;
    lu.compute(system);
    return true;
  }

  /// Pairing coordinates of the zone's rows (2D: segment + ξ, normal angle).
  Eigen::VectorXd coordinates(const Pairing& p) const {
    Eigen::VectorXd q(2 * m);
    for (int r = 0; r < m; ++r) {
      const int k = m_rows[static_cast<size_t>(r)];
      q(2 * r) = p.segment[static_cast<size_t>(k)] + p.xi[static_cast<size_t>(k)];
      q(2 * r + 1) = std::atan2(p.normal(1, k), p.normal(0, k));
    }
    return q;
  }

  /// `found` moved by the Newton (or chord) step with `lu` from pairing p.
  bool newton_step(const Pairing& p, const Pairing& found, const Eigen::PartialPivLU<Eigen::MatrixXd>& lu,
                   Pairing& out) const {
    const Eigen::VectorXd q = coordinates(p);
    Eigen::VectorXd step = coordinates(found) - q;
    for (int r = 0; r < m; ++r) step(2 * r + 1) = std::remainder(step(2 * r + 1), 2.0 * M_PI);
    const Eigen::VectorXd delta = lu.solve(step);
    if (!delta.allFinite()) return false;
    out = found;
    m_contact.move_pairing(out, m_rows, q + delta);
    return true;
  }

  /// The zone's rows of `from` into `to`.
  void copy_rows(const Pairing& from, Pairing& to) const {
    for (int r : m_rows) {
      const size_t k = static_cast<size_t>(r);
      to.segment[k] = from.segment[k], to.xi[k] = from.xi[k];
      to.normal.col(r) = from.normal.col(r);
    }
  }

  int m = 0, nd = 0;  // |A|, |D|

 private:
  const ContactModel& m_contact;
  const Eigen::MatrixXd& m_s;
  const Eigen::VectorXd& m_u0_s;
  const double m_u_scale;
  const ContactZoneOptions& m_options;
  const Pairing* m_start = nullptr;
  std::vector<int> m_rows, m_dofs, m_position, m_local;
  Eigen::MatrixXd m_s_dd, m_sct, m_factor;
  Eigen::LLT<Eigen::MatrixXd> m_llt;
  Eigen::VectorXd m_u0_d, m_weights, m_full;
  ConstraintMatrix m_c;
};

}  // namespace

bool contact_zone_step(const ContactModel& contact, const Eigen::MatrixXd& s, const Eigen::VectorXd& u0_s,
                       double u_scale, const PairedSolution& at, const Pairing& next, const SearchMemory& memory,
                       const ContactZoneOptions& options, Pairing& out, int& steps) {
  Zone zone(contact, s, u0_s, u_scale, options);
  if (!zone.set_up(at.lambda, next, at.surface_displacement)) return false;
  const bool newton = zone.m <= options.newton_max_active;
  SearchMemory zone_memory = memory;
  AndersonMixer mixer(options.anderson_depth, false);
  Pairing p = next, found;  // the pairing solved at, and its re-pairing
  Eigen::VectorXd x_d = zone.restrict(at.surface_displacement), f_d, x_next, g, g_next, lambda;
  ConstraintMatrix c, c_next;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  bool factorised = false;
  const double inf = std::numeric_limits<double>::infinity();
  double first = -1.0, last = inf, newton_change = inf;
  out = next;
  bool pending = false;  // f_d is a solution whose re-pairing is not in `out` yet
  for (int it = 0; it < options.max_steps; ++it) {
    if (!zone.assemble(p, c, g) || !zone.solve(c, g, lambda, f_d)) break;
    ++steps;
    double change;
    if (newton) {  // the fixed point's own measure, from the re-pairing at F
      if (!zone.search(f_d, p, zone_memory, found) || !zone.assemble(found, c_next, g_next)) break;
      zone.copy_rows(found, out);
      change = zone.change(c, g, c_next, g_next, f_d, lambda);
    } else {
      change = zone.relative_move(f_d, x_d);
    }
    pending = !newton;
    if (first < 0.0) first = change;
    last = change;
    if (change <= options.tolerance) break;
    if (newton && change <= options.newton_start && change < newton_change) {
      const bool chord = factorised && change <= options.chord_ratio * newton_change;
      if (!chord) factorised = zone.newton_system(p, found, lambda, f_d, lu);
      Pairing proposal;
      if (factorised && zone.newton_step(p, found, lu, proposal)) {
        newton_change = change;
        zone.copy_rows(proposal, p);
        x_d = f_d;
        mixer.clear();
        continue;
      }
    }
    mixer.next(x_d, f_d, x_next);
    std::swap(x_d, x_next);
    if (!zone.search(x_d, p, zone_memory, found)) break;
    std::swap(p, found);
  }
  if (pending) {  // the re-pairing of the last solution
    if (!zone.search(f_d, p, zone_memory, found)) return false;
    zone.copy_rows(found, out);
  }
  return first >= 0.0 && (last <= options.tolerance || last <= 0.5 * first);
}

}  // namespace contactrom::fom
