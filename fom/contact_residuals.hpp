#pragma once
/// \file contact_residuals.hpp
/// \brief Full-order contact residuals of a candidate solution measured on the
/// contact surface only, row by row, at the candidate's own pairing — what a
/// reduced answer is judged by before it may report `success` (docs/rom.md,
/// "Statuses"; docs/theory.md §3.4).
///
/// For a surface displacement u_s and a pressure λ (one value per constraint row),
/// the pairing is searched at u_s and C(u_s), g(u_s) assembled on every row; with
/// the gap per node \f$ d_s = (C u_s - g)_s / w_s \f$ (positive: penetration):
///  - penetration: \f$ \max_s d_s^+ / U \f$ (U: the problem's displacement scale),
///  - negative pressure: \f$ \max_s (-\lambda_s)^+ / \|\lambda\|_\infty \f$,
///  - separation under pressure: \f$ \sum_s w_s |\lambda_s|\,|d_s| / (U \sum_s w_s |\lambda_s|) \f$,
///    the pressure-weighted mean distance between the surfaces where λ ≠ 0 — the
///    row-by-row complementarity: unlike \f$ |\lambda^T (Cu - g)| \f$ no row's
///    penetration can cancel another row's separation.
/// Every row counts on its own, so one contact pair's penetration is never paid for
/// by another pair's lift-off. Cost: one contact search and assembly on the surface
/// (no mesh-size operation).
#include <Eigen/Dense>
#include <string>

#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/problem.hpp>

namespace contactrom::fom {

/// \brief Tolerances of the contact residuals (relative, see the file comment).
struct ContactTolerances {
  /// Largest penetration, in units of the displacement scale U. Default 5e-2.
  double penetration = 5e-2;
  /// Largest separation under pressure (pressure-weighted mean |gap|), in units of
  /// U. Default 5e-2.
  double complementarity = 5e-2;
  /// Largest negative pressure relative to the largest pressure. Default 1e-2.
  double negative_pressure = 1e-2;
};

/// \brief The tolerances a candidate's gaps are judged by, on its own scale: those
/// of `tol` when the candidate's largest surface displacement \f$ \|u_s\|_\infty \f$
/// is at least U, else its penetration and separation tolerances times
/// `scale` = \f$ \max(\|u_s\|_\infty / U,\ 10^{-6}) \f$ (the residuals stay in units
/// of U). Far below the loads U describes, U's tolerance would pass a gap as large
/// as the whole answer; below 1e-6 U the load counts as zero (kNearZeroReference of
/// fom/kkt.hpp). The negative-pressure tolerance is relative to ‖λ‖∞ already.
struct ScaledContactTolerances {
  ContactTolerances tolerances;  ///< the scaled tolerances
  double scale = 1.0;            ///< the factor applied (1: U's own)
};
ScaledContactTolerances tolerances_on_own_scale(const ContactTolerances& tol, const Eigen::VectorXd& u_surface,
                                                double displacement_scale);

/// \brief The row-by-row contact residuals of a candidate; see the file comment.
struct ContactResiduals {
  double penetration = 0.0;        ///< max_s d_s^+ / U
  int penetration_row = -1;        ///< the row of that maximum (−1: no penetration)
  double negative_pressure = 0.0;  ///< max_s (−λ_s)^+ / ‖λ‖∞
  int negative_pressure_row = -1;  ///< the row of that maximum (−1: none negative)
  double complementarity = 0.0;    ///< Σ w_s|λ_s||d_s| / (U Σ w_s|λ_s|)
  int complementarity_row = -1;    ///< the row contributing most to it (−1: λ = 0)
  /// Whether every residual is finite and within `tol`.
  bool within(const ContactTolerances& tol) const;
  /// Whether the gap conditions alone — penetration and separation under pressure —
  /// are finite and within `tol` (the online fixed points' physical test).
  bool gaps_within(const ContactTolerances& tol) const;
  /// One line naming each residual above its tolerance and its row, e.g.
  /// "penetration 4.65 U at contact row 12 (tolerance 0.01)"; empty when within.
  std::string describe(const ContactTolerances& tol) const;
};

/// \brief Contact residuals of (u_s, λ) at the pairing searched at u_s.
/// \param u_surface displacement of the contact-surface dofs (ContactModel::surface_dofs order)
/// \param lambda pressure per constraint row (size ContactModel::num_constraints())
ContactResiduals contact_residuals(const Problem& problem, const Eigen::VectorXd& u_surface,
                                   const Eigen::VectorXd& lambda);

/// \brief Same, with `pairing` already searched at u_surface (e.g. by a search with a
/// memory, ContactModel::search_rows, which gives the same pairing faster).
ContactResiduals contact_residuals(const Problem& problem, const Pairing& pairing, const Eigen::VectorXd& u_surface,
                                   const Eigen::VectorXd& lambda);

/// \brief The residuals of the file comment from the gaps of a set of rows:
/// `gap` = (Cu − g) on those rows, `weights` and `lambda` on the same rows (all of
/// one length; rows in the result are positions in them). The other overloads, and
/// a reduced method testing its own support rows, call this.
ContactResiduals contact_residuals_of_gaps(const Eigen::VectorXd& gap, const Eigen::VectorXd& weights,
                                           const Eigen::VectorXd& lambda, double displacement_scale);

/// \brief The problem's tolerances: its file's `[rom]` `penetration_tolerance`,
/// `complementarity_tolerance` and `negative_pressure_tolerance`, else the defaults
/// of ContactTolerances.
ContactTolerances default_contact_tolerances(const Problem& problem);

}  // namespace contactrom::fom
