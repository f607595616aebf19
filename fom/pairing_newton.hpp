#pragma once
/// \file pairing_newton.hpp
/// \brief A Newton step of the contact pairing fixed point (docs/theory.md §2.2).
///
/// The fixed point x = F(x) of fom/pairing_fixed_point.hpp depends on x only through
/// the pairing coordinates q of the rows that carry pressure (2D: position along the
/// master chain and angle of the normal, ContactModel::linearise_pairing()), so its
/// Jacobian has rank k·|A| and the plain or Anderson-accelerated iteration converges
/// only linearly (hertz: 17 iterations to 1e-12, ironing: 30–45). Newton's method on
/// the coordinates, q ← q + (I − J)⁻¹ (Q(q) − q) with Q(q) the coordinates found at the
/// solution of the pairing q, converges quadratically once the active set A is settled.
///
/// J = ∂Q/∂q is exact: with the active rows' Delassus matrix G_AA = C_A S C_Aᵀ, the
/// solution's multipliers λ_A = G_AA⁻¹ (C_A u0_s − g_A) and surface displacement
/// F = u0_s − S C_Aᵀ λ_A, a change dC_A, dg_A of the rows at fixed u gives
///   dλ_A = G_AA⁻¹ (dC_A F − dg_A − C_A S dC_Aᵀ λ_A),  dF = −S (dC_Aᵀ λ_A + C_Aᵀ dλ_A),
/// and J = (∂q/∂u)(∂F/∂q). Only the rows of S on the dofs D that the active rows and
/// their coordinates touch enter (|D| ≈ 4|A| in 2D): a step costs O(|A|³), with no
/// dependence on the mesh beyond the contact zone, against O(n_s |W|) for a plain
/// iteration (n_s surface dofs, |W| the QP's working set). It pays where few rows
/// carry the contact: ironing (6 active rows of 50) needs 14 instead of 45
/// iterations and takes less time; hertz (27 of 79) needs 6 instead of 17 but each
/// step costs about four plain iterations (docs/results.md), hence the cap on |A|.
///
/// The step only chooses the next pairing: the QP at that pairing is solved exactly and
/// the fixed point's stopping test is unchanged, so a converged result is the same
/// fixed point as the plain iteration's (to its tolerance).
#include <Eigen/Dense>

#include <contactrom/fom/contact_model.hpp>

namespace contactrom::fom {

/// \brief The pairing of the Newton step from the solution (λ, F) of the pairing
/// `pairing` (operator `c`), whose re-pairing at F is `next`.
/// \param s the condensed surface compliance S = E_sᵀ K⁻¹ E_s (n_s x n_s)
/// \param max_rows no step when more rows than this are active (the step costs O(|A|³))
/// \param out `next` with the active rows (λ > 0) moved to the Newton coordinates
/// \returns false when there is no step: no active row or more than `max_rows`, a
///   model without linearisation, or a singular system (out is then unspecified).
bool newton_pairing(const ContactModel& contact, const Eigen::MatrixXd& s, const Pairing& pairing,
                    const ConstraintMatrix& c, const Eigen::VectorXd& lambda, const Eigen::VectorXd& f,
                    const Pairing& next, int max_rows, Pairing& out);

}  // namespace contactrom::fom
