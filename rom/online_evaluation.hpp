#pragma once
/// \file online_evaluation.hpp
/// \brief Evaluation of an online ROM method over a parameter set against the FOM:
/// reference solutions, per-query errors, sparsity, iterations and time, their
/// means and maxima, the CSV of the rows, and the summary's key/value list shared by
/// `online --json`, `chls --json` and the Python module.
///
/// Exact command line (see docs/rom.md):
/// \code
///   contactrom online --db hertz30.h5 --method greedy --delta 1e-8 --validation --out hertz30.csv --json
/// \endcode
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_solver.hpp>

namespace contactrom::rom {

/// \brief FOM reference solutions at `params` (one shared solver, in parallel on
/// `threads` threads, ≤ 0: hardware concurrency), in continuation chains of
/// fom::kDefaultChain as the offline stage (fom::solve_in_chains()): the FOM's answers
/// to its pairing tolerance, the same for any thread count.
std::vector<fom::FomSolution> compute_references(const fom::ActiveSetSolver& solver,
                                                 const std::vector<fom::Param>& params, int threads = 0,
                                                 const ProgressCallback& progress = {});

/// \brief The warning about `references` (compute_references() at `params`) whose
/// solutions turn elements inside out (fom::solution_warnings(): errors measured against
/// them mean little), as `online --validation` prints it; "" when none does.
std::string references_warning(const fom::Problem& problem, const std::vector<fom::Param>& params,
                               const std::vector<fom::FomSolution>& references);

/// \brief One evaluated query.
struct EvaluationRow {
  fom::Param mu;
  double primal_error = 0.0;   ///< relative H¹ error against the FOM (absolute if `absolute_errors`)
  double dual_error = 0.0;     ///< relative L²(Γc) error against the FOM (absolute if `absolute_errors`)
  /// The FOM displacement is near zero (fom::kNearZeroReference): the two errors are
  /// absolute, since relative ones would divide by round-off.
  bool absolute_errors = false;
  int sparsity = 0;            ///< |I|, number of selected dictionary columns
  int iterations = 0;
  double time_s = 0.0;         ///< online core time (OnlineResult::time_s)
  bool converged = false;
  Status status = Status::Success;
  fom::ContactResiduals contact;  ///< the answer's full-order contact residuals (OnlineResult::contact)
  /// The answer's error estimates (OnlineResult::primal_estimate, dual_estimate; NaN if none).
  double primal_estimate = std::numeric_limits<double>::quiet_NaN();
  double dual_estimate = std::numeric_limits<double>::quiet_NaN();
  bool absolute_estimates = false;  ///< OnlineResult::absolute_estimates
  std::vector<int> selected;   ///< selected columns as database snapshot indices
  Status fom_status = Status::Success;
  double fom_time_s = 0.0;     ///< FOM reference time (measured in parallel: indicative only)
  fom::KktResiduals kkt;       ///< FOM KKT residuals of the ROM solution (if requested)
};

/// \brief Settings of evaluate_online.
struct EvaluationOptions {
  bool kkt = false;  ///< compute the FOM KKT residuals of every ROM solution. Default false.
  ProgressCallback progress;  ///< called after every query (optional)
};

/// \brief Means and maxima of errors against the FOM, by the rule of
/// fom::reference_errors: relative errors are averaged; absolute ones (near-zero
/// FOM displacement, where a relative error would divide round-off by round-off)
/// are counted apart with their own maxima.
struct ErrorStatistics {
  /// Means and maxima of the relative errors (rows with absolute errors left out).
  double mean_primal_error = 0.0, max_primal_error = 0.0;
  double mean_dual_error = 0.0, max_dual_error = 0.0;
  int absolute_error_rows = 0;  ///< rows whose errors are absolute (near-zero FOM displacement)
  /// Maxima of the absolute errors of those rows (0 without such rows).
  double max_absolute_primal_error = 0.0, max_absolute_dual_error = 0.0;
  /// Adds the errors of one row.
  void add_errors(const fom::ReferenceErrors& errors);

