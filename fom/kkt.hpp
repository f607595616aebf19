#pragma once
/// \file kkt.hpp
/// \brief Full-order KKT residuals and solution comparisons (docs/theory.md §2.3, §4).
///
/// For a candidate (u, λ) at parameter μ, the pairing is recomputed from u in the
/// deformed configuration and C(u), g(u) assembled. Residuals, all relative:
///  - stationarity: \f$ \|K u_0 - f + C^T\lambda\|_2 / \max(\|K u_0\|_2, \|f\|_2, \|C^T\lambda\|_2) \f$
///    on free dofs (\f$u_0\f$: u minus the lifting; a normwise backward error, at most 3,
///    and meaningful also when the load vanishes; the denominator is at least
///    \f$ \sqrt{n}\,\mathrm{DBL\_MIN}/\varepsilon \approx 10^{-292}\sqrt{n} \f$, below which
///    numbers are subnormal and a residual measures their lost bits, not the solution),
///  - penetration: \f$ \max_s (C u - g)_s^+ / (w_s\, U) \f$ (gap per node in units
///    of the problem's displacement scale U),
///  - negative pressure: \f$ \max_s (-\lambda_s)^+ / \|\lambda\|_\infty \f$,
///  - complementarity: \f$ |\lambda^T (C u - g)| / (U \sum_s w_s |\lambda_s|) \f$.
#include <Eigen/Dense>
#include <vector>

#include <contactrom/fom/problem.hpp>

namespace contactrom::fom {

/// \brief The four relative KKT residuals; see the file comment.
struct KktResiduals {
  double stationarity = 0.0;
  double penetration = 0.0;
  double negative_pressure = 0.0;
  double complementarity = 0.0;
  /// Largest of the four.
  double max() const;
};

/// \brief Gap of every constraint row in length units, \f$ -(Cu-g)_s / w_s \f$, with
/// the pairing recomputed from `u` (unpaired rows: +infinity).
Eigen::VectorXd normal_gaps(const Problem& problem, const Eigen::VectorXd& u);

/// \brief KKT residuals of (u, λ) at μ; `u` is the full displacement (lifting included).
/// \throws InputError for a `u`, λ or μ of the wrong size, or a μ outside its range.
KktResiduals kkt_residuals(const Problem& problem, const Param& mu, const Eigen::VectorXd& u,
                           const Eigen::VectorXd& lambda);

/// \brief Differences between a candidate and a reference solution.
struct SolutionErrors {
  double primal_h1 = 0.0;  ///< \f$ \|u-u_{ref}\|_{H^1} / \|u_{ref}\|_{H^1} \f$
  double dual_l2 = 0.0;    ///< \f$ \|\lambda-\lambda_{ref}\|_{L^2(\Gamma_c)} / \|\lambda_{ref}\|_{L^2(\Gamma_c)} \f$ (absolute if λ_ref = 0)
  int active_set_differences = 0;  ///< rows active in one and not the other, ignoring rows where
                                   ///< both pressure and gap are below `degenerate_tol`
};

/// \brief Relative errors of (u, λ) against (u_ref, λ_ref).
/// \param degenerate_tol threshold (relative to max λ_ref and the displacement scale) below which a
///   row with both small pressure and small gap is not counted as an active-set difference (default 1e-8)
SolutionErrors compare_solutions(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda,
                                 const Eigen::VectorXd& u_ref, const Eigen::VectorXd& lambda_ref,
                                 double degenerate_tol = 1e-8);

/// \brief Relative H¹ error of a full displacement against a reference.
double relative_h1_error(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& u_ref);
/// \brief Relative L²(Γc) error of pressures (absolute if the reference is zero).
double relative_l2_pressure_error(const Problem& problem, const Eigen::VectorXd& lambda,
                                  const Eigen::VectorXd& lambda_ref);

/// \brief A reference displacement whose H¹ norm is below this fraction of the
/// problem's scale \f$ U\,\|\mathbf 1\|_{H^1} \f$ (U the displacement scale, \f$\mathbf 1\f$
/// the field equal to 1 in every component, so the scale is U times the square root
/// of the domain's measure per component) counts as near zero: errors against it are
/// reported absolute, since a relative error divides by round-off there.
constexpr double kNearZeroReference = 1e-6;

/// \brief Errors of a candidate against a reference, relative unless the reference is near zero.
struct ReferenceErrors {
  /// \f$ \|u-u_{ref}\|_{H^1} / \|u_{ref}\|_{H^1} \f$, or \f$ \|u-u_{ref}\|_{H^1} \f$ when `absolute`.
  double primal = 0.0;
  /// \f$ \|\lambda-\lambda_{ref}\|_{L^2(\Gamma_c)} / \|\lambda_{ref}\|_{L^2(\Gamma_c)} \f$, or the
  /// numerator alone when `absolute` (or when λ_ref = 0).
  double dual = 0.0;
  /// The reference displacement is near zero (kNearZeroReference): both errors are absolute.
  bool absolute = false;
};

/// \brief Errors of (u, λ) against (u_ref, λ_ref): relative, or absolute when the
/// reference displacement is near zero (see kNearZeroReference).
ReferenceErrors reference_errors(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda,
                                 const Eigen::VectorXd& u_ref, const Eigen::VectorXd& lambda_ref);

/// \brief Total contact force \f$ \sum_s w_s \lambda_s \f$ (per unit thickness).
double contact_force(const Problem& problem, const Eigen::VectorXd& lambda);

}  // namespace contactrom::fom
