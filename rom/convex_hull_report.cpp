#include <contactrom/rom/convex_hull_report.hpp>

#include <algorithm>
#include <cmath>
#include <ostream>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/parameter_space.hpp>
#include <contactrom/rom/offline.hpp>

namespace contactrom::rom {
namespace {

HullReportRow report_row(const ConvexHullSolver& solver, const fom::Param& mu, const fom::FomSolution& ref) {
  const fom::Problem& problem = solver.model().problem();
  HullReportRow row;
  row.mu = mu;
  row.result = solver.solve_detailed(mu);
  const OnlineResult& on = row.result.online;
  const fom::ReferenceErrors errors = fom::reference_errors(problem, on.u, on.lambda, ref.u, ref.lambda);
  row.primal_error = errors.primal;
  row.dual_error = errors.dual;
  row.absolute_errors = errors.absolute;
  row.kkt = fom::kkt_residuals(problem, mu, on.u, on.lambda);
  // Absolute compliance: largest penetration (length) and |λᵀ(Cu − g)| = |Σ w_s λ_s gap_s|.
  const Eigen::VectorXd& w = problem.contact().weights();
  const Eigen::VectorXd gaps = fom::normal_gaps(problem, on.u);
  double comp = 0.0;
  for (Eigen::Index s = 0; s < gaps.size(); ++s) {
    if (!std::isfinite(gaps(s))) continue;
    row.penetration_abs = std::max(row.penetration_abs, -gaps(s));
    comp += w(s) * on.lambda(s) * gaps(s);
  }
  row.complementarity_abs = std::abs(comp);
  return row;
}

void summarize(HullReport& r) {
  const double n = std::max<double>(1.0, static_cast<double>(r.rows.size()));
  for (const HullReportRow& row : r.rows) {
    const OnlineResult& on = row.result.online;
    const double sparsity = static_cast<double>(on.selected.size());
    r.add_errors({row.primal_error, row.dual_error, row.absolute_errors});
    r.mean_sparsity += sparsity / n;
    r.max_sparsity = std::max(r.max_sparsity, sparsity);
    r.max_sum_violation = std::max(r.max_sum_violation, row.result.sum_violation);
    r.max_penetration = std::max(r.max_penetration, row.kkt.penetration);
    r.max_penetration_abs = std::max(r.max_penetration_abs, row.penetration_abs);
    r.max_complementarity = std::max(r.max_complementarity, row.kkt.complementarity);
    r.max_complementarity_abs = std::max(r.max_complementarity_abs, row.complementarity_abs);
    r.max_stationarity = std::max(r.max_stationarity, row.kkt.stationarity);
    r.max_projected_residual = std::max(r.max_projected_residual, row.result.projected_residual);
    r.mean_iterations += on.iterations / n;
    r.mean_pairing_iterations += row.result.pairing_iterations / n;
    if (!on.converged) ++r.nonconverged;
  }
}

}  // namespace

std::vector<int> DatabaseChls::support(std::size_t k) const {
  std::vector<int> out;
  for (std::size_t j = 0; j < snapshots.size(); ++j)
    if (result.coefficients(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(k)) > 0.0)
      out.push_back(snapshots[j]);
  return out;
}

DatabaseChls chls_of_database(const SnapshotDatabase& db, const ChlsOptions& options) {
  DatabaseChls c;
  c.snapshots = db.successful_snapshots();
  if (c.snapshots.size() < 2)
    throw InputError("database holds " + std::to_string(c.snapshots.size()) +
                     " successful snapshots; CHLS needs at least 2");
  Eigen::MatrixXd primal(db.num_dofs(), static_cast<Eigen::Index>(c.snapshots.size()));
  for (std::size_t k = 0; k < c.snapshots.size(); ++k)
    primal.col(static_cast<Eigen::Index>(k)) = db.primal.col(c.snapshots[k]);
  c.result = chls_leave_one_out(primal, options);
  return c;
}

void write_chls_csv(const std::string& path, const SnapshotDatabase& db, const DatabaseChls& c) {
  write_file_atomically(path, [&](std::ostream& out) {
    for (const std::string& name : db.problem.param_names) out << name << ',';
    out << "chls_error,status,iterations,support\n";
    for (std::size_t k = 0; k < c.snapshots.size(); ++k) {
      const fom::Param mu = db.parameter(c.snapshots[k]);
      for (Eigen::Index i = 0; i < mu.size(); ++i) out << format_number(mu(i)) << ',';
      out << format_number(c.result.errors(static_cast<Eigen::Index>(k))) << ',' << to_string(c.result.status[k])
          << ',' << c.result.iterations[k] << ',';
      const std::vector<int> support = c.support(k);
      for (std::size_t j = 0; j < support.size(); ++j) out << (j ? " " : "") << support[j];
      out << '\n';
    }
  });
}

HullReport convex_hull_report(const ConvexHullSolver& solver, const std::vector<fom::Param>& params,
                              const HullReportOptions& options) {
  const fom::ActiveSetSolver fom_solver(solver.model().problem());
  const std::vector<fom::FomSolution> refs = compute_references(fom_solver, params, options.threads);
  HullReport r;
  for (std::size_t i = 0; i < params.size(); ++i) r.rows.push_back(report_row(solver, params[i], refs[i]));
  summarize(r);
  if (options.time) r.timing = time_online(solver, params, options.repeats);
  return r;
}

SummaryValues summary_values(const HullReport& r) {
  SummaryValues v{{"queries", static_cast<long long>(r.rows.size())}};
  append_error_values(v, r);
  v.insert(v.end(), {{"mean_sparsity", r.mean_sparsity},
                     {"max_sparsity", static_cast<long long>(r.max_sparsity)},
                     {"max_sum_violation", r.max_sum_violation},
                     {"max_penetration", r.max_penetration},
                     {"max_penetration_abs", r.max_penetration_abs},
                     {"max_complementarity", r.max_complementarity},
                     {"max_complementarity_abs", r.max_complementarity_abs},
                     {"max_stationarity", r.max_stationarity},
                     {"max_projected_residual", r.max_projected_residual},
                     {"mean_iterations", r.mean_iterations},
                     {"mean_pairing_iterations", r.mean_pairing_iterations},
                     {"nonconverged", static_cast<long long>(r.nonconverged)}});
  if (r.timing.queries > 0)
    v.insert(v.end(), {{"median_time_s", r.timing.median_core_s},
                       {"median_total_time_s", r.timing.median_total_s},
                       {"timed_queries", static_cast<long long>(r.timing.queries)}});
  return v;
}

SummaryValues summary_values(const DatabaseChls& c) {
  const ChlsResult& r = c.result;
  const long long nonconverged =
      std::count_if(r.status.begin(), r.status.end(), [](Status s) { return s != Status::Success; });
  return {{"snapshots", static_cast<long long>(c.snapshots.size())},
          {"max_chls_error", r.max_error},
          {"mean_chls_error", r.mean_error},
          {"nonconverged", nonconverged},
          {"time_s", r.time_s}};
}

void write_hull_report_csv(const std::string& path, const ConvexHullSolver& solver, const HullReport& report) {
  const ReducedModel& model = solver.model();
  auto selected_text = [&](const OnlineResult& on, bool coefficients) {
    std::string s;
    for (std::size_t k = 0; k < on.selected.size(); ++k) {
      s += k ? " " : "";
      s += coefficients ? format_number(on.coefficients(static_cast<Eigen::Index>(k)))
                        : std::to_string(model.dictionary_snapshots()[static_cast<std::size_t>(on.selected[k])]);
    }
    return s;
  };
  write_file_atomically(path, [&](std::ostream& out) {
    for (const std::string& name : model.problem().param_names()) out << name << ',';
    out << "primal_error,dual_error,errors,sparsity,sum_violation,penetration,penetration_abs,complementarity,"
           "complementarity_abs,stationarity,negative_pressure,projected_residual,iterations,pairing_iterations,"
           "converged,status,time_s,selected,coefficients\n";
    for (const HullReportRow& row : report.rows) {
      const OnlineResult& on = row.result.online;
      for (Eigen::Index k = 0; k < row.mu.size(); ++k) out << format_number(row.mu(k)) << ',';
      out << format_number(row.primal_error) << ',' << format_number(row.dual_error) << ','
          << (row.absolute_errors ? "absolute" : "relative") << ',' << on.selected.size()
          << ',' << format_number(row.result.sum_violation) << ',' << format_number(row.kkt.penetration) << ','
          << format_number(row.penetration_abs) << ',' << format_number(row.kkt.complementarity) << ','
          << format_number(row.complementarity_abs) << ',' << format_number(row.kkt.stationarity) << ','
          << format_number(row.kkt.negative_pressure) << ',' << format_number(row.result.projected_residual) << ','
          << on.iterations << ',' << row.result.pairing_iterations << ',' << (on.converged ? 1 : 0) << ','
          << to_string(on.status) << ',' << format_number(on.time_s) << ',' << selected_text(on, false) << ','
          << selected_text(on, true) << '\n';
    }
  });
}

}  // namespace contactrom::rom