 private:
  int m_relative_rows = 0;
  double m_sum_primal = 0.0, m_sum_dual = 0.0;
};

/// \brief How well the error estimates of a set of rows match the true errors, over
/// the rows whose errors and estimates are both relative and finite and whose FOM
/// reference succeeded.
struct EstimateQuality {
  int rows = 0;                    ///< rows compared
  /// Spearman rank correlation of estimate and true error (NaN below 3 rows).
  double primal_correlation = std::numeric_limits<double>::quiet_NaN();
  double dual_correlation = std::numeric_limits<double>::quiet_NaN();
  /// Rows whose true error exceeds its estimate.
  int primal_underestimated = 0, dual_underestimated = 0;
  /// Smallest and largest effectivity estimate / error (rows with an error above 1e-12).
  double min_primal_effectivity = std::numeric_limits<double>::quiet_NaN();
  double max_primal_effectivity = std::numeric_limits<double>::quiet_NaN();
  double min_dual_effectivity = std::numeric_limits<double>::quiet_NaN();
  double max_dual_effectivity = std::numeric_limits<double>::quiet_NaN();
};

/// \brief EstimateQuality of `rows`.
EstimateQuality estimate_quality(const std::vector<EvaluationRow>& rows);

/// \brief Spearman rank correlation of two samples of one length (average ranks for
/// ties); NaN for fewer than 3 values or a constant sample.
double rank_correlation(const std::vector<double>& x, const std::vector<double>& y);

/// \brief Means and maxima over the rows; summary_values() lists them.
struct EvaluationSummary : ErrorStatistics {
  std::string problem;      ///< name of the problem
  std::string method;
  double delta = 0.0;
  int dictionary_size = 0;
  int dual_basis_size = 0;  ///< OnlineSolver::dual_basis_size()
  int primal_rank = 0;
  std::vector<EvaluationRow> rows;
  double mean_sparsity = 0.0;
  int max_sparsity = 0;
  double mean_iterations = 0.0;
  double mean_time_s = 0.0, median_time_s = 0.0;
  int nonconverged = 0;   ///< ROM queries that hit the iteration cap or failed
  int inaccurate = 0;     ///< ROM queries that converged with contact residuals above tolerance (Status::Inaccurate)
  /// Reference FOM solves whose status != Success: their rows are left out of the
  /// error statistics (ErrorStatistics) and of the EstimateQuality.
  int fom_failures = 0;
  bool kkt = false;       ///< whether the rows' KKT residuals were computed (EvaluationOptions::kkt)
  double max_kkt = 0.0;   ///< largest KKT residual over the rows (if computed)
  EstimateQuality estimates;         ///< the error estimates against the true errors
  double mean_estimate_time_s = 0.0; ///< mean OnlineResult::estimate_time_s (part of mean_time_s)
};

/// \brief One value of a summary: a count, a real number or a word.
using SummaryValue = std::variant<long long, double, std::string>;

/// \brief Ordered (key, value) pairs of a summary: the keys of a command's `--json`
/// object and of the Python module's dictionaries (docs/rom.md, "JSON keys").
using SummaryValues = std::vector<std::pair<std::string, SummaryValue>>;

/// \brief The summary of `online --validation --json` and of the Python
/// `ReducedModel.evaluate`: problem, method, delta, dictionary_size,
/// dual_basis_size, primal_rank, validation_size, mean_primal_error,
/// max_primal_error, mean_dual_error, max_dual_error, absolute_error_rows,
/// max_absolute_primal_error, max_absolute_dual_error, mean_sparsity, max_sparsity,
/// mean_iterations, mean_time_s, median_time_s, nonconverged, inaccurate, fom_failures,
/// max_kkt when the KKT residuals were computed, and the EstimateQuality:
/// estimated_rows, primal_estimate_correlation, dual_estimate_correlation,
/// primal_underestimated, dual_underestimated, min/max_primal_effectivity,
/// min/max_dual_effectivity, mean_estimate_time_s.
SummaryValues summary_values(const EvaluationSummary& summary);

/// \brief Appends the error entries shared by every evaluation against the FOM
/// (mean_primal_error, max_primal_error, mean_dual_error, max_dual_error,
/// absolute_error_rows, max_absolute_primal_error, max_absolute_dual_error), so
/// that every command names them alike.
void append_error_values(SummaryValues& values, const ErrorStatistics& errors);

/// \brief Solves `solver` at every parameter (sequentially, so the timings are not
/// disturbed) and compares with the references (same order as `params`).
EvaluationSummary evaluate_online(const OnlineSolver& solver, const std::vector<fom::Param>& params,
                                  const std::vector<fom::FomSolution>& references,
                                  const EvaluationOptions& options = {});

/// \brief Writes the rows as CSV (atomically): one column per parameter (named
/// after it), then primal_error, dual_error, sparsity, iterations, time_s,
/// converged (0/1), status, selected (space-separated database snapshot indices),
/// errors ("relative", or "absolute" where the FOM displacement is near zero),
/// penetration and separation (the answer's contact residuals, units of U),
/// primal_estimate and dual_estimate (the answer's error estimates), reference_status
/// (the status of the FOM reference the errors were measured against).
void write_evaluation_csv(const std::string& path, const fom::Problem& problem, const EvaluationSummary& summary);

}  // namespace contactrom::rom
