#pragma once
/// \file kkt_verifier.hpp
/// \brief KKT verification of candidate contact solutions (FOM, reduced, baselines)
/// against the optimality conditions of the full-order QP and, optionally, against
/// a reference solution (usually the Ipopt one; docs/theory.md §2.3).
///
/// All quantities come from fom/kkt.hpp (one implementation of the residuals and
/// errors): for a candidate (u, λ) at μ the pairing is recomputed from u in the
/// deformed configuration, then
///  - KKT residuals (relative): stationarity, penetration, negative pressure,
///    complementarity — see fom::kkt_residuals;
///  - against a reference: primal relative H¹ error, dual relative L²(Γc) error and
///    the number of active-set differences outside degenerate rows — see
///    fom::compare_solutions.
/// Reports aggregate into a VerificationSummary of plain numbers (max of each
/// quantity over many parameters) that a CLI writes as JSON or CSV.
///
/// Example (`contactrom verify`): for every validation parameter, verify the reduced
/// solution against the Ipopt reference and `add()` the report to a summary.
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>

namespace contactrom::baselines {

/// \brief Verification of one candidate solution.
struct VerificationReport {
  fom::Param mu;  ///< parameter of the candidate
  /// Success, or InvalidInput when sizes are inconsistent (u, λ, reference) or
  /// values are not finite; then every residual and error is +infinity.
  Status status = Status::Success;
  std::string message;    ///< what was inconsistent, when status != Success
  fom::KktResiduals kkt;  ///< relative KKT residuals (fom::kkt_residuals)
  bool has_reference = false;  ///< whether `errors` was computed
  fom::SolutionErrors errors;  ///< errors against the reference (fom::compare_solutions)
};

/// \brief Verifies a candidate (u, λ) at μ.
/// \param problem the full-order problem
/// \param mu parameter (must have problem.num_params() entries)
/// \param u full displacement, lifting included (problem.num_dofs())
/// \param lambda contact pressure per constraint row (contact().num_constraints())
/// \param reference optional reference solution at the same μ (e.g. IpoptQpSolver's);
///   nullptr: only the KKT residuals are computed
/// \param degenerate_tol rows whose pressure and gap are both below this (relative) are
///   not counted as active-set differences (default 1e-8, see fom::compare_solutions)
/// \returns the report; never throws on numerical input, inconsistent sizes give
///   status InvalidInput
VerificationReport verify_solution(const fom::Problem& problem, const fom::Param& mu, const Eigen::VectorXd& u,
                                   const Eigen::VectorXd& lambda, const fom::FomSolution* reference = nullptr,
                                   double degenerate_tol = 1e-8);

/// \brief Same, for a candidate given as a FomSolution (its μ, u and λ).
VerificationReport verify_solution(const fom::Problem& problem, const fom::FomSolution& candidate,
                                   const fom::FomSolution* reference = nullptr, double degenerate_tol = 1e-8);

/// \brief Aggregate of many reports: the maximum of each quantity (NaN counts as
/// +infinity), means of the errors, and counts. Plain numbers, ready for JSON.
struct VerificationSummary {
  int count = 0;           ///< reports added
  int invalid = 0;         ///< reports with status != Success
  int with_reference = 0;  ///< reports that carry errors against a reference
  fom::KktResiduals max_kkt;              ///< componentwise maximum of the KKT residuals
  double max_primal_h1 = 0.0;             ///< max relative H¹ error against the reference
  double max_dual_l2 = 0.0;               ///< max relative L²(Γc) pressure error against the reference
  double mean_primal_h1 = 0.0;            ///< mean over reports with a reference
  double mean_dual_l2 = 0.0;              ///< mean over reports with a reference
  int max_active_set_differences = 0;     ///< max over reports
  int total_active_set_differences = 0;   ///< sum over reports

  /// Adds one report.
  void add(const VerificationReport& report);
  /// Largest KKT residual of all kinds.
  double max_kkt_residual() const { return max_kkt.max(); }
  /// (key, value) pairs in a fixed order for JSON/CSV writers: count, invalid,
  /// with_reference, max_stationarity, max_penetration, max_negative_pressure,
  /// max_complementarity, max_kkt, max_primal_error, mean_primal_error, max_dual_error,
  /// mean_dual_error, max_active_set_differences, total_active_set_differences.
  std::vector<std::pair<std::string, double>> fields() const;

 private:
  double m_sum_primal_h1 = 0.0, m_sum_dual_l2 = 0.0;
};

/// \brief Summary of a list of reports (VerificationSummary::add on each).
VerificationSummary summarize(const std::vector<VerificationReport>& reports);

}  // namespace contactrom::baselines
