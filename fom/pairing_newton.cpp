#include <contactrom/fom/pairing_newton.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace contactrom::fom {
namespace {

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// Adds the columns of the listed rows of `m` to the dof list (unsorted, marked in `position`).
void collect_columns(const RowMatrix& m, const std::vector<int>* rows, std::vector<int>& position,
                     std::vector<int>& dofs) {
  const Eigen::Index n = rows ? static_cast<Eigen::Index>(rows->size()) : m.rows();
  for (Eigen::Index i = 0; i < n; ++i)
    for (RowMatrix::InnerIterator it(m, rows ? (*rows)[static_cast<size_t>(i)] : i); it; ++it)
      if (position[it.col()] < 0) position[it.col()] = 0, dofs.push_back(static_cast<int>(it.col()));
}

/// Column j of the result: Σ over the entries (col, v) of row rows[j] of `m` of v · S(D, col).
Eigen::MatrixXd compliance_columns(const Eigen::MatrixXd& s, const std::vector<int>& dofs, const RowMatrix& m,
                                   const std::vector<int>* rows) {
  const Eigen::Index n = rows ? static_cast<Eigen::Index>(rows->size()) : m.rows();
  const Eigen::Index nd = static_cast<Eigen::Index>(dofs.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(nd, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (RowMatrix::InnerIterator it(m, rows ? (*rows)[static_cast<size_t>(j)] : j); it; ++it) {
      const double* column = s.data() + it.col() * s.rows();  // S is symmetric: S(D, col) = S(col, D)ᵀ
      for (Eigen::Index i = 0; i < nd; ++i) out(i, j) += it.value() * column[dofs[static_cast<size_t>(i)]];
    }
  return out;
}

/// Row i of the result: Σ over the entries (col, v) of row rows[i] of `m` of v · Y(position[col], :).
Eigen::MatrixXd gather_rows(const RowMatrix& m, const std::vector<int>* rows, const std::vector<int>& position,
                            const Eigen::MatrixXd& y) {
  const Eigen::Index n = rows ? static_cast<Eigen::Index>(rows->size()) : m.rows();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, y.cols());
  for (Eigen::Index i = 0; i < n; ++i)
    for (RowMatrix::InnerIterator it(m, rows ? (*rows)[static_cast<size_t>(i)] : i); it; ++it)
      out.row(i) += it.value() * y.row(position[it.col()]);
  return out;
}

}  // namespace

bool newton_pairing(const ContactModel& contact, const Eigen::MatrixXd& s, const Pairing& pairing,
                    const ConstraintMatrix& c, const Eigen::VectorXd& lambda, const Eigen::VectorXd& f,
                    const Pairing& next, int max_rows, Pairing& out) {
  std::vector<int> active;
  for (Eigen::Index r = 0; r < lambda.size(); ++r)
    if (lambda(r) > 0.0) active.push_back(static_cast<int>(r));
  if (active.empty() || static_cast<int>(active.size()) > max_rows) return false;
  for (int r : active)
    if (next.segment[static_cast<size_t>(r)] < 0) return false;  // an active row left its master: no Newton model
  PairingLinearisation at, found;  // of the pairing solved on, and of the one found at its solution
  if (!contact.linearise_pairing(f, pairing, active, at) || !contact.linearise_pairing(f, next, active, found))
    return false;
  const int m = static_cast<int>(active.size()), k = at.per_row, nk = k * m;

  // The dofs D the active rows, their derivatives and the coordinates touch.
  std::vector<int> position(static_cast<size_t>(c.cols()), -1), dofs;
  collect_columns(c, &active, position, dofs);
  collect_columns(at.dc, nullptr, position, dofs);
  collect_columns(found.dq_du, nullptr, position, dofs);
  std::sort(dofs.begin(), dofs.end());
  for (size_t i = 0; i < dofs.size(); ++i) position[static_cast<size_t>(dofs[i])] = static_cast<int>(i);

  const Eigen::MatrixXd y = compliance_columns(s, dofs, c, &active);   // (S C_Aᵀ)_D, |D| x m
  const Eigen::MatrixXd g_aa = gather_rows(c, &active, position, y);  // C_A S C_Aᵀ
  const Eigen::MatrixXd dc_y = gather_rows(at.dc, nullptr, position, y);  // dC S C_Aᵀ, km x m
  // dλ_A per coordinate j of row r: G_AA⁻¹ (e_r (dC_j F − dg_j) − λ_r C_A S dC_jᵀ).
  Eigen::MatrixXd rhs(m, nk);
  const Eigen::VectorXd moved = at.dc * f - at.dg;
  for (int j = 0; j < nk; ++j) {
    const double lam = lambda(active[static_cast<size_t>(j / k)]);
    rhs.col(j) = -lam * dc_y.row(j).transpose();
    rhs(j / k, j) += moved(j);
  }
  const Eigen::LDLT<Eigen::MatrixXd> g_factor(g_aa);
  if (g_factor.info() != Eigen::Success) return false;
  const Eigen::MatrixXd dlambda = g_factor.solve(rhs);
  // J = ∂q/∂u dF with dF = −S dCᵀ λ_r − S C_Aᵀ dλ_A, ∂q/∂u sparse on D: the products
  // with it first (its rows have about ten entries).
  const Eigen::MatrixXd dq_y = gather_rows(found.dq_du, nullptr, position, y);  // km x m
  const Eigen::MatrixXd b = compliance_columns(s, dofs, at.dc, nullptr);          // (S dCᵀ)_D, |D| x km
  Eigen::MatrixXd jac = -dq_y * dlambda;
  jac.noalias() -= gather_rows(found.dq_du, nullptr, position, b) *
                   Eigen::VectorXd(Eigen::VectorXd::NullaryExpr(nk, [&](Eigen::Index j) {
                     return lambda(active[static_cast<size_t>(j / k)]);
                   })).asDiagonal();

  // q ← q + (I − J)⁻¹ (Q − q); angles compared on the circle.
  Eigen::VectorXd step = found.q - at.q;
  if (k == 2)
    for (int r = 0; r < m; ++r) step(2 * r + 1) = std::remainder(step(2 * r + 1), 2.0 * M_PI);
  const Eigen::MatrixXd system = Eigen::MatrixXd::Identity(nk, nk) - jac;
  const Eigen::VectorXd delta = system.partialPivLu().solve(step);
  if (!delta.allFinite()) return false;
  out = next;
  contact.move_pairing(out, active, at.q + delta);
  return true;
}

}  // namespace contactrom::fom
