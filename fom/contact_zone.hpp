#pragma once
/// \file contact_zone.hpp
/// \brief The pairing fixed point of the contact zone alone: the FOM's step from a
/// solution of its pairing loop (docs/theory.md §2.2).
///
/// Once the pairing loop of fom/pairing_fixed_point.hpp is close (its change at
/// most ActiveSetOptions::zone_start), the rows that carry pressure — the active set
/// A — rarely change, and each row's segment moves by one at most. The rest of the
/// loop then iterates a map of the zone alone: the pairing of the rows in A → their
/// constraint rows C_A, g_A → the multipliers of the equality-constrained QP,
/// G_AA λ_A = C_A u0 − g_A with G_AA = C_A S C_Aᵀ → the surface displacement
/// F = u0 − S C_Aᵀ λ_A → the re-pairing of the rows in A at F. That map reads S only
/// on the dofs D that the zone's pairing reads (the slave nodes of A and the master
/// nodes of their segments, their neighbours and `reach` more on each side:
/// ContactModel::pairing_support()), so one step costs O(|D| |A|) against O(n_s |W|)
/// for a step of the whole loop, plus a search of |A| rows from the loop's memory.
///
/// The zone is iterated with Anderson steps on F restricted to D, or, while at most
/// `newton_max_active` rows are active and the change is at most `newton_start`,
/// with Newton steps on the pairing coordinates q (2D: the position along the master
/// chain and the angle of the normal of each row, ContactModel::linearise_pairing):
/// q ← q + (I − J)⁻¹ (Q(q) − q), Q(q) the coordinates found at the zone's solution
/// of the pairing q. J = ∂Q/∂q is exact: for a change dC_A, dg_A of the rows at fixed u,
///   dλ_A = G_AA⁻¹ (dC_A F − dg_A − C_A S dC_Aᵀ λ_A),  dF = −S (dC_Aᵀ λ_A + C_Aᵀ dλ_A),
/// and J = (∂q/∂u)(∂F/∂q), all on D. After a step that reduced the change to at most
/// `chord_ratio` times its value, the next step reuses the factorised I − J (a chord
/// step) instead of linearising again.
///
/// The result only chooses the next pairing of the whole loop: the loop solves the QP
/// of every row at it exactly and applies its own stopping test, so a converged
/// result is the loop's fixed point whatever the zone did (to its tolerance). The zone
/// stops — and proposes the pairing of its last solution — when its change is at most
/// `tolerance`, when a row leaves the zone (no pair, or a segment more than `reach`
/// from the one it started on), when a multiplier of A is not positive (the active set
/// changes: the whole loop decides how) or after `max_steps`.
#include <Eigen/Dense>

#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/pairing_fixed_point.hpp>

namespace contactrom::fom {

/// \brief Options of contact_zone_step() (documented defaults).
struct ContactZoneOptions {
  int max_steps = 60;         ///< cap on the zone's solves per call. Default 60.
  /// Stop when the zone's change is at most this: relative to the displacement scale,
  /// the largest change of F on D between two Anderson steps, or the fixed point's
  /// pairing_change() of the zone's rows while it takes Newton steps. Default 1e-13,
  /// below the FOM's pairing tolerance (1e-12), so that the whole loop's test passes
  /// at the proposed pairing.
  double tolerance = 1e-13;
  /// Segments a row may move from the one it started on before the zone stops (the
  /// dofs D cover them). Default 2.
  int reach = 2;
  /// No zone of more rows than this: G_AA's Cholesky factorisation, O(|A|³) at every
  /// zone step, then costs about what a step of the whole loop does, and the zone's
  /// extra steps are not repaid (measured on hertz: refine 2, up to 161 rows, 12 %
  /// faster with the zone; refine 3, about 245 rows, even; refine 4, about 430 rows,
  /// 1.28× slower). Default 200.
  int max_rows = 200;
  int anderson_depth = 5;     ///< Anderson depth of the zone's steps. Default 5.
  /// Newton steps while at most this many rows are active: a Newton step costs
  /// O(|A|³ + |D| |A|²), against O(|D| |A|) for an Anderson step (measured: ironing,
  /// 6 rows, pays; hertz, 27–38 rows, does not). Default 16.
  int newton_max_active = 16;
  double newton_start = 0.3;  ///< ... once the zone's change is at most this. Default 0.3.
  /// A chord step (the last factorised I − J again) after a step that reduced the
  /// change to at most this fraction. Default 0.05.
  double chord_ratio = 0.05;
};

/// \brief The pairing that the contact zone's fixed point proposes from the solution
/// `at` of a pairing whose re-pairing at `at.surface_displacement` is `next` (see
/// the file comment).
/// \param s the condensed surface compliance S (n_s x n_s)
/// \param u0_s the unconstrained displacement on the surface dofs
/// \param u_scale the problem's displacement scale
/// \param memory the loop's search memory (copied: the zone's searches start from it)
/// \param out `next` with the zone's rows moved to the proposed pairing
/// \param steps incremented by the zone's solves
/// \returns whether there is a proposal: the zone converged or at least halved its
///   change. False without active rows or with more than `max_rows`, for a model
///   without pairing support, or when the zone's first step already left it.
bool contact_zone_step(const ContactModel& contact, const Eigen::MatrixXd& s, const Eigen::VectorXd& u0_s,
                       double u_scale, const PairedSolution& at, const Pairing& next, const SearchMemory& memory,
                       const ContactZoneOptions& options, Pairing& out, int& steps);

}  // namespace contactrom::fom
