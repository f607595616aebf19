#pragma once
/// \file verification.hpp
/// \brief KKT verification of online ROM methods against a reference FOM solver
/// over a parameter set: what `contactrom verify` computes, as one library call.
///
/// For every parameter and every method:
///  - the FOM KKT residuals of the reduced solution (verify_solution: stationarity,
///    penetration, negative pressure, complementarity, full-order and relative),
///  - its errors against the reference solution (primal H¹, dual L²(Γc), active-set
///    differences),
///  - the reduced-level penetration \f$ \max_p W_p^T(C(u)u - g(u)) \f$ over the
///    method's dual columns (greedy and full-dictionary: every dictionary column;
///    cpg: its basis), accepted when at most τ + VerifyReport::reduced_penetration_slack,
/// and the same KKT residuals of the reference solution itself. The reference is
/// IpoptQpSolver ("ipopt") or the custom active-set FOM ("fom", fast); several
/// methods share one set of reference solves. With VerifyOptions::bench the
/// methods and the FOM are also timed in interleaved rounds (rom::time_interleaved).
///
/// \code
///   contactrom::baselines::VerifyOptions o;
///   o.methods = {{"greedy", {}}, {"cpg", {}}};
///   const auto report = contactrom::baselines::verify(model, rom::database_validation_set(db, problem), o);
///   // report.methods[0].summary.max_kkt, report.reference_summary.max_kkt, ...
/// \endcode
/// Command line: `contactrom verify --db hertz30.h5 --method greedy,cpg --json`.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <contactrom/baselines/kkt_verifier.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::baselines {

/// \brief An online method to verify, with its settings.
struct VerifyMethod {
  std::string name;                   ///< registry name (rom/online_methods.hpp)
  rom::OnlineSolverOptions options;   ///< its settings (validated by the registry)
};

/// \brief Settings of verify() (documented defaults).
struct VerifyOptions {
  /// Methods to verify, each once. Default: `greedy` with its defaults.
  std::vector<VerifyMethod> methods{{"greedy", {}}};
  /// Reference solver: "ipopt" (baselines::IpoptQpSolver) or "fom" (the custom
  /// active-set solver). Default "ipopt".
  std::string reference = "ipopt";
  /// Threads of the reference solves; ≤ 0: hardware concurrency. Default 0.
  int threads = 0;
  /// Also time every method and the FOM in interleaved rounds. Default false.
  bool bench = false;
  /// Timing rounds with `bench`. Default 3.
  int repeats = 3;
  /// Called as solves complete: (stage label, done, total); optional.
  std::function<void(const std::string& stage, int done, int total)> progress;
};

/// \brief Per-parameter outcome of one method.
struct VerifyRow {
  VerificationReport report;         ///< KKT residuals and errors against the reference
  /// Errors against the reference: relative, or absolute where the reference
  /// displacement is near zero (fom::reference_errors, the rule of `online`).
  fom::ReferenceErrors errors;
  double reduced_penetration = 0.0;  ///< max over the dual columns of W_pᵀ(Cu − g)
  Status status = Status::Success;   ///< the online solve's status
  bool converged = false;            ///< the online solve's stopping criterion was met
  int iterations = 0;                ///< online iterations
  int sparsity = 0;                  ///< |I|, selected dual columns
  double time_s = 0.0;               ///< online core time (rom::OnlineResult::time_s)
};

/// \brief Verification of one method over the parameter set.
struct MethodVerification {
  std::string name;                  ///< registry name
  std::vector<int> dual_columns;     ///< dictionary columns of the reduced constraint
  bool reduced_constraint = false;   ///< whether the method imposes Wᵀ(Cu − g) ≤ τ
  double tau = 0.0;                  ///< threshold τ of that constraint
  std::vector<VerifyRow> rows;       ///< one per parameter, in order
  VerificationSummary summary;       ///< maxima and means of the rows' reports
  /// Means and maxima of the rows' `errors`: relative ones averaged, absolute ones
  /// (near-zero reference) counted apart.
  rom::ErrorStatistics errors;
  double max_reduced_penetration = -std::numeric_limits<double>::infinity();  ///< over the rows
  int reduced_violations = 0;        ///< rows whose reduced penetration exceeds τ + slack
  int nonconverged = 0;              ///< rows not converged or failed (not counting `inaccurate`)
  int inaccurate = 0;                ///< rows with Status::Inaccurate (contact residuals above tolerance)
  double mean_time_s = 0.0;          ///< mean online core time
  double mean_sparsity = 0.0;        ///< mean |I|
  double mean_iterations = 0.0;      ///< mean iterations
  rom::OnlineTiming timing;          ///< medians (VerifyOptions::bench only)
  double basis_time_s = 0.0;         ///< offline construction of the CPG basis (cpg only)
};

/// \brief Everything verify() computed.
struct VerifyReport {
  std::vector<fom::Param> params;                      ///< the parameters, in order
  std::string reference;                               ///< "ipopt" or "fom"
  std::vector<fom::FomSolution> references;            ///< reference solutions
  std::vector<VerificationReport> reference_reports;   ///< their KKT residuals
  VerificationSummary reference_summary;               ///< maxima over the references
  int reference_failures = 0;                          ///< references whose status != Success
  double reference_wall_s = 0.0;                       ///< wall time of the reference solves
  std::vector<MethodVerification> methods;             ///< in the order requested
  double fom_median_time_s = 0.0;                      ///< FOM time per query (bench only)
  /// Slack of the reduced-level acceptance test max_p W_pᵀ(Cu − g) ≤ τ + slack.
  double reduced_penetration_slack = 1e-10;
};

/// \brief Verifies every method of `options` on `model` at `params` (see the file
/// comment). Reduced solves run sequentially (their times undisturbed); the
/// reference solves in parallel.
/// \throws InputError for an unknown method or reference, a method named twice,
/// or settings a method refuses.
VerifyReport verify(const rom::ReducedModel& model, const std::vector<fom::Param>& params,
                    const VerifyOptions& options = {});

/// \brief Writes the report as CSV (atomically): one row per reference solve, then
/// one per method and parameter; columns method, the parameters, primal_error,
/// dual_error, errors (relative or absolute), active_set_differences, the four KKT residuals,
/// reduced_penetration, tau, converged, status, iterations, sparsity, time_s.
void write_verify_csv(const std::string& path, const fom::Problem& problem, const VerifyReport& report);

/// \brief Evenly spaced subset of `n` parameters (first and last kept); all of
/// them when n ≤ 0 or n ≥ their number.
std::vector<fom::Param> subsample(const std::vector<fom::Param>& params, int n);

}  // namespace contactrom::baselines
