#pragma once
/// \file error_indicator.hpp
/// \brief A posteriori estimate of the errors of a reduced answer without the FOM
/// solve: the answer is corrected by the exact condensed contact problem of the
/// FOM on the contact surface, from the answer's own pairing, and the estimates are
/// the errors of the answer against that correction, in the norms of the true
/// errors (relative H¹ for the displacement, relative L²(Γc) for the pressure).
/// Derivation in docs/theory.md ("Error estimate of a reduced answer").
///
/// Offline (once per model, one factorisation of K): the surface flexibility
/// \f$ S = E_s^T K^{-1} E_s \f$ and the unconstrained load responses z_k (the FOM's
/// condensation, fom::condense), and the H¹ products that let the norm of a field
/// \f$ V a + K^{-1} E_s y \f$ be evaluated from its coordinates a and the surface
/// force y: \f$ V^T H V \f$, \f$ V^T H K^{-1} E_s \f$ and
/// \f$ E_s^T K^{-1} H K^{-1} E_s \f$ (H: the Gram matrix of the H¹ norm), with
/// \f$ V = [\Phi,\ \tilde L - Z] \f$. A model that keeps its primal snapshots P also
/// gets the same products of \f$ W = [P,\ L - Z] \f$ (L: the lifting terms), for
/// answers that combine snapshots (the convex hull: \f$ a = (\alpha, \phi(\mu)) \f$).
///
/// Per answer (û, λ_r) at μ, pairing P searched at its surface displacement u_s:
///  1. C, g at P; the FOM dual QP at that pairing (working set of the rows within a
///     margin of contact, warm-started by λ_r), re-paired at its own displacement by
///     the FOM's pairing loop until the contact forces and gaps change by at most
///     ErrorIndicatorOptions::pairing_tolerance (1 %), gives λ_c and C;
///  2. \f$ u_c = z(\mu) - K^{-1}E_s C^T\lambda_c \f$, never formed: with
///     \f$ y = C^T\lambda_c \f$ and \f$ a = (\hat u, \phi(\mu)) \f$,
///     \f$ \|u_r - u_c\|_H^2 = a^T V^T H V a + 2 a^T V^T H K^{-1}E_s y + y^T E_s^T K^{-1} H K^{-1} E_s y \f$;
///  3. primal estimate \f$ \|u_r - u_c\|_H / \|u_c\|_H \f$, dual estimate
///     \f$ \|\lambda_r - \lambda_c\|_{L^2(\Gamma_c)} / \|\lambda_c\|_{L^2(\Gamma_c)} \f$
///     (absolute when \f$ u_c \f$ is near zero, as the true errors).
/// Cost: one dual QP on the working set (Delassus block \f$ C_W S C_W^T \f$) per
/// pairing (one when the answer's pairing is already the FOM's, to the tolerance;
/// more where it is not, i.e. on the answers that are wrong) and quadratic forms on
/// the support of y: no mesh-size operation.
///
/// Requires a stiffness independent of the parameters (one factorisation serves
/// every query); otherwise available() is false and the estimates are NaN.
#include <Eigen/Dense>
#include <limits>
#include <vector>
#include <memory>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/contact_model.hpp>
#include <contactrom/fom/problem.hpp>

