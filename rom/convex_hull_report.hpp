#pragma once
/// \file convex_hull_report.hpp
/// \brief Reports of the convex-hull approach over a snapshot database: the
/// leave-one-out CHLS test of its primal snapshots, and the convex-hull ROM's
/// errors, sparsity and KKT compliance at a parameter set against the FOM. What
/// `contactrom chls` and `contactrom hull-report` compute, as library calls.
///
/// \code
///   const contactrom::rom::DatabaseChls c = contactrom::rom::chls_of_database(db);     // c.result.max_error
///   contactrom::rom::ConvexHullSolver solver(model);
///   const auto report = contactrom::rom::convex_hull_report(solver, params);          // report.max_dual_error
/// \endcode
#include <string>
#include <vector>

#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/chls.hpp>
#include <contactrom/rom/convex_hull.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::rom {

/// \brief CHLS of the successful primal snapshots of a database.
struct DatabaseChls {
  std::vector<int> snapshots;  ///< database indices of the snapshots tested, in order
  ChlsResult result;           ///< one column per snapshot of `snapshots`
  /// Database indices of the snapshots with a positive coefficient in the
  /// approximation of snapshot `k` (a position in `snapshots`).
  std::vector<int> support(std::size_t k) const;
};

/// \brief Leave-one-out CHLS (chls_leave_one_out) of the successful primal snapshots.
/// \throws InputError if fewer than 2 snapshots succeeded.
DatabaseChls chls_of_database(const SnapshotDatabase& db, const ChlsOptions& options = {});

/// \brief Writes a DatabaseChls as CSV (atomically): parameter columns, chls_error,
/// status, iterations, support (space-separated database indices).
void write_chls_csv(const std::string& path, const SnapshotDatabase& db, const DatabaseChls& chls);

/// \brief One query of convex_hull_report().
struct HullReportRow {
  fom::Param mu;                     ///< parameter
  ConvexHullResult result;           ///< the solve and its statistics
  double primal_error = 0.0;         ///< relative H¹ error against the FOM (absolute if `absolute_errors`)
  double dual_error = 0.0;           ///< relative L²(Γc) error against the FOM (absolute if `absolute_errors`)
  bool absolute_errors = false;      ///< the FOM displacement is near zero (fom::reference_errors)
  fom::KktResiduals kkt;             ///< relative FOM KKT residuals of the ROM solution
  double penetration_abs = 0.0;      ///< largest penetration (length)
  double complementarity_abs = 0.0;  ///< \f$ |\sum_s w_s \lambda_s\, gap_s| \f$ (force × length)
};

/// \brief Settings of convex_hull_report() (documented defaults).
struct HullReportOptions {
  int threads = 0;     ///< threads of the FOM references; ≤ 0: hardware concurrency. Default 0.
  bool time = false;   ///< also time the online solve (time_online). Default false.
  int repeats = 3;     ///< timing passes with `time`. Default 3.
};

/// \brief The rows and their means and maxima (errors by the rule of ErrorStatistics).
struct HullReport : ErrorStatistics {
  std::vector<HullReportRow> rows;  ///< one per parameter, in order
  double mean_sparsity = 0.0, max_sparsity = 0.0;          ///< |support of α|
  double max_sum_violation = 0.0;        ///< max \f$ |\mathbf 1^T\alpha - 1| \f$
  double max_penetration = 0.0, max_penetration_abs = 0.0;            ///< relative and absolute
  double max_complementarity = 0.0, max_complementarity_abs = 0.0;    ///< relative and absolute
  double max_stationarity = 0.0;         ///< max relative stationarity residual
  double max_projected_residual = 0.0;   ///< max ConvexHullResult::projected_residual
  double mean_iterations = 0.0, mean_pairing_iterations = 0.0;  ///< means over the rows
  int nonconverged = 0;                  ///< rows not converged
  OnlineTiming timing;                   ///< HullReportOptions::time only
};

/// \brief Solves `solver` at every parameter and compares with the FOM.
HullReport convex_hull_report(const ConvexHullSolver& solver, const std::vector<fom::Param>& params,
                              const HullReportOptions& options = {});

/// \brief The summary of `hull-report --json`: queries, the error entries of
/// append_error_values, mean_sparsity, max_sparsity, max_sum_violation,
/// max_penetration, max_penetration_abs, max_complementarity,
/// max_complementarity_abs, max_stationarity, max_projected_residual,
/// mean_iterations, mean_pairing_iterations, nonconverged, and with timing
/// median_time_s, median_total_time_s, timed_queries.
SummaryValues summary_values(const HullReport& report);

/// \brief The summary of `chls --json`: snapshots, max_chls_error, mean_chls_error,
/// nonconverged, time_s.
SummaryValues summary_values(const DatabaseChls& chls);

/// \brief Writes the rows as CSV (atomically): parameter columns, errors, sparsity,
/// compliance, iterations, status, time, selected snapshots and coefficients.
void write_hull_report_csv(const std::string& path, const ConvexHullSolver& solver, const HullReport& report);

}  // namespace contactrom::rom