namespace contactrom::rom {

class ReducedModel;

/// \brief Options of ErrorIndicator (documented defaults).
struct ErrorIndicatorOptions {
  /// Cap on the pairings the correction is solved at: 1 = the answer's own pairing
  /// only; k > 1 runs the FOM's pairing loop (fom::solve_pairing_loop: Anderson and
  /// contact-zone steps) from the answer's pairing and surface displacement until
  /// re-pairing changes the correction by at most `pairing_tolerance`, or k solves.
  /// Default 20.
  int pairing_iterations = 20;
  /// Relative change of the correction's contact forces and gaps under re-pairing
  /// (fom::pairing_change) at which the loop stops: the estimates need the correction
  /// to a few per cent, not to the FOM's 1e-12. Default 1e-2.
  double pairing_tolerance = 1e-2;
  /// Options of the FOM's dual QP (working-set margin, QP tolerances) and pairing loop.
  /// Default: the FOM's, except its steps on the contact zone: from a change of 0.1
  /// (`zone_start`; the FOM's 0.3 lets the loose stop above end at pairings reached
  /// by steps from farther away, whose pressures are farther from the FOM's — ironing
  /// level 5: dual effectivity 0.34–1.63 against 0.8–1.25) and not again after one that
  /// did not reduce the change (`zone_retry` 0; retried steps cost more than they
  /// save when the loop stops at 1 % — hertz 30: 86 → 101 µs a query), and the zone
  /// settled to a change of 1e-3 (`zone.tolerance`) rather than the FOM's 1e-13
  /// (ironing 7: 255 → 222 µs a query).
  fom::ActiveSetOptions fom = [] {
    fom::ActiveSetOptions o;
    o.zone_start = 0.1;
    o.zone_retry = 0.0;
    o.zone.tolerance = 1e-3;
    return o;
  }();
};

/// \brief An answer made of the model's primal snapshots (ErrorIndicator::estimate()).
struct SnapshotCombination {
  const std::vector<int>& columns;        ///< dictionary columns
  const Eigen::VectorXd& coefficients;    ///< one per column
};

/// \brief The estimate of one answer.
struct ErrorEstimate {
  double primal = std::numeric_limits<double>::quiet_NaN();  ///< estimate of the relative H¹ error (absolute if `absolute`)
  double dual = std::numeric_limits<double>::quiet_NaN();    ///< estimate of the relative L²(Γc) error (absolute if `absolute`)
  /// The corrected displacement is near zero (fom::kNearZeroReference): both are absolute.
  bool absolute = false;
  /// Success; NumericalIssue when the correction's QP failed (estimates NaN); InvalidInput
  /// when the indicator is unavailable or the answer has no fields.
  Status status = Status::InvalidInput;
  int qp_iterations = 0;  ///< active-set iterations of the correction
  int pairings = 0;       ///< pairings the correction was solved at
  double time_s = 0.0;    ///< wall time of the estimate
};

/// \brief Why the answers of a reduced model of `problem` can have no error estimate
/// ("the stiffness of problem 'X' depends on its parameters"); empty when they can.
std::string no_error_estimate_reason(const fom::Problem& problem);

/// \brief The error estimate of a reduced model's answers; see the file comment.
/// Immutable after construction; estimate() is const and thread-safe.
class ErrorIndicator {
 public:
  /// \brief Builds the offline operators for `model` (its problem must outlive the indicator).
  explicit ErrorIndicator(const ReducedModel& model, ErrorIndicatorOptions options = {});
  ~ErrorIndicator();

  /// Whether estimates can be made (a parameter-independent stiffness).
  bool available() const { return m_available; }
  /// The problem of the model.
  const fom::Problem& problem() const { return m_problem; }
  /// Seconds spent building the operators.
  double setup_time() const { return m_setup_time; }

  /// \brief Estimates the errors of the answer (û, λ) at μ.
  /// \param u_hat reduced coordinates (size r of the model)
  /// \param lambda pressure per constraint row
  /// \param pairing the pairing searched at the answer's surface displacement `u_surface`
  /// \param pairings cap on the correction's pairings (≤ 0: ErrorIndicatorOptions::pairing_iterations)
  /// \param memory memory of the search that found `pairing` (its re-pairings start
  ///   from it: the same estimate, less searching), or nullptr
  /// \param combination for an answer that is a combination of the model's primal
  ///   snapshots, u = u_lift(μ) + Σ_i coefficients_i P[:, columns_i] (the convex hull),
  ///   rather than Φû + u_off(μ): its primal estimate is then that answer's own (when
  ///   the model keeps its primal snapshots; else that of Φû); nullptr: Φû + u_off(μ).
  ErrorEstimate estimate(const fom::Param& mu, const Eigen::VectorXd& u_hat, const Eigen::VectorXd& lambda,
                         const fom::Pairing& pairing, const Eigen::VectorXd& u_surface, int pairings = 0,
                         const fom::SearchMemory* memory = nullptr,
                         const SnapshotCombination* combination = nullptr) const;

 private:
  void build(const ReducedModel& model);

  const fom::Problem& m_problem;
  int m_rank = 0;
  ErrorIndicatorOptions m_options;
  bool m_available = false;
  double m_setup_time = 0.0;
  fom::Condensation m_cond;   // S and the unconstrained load responses (factor released)
  Eigen::MatrixXd m_z_s;      // z_k on the surface dofs, n_s × T
  Eigen::MatrixXd m_vhv;      // Vᵀ H V, (r+T)²
  Eigen::MatrixXd m_vhs;      // Vᵀ H K⁻¹ E_s, (r+T) × n_s
  Eigen::MatrixXd m_zhz;      // Zᵀ H Z, T × T
  Eigen::MatrixXd m_zhs;      // Zᵀ H K⁻¹ E_s, T × n_s
  Eigen::MatrixXd m_shs;      // E_sᵀ K⁻¹ H K⁻¹ E_s, n_s × n_s
  // With the model's primal snapshots P (m columns): W = [P, L − Z], the answer of a
  // combination being W (α, φ) + z(μ) (L: the lifting terms).
  Eigen::MatrixXd m_whw;      // Wᵀ H W, (m+T)², empty without the snapshots
  Eigen::MatrixXd m_whs;      // Wᵀ H K⁻¹ E_s, (m+T) × n_s
  double m_near_zero = 0.0;   // ‖u_c‖_H below which the estimates are absolute
};

}  // namespace contactrom::rom
