#include <contactrom/rom/online_evaluation.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/rom/online_timing.hpp>

namespace contactrom::rom {

void ErrorStatistics::add_errors(const fom::ReferenceErrors& errors) {
  if (errors.absolute) {
    ++absolute_error_rows;
    max_absolute_primal_error = std::max(max_absolute_primal_error, errors.primal);
    max_absolute_dual_error = std::max(max_absolute_dual_error, errors.dual);
    return;
  }
  ++m_relative_rows;
  m_sum_primal += errors.primal;
  m_sum_dual += errors.dual;
  mean_primal_error = m_sum_primal / m_relative_rows;
  mean_dual_error = m_sum_dual / m_relative_rows;
  max_primal_error = std::max(max_primal_error, errors.primal);
  max_dual_error = std::max(max_dual_error, errors.dual);
}

void append_error_values(SummaryValues& values, const ErrorStatistics& e) {
  values.insert(values.end(), {{"mean_primal_error", e.mean_primal_error},
                               {"max_primal_error", e.max_primal_error},
                               {"mean_dual_error", e.mean_dual_error},
                               {"max_dual_error", e.max_dual_error},
                               {"absolute_error_rows", static_cast<long long>(e.absolute_error_rows)},
                               {"max_absolute_primal_error", e.max_absolute_primal_error},
                               {"max_absolute_dual_error", e.max_absolute_dual_error}});
}

SummaryValues summary_values(const EvaluationSummary& s) {
  SummaryValues v{{"problem", s.problem},
                  {"method", s.method},
                  {"delta", s.delta},
                  {"dictionary_size", static_cast<long long>(s.dictionary_size)},
                  {"dual_basis_size", static_cast<long long>(s.dual_basis_size)},
                  {"primal_rank", static_cast<long long>(s.primal_rank)},
                  {"validation_size", static_cast<long long>(s.rows.size())}};
  append_error_values(v, s);
  v.insert(v.end(), {{"mean_sparsity", s.mean_sparsity},
                     {"max_sparsity", static_cast<long long>(s.max_sparsity)},
                     {"mean_iterations", s.mean_iterations},
                     {"mean_time_s", s.mean_time_s},
                     {"median_time_s", s.median_time_s},
                     {"nonconverged", static_cast<long long>(s.nonconverged)},
                     {"inaccurate", static_cast<long long>(s.inaccurate)},
                     {"fom_failures", static_cast<long long>(s.fom_failures)}});
  if (s.kkt) v.emplace_back("max_kkt", s.max_kkt);
  const EstimateQuality& q = s.estimates;
  v.insert(v.end(), {{"estimated_rows", static_cast<long long>(q.rows)},
                     {"primal_estimate_correlation", q.primal_correlation},
                     {"dual_estimate_correlation", q.dual_correlation},
                     {"primal_underestimated", static_cast<long long>(q.primal_underestimated)},
                     {"dual_underestimated", static_cast<long long>(q.dual_underestimated)},
                     {"min_primal_effectivity", q.min_primal_effectivity},
                     {"max_primal_effectivity", q.max_primal_effectivity},
                     {"min_dual_effectivity", q.min_dual_effectivity},
                     {"max_dual_effectivity", q.max_dual_effectivity},
                     {"mean_estimate_time_s", s.mean_estimate_time_s}});
  return v;
}

double rank_correlation(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  if (n < 3 || y.size() != n) return std::numeric_limits<double>::quiet_NaN();
  const auto ranks = [n](const std::vector<double>& v) {
    std::vector<size_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&v](size_t a, size_t b) { return v[a] < v[b]; });
    Eigen::VectorXd r(static_cast<Eigen::Index>(n));
    for (size_t i = 0; i < n;) {
      size_t j = i;
      while (j + 1 < n && v[order[j + 1]] == v[order[i]]) ++j;
      for (size_t k = i; k <= j; ++k) r(static_cast<Eigen::Index>(order[k])) = 0.5 * static_cast<double>(i + j);
      i = j + 1;
    }
    return Eigen::VectorXd(r.array() - r.mean());
  };
  const Eigen::VectorXd rx = ranks(x), ry = ranks(y);
  const double den = rx.norm() * ry.norm();
  return den > 0.0 ? rx.dot(ry) / den : std::numeric_limits<double>::quiet_NaN();
}

EstimateQuality estimate_quality(const std::vector<EvaluationRow>& rows) {
  EstimateQuality q;
  std::vector<double> ep, ed, xp, xd;
  const auto effectivity = [](double estimate, double error, double& lo, double& hi) {
    if (!(error > 1e-12)) return;
    const double ratio = estimate / error;
    if (!(ratio >= lo)) lo = std::isnan(lo) ? ratio : std::min(lo, ratio);
    if (!(ratio <= hi)) hi = std::isnan(hi) ? ratio : std::max(hi, ratio);
  };
  for (const EvaluationRow& row : rows) {
    if (row.fom_status != Status::Success || row.absolute_errors || row.absolute_estimates ||
        !std::isfinite(row.primal_estimate) ||
        !std::isfinite(row.dual_estimate) || !std::isfinite(row.primal_error) || !std::isfinite(row.dual_error))
      continue;
    ++q.rows;
    ep.push_back(row.primal_error), xp.push_back(row.primal_estimate);
    ed.push_back(row.dual_error), xd.push_back(row.dual_estimate);
    if (row.primal_error > row.primal_estimate) ++q.primal_underestimated;
    if (row.dual_error > row.dual_estimate) ++q.dual_underestimated;
    effectivity(row.primal_estimate, row.primal_error, q.min_primal_effectivity, q.max_primal_effectivity);
    effectivity(row.dual_estimate, row.dual_error, q.min_dual_effectivity, q.max_dual_effectivity);
  }
  q.primal_correlation = rank_correlation(xp, ep);
  q.dual_correlation = rank_correlation(xd, ed);
  return q;
}

std::vector<fom::FomSolution> compute_references(const fom::ActiveSetSolver& solver,
                                                 const std::vector<fom::Param>& params, int threads,
                                                 const ProgressCallback& progress) {
  std::vector<fom::FomSolution> out(params.size());
  fom::solve_in_chains(
      solver, params, fom::kDefaultChain, threads, [&](int i, fom::FomSolution&& sol) { out[i] = std::move(sol); },
      progress);
  return out;
}

std::string references_warning(const fom::Problem& problem, const std::vector<fom::Param>& params,
                               const std::vector<fom::FomSolution>& references) {
  std::vector<std::vector<std::string>> warnings;
  for (const fom::FomSolution& ref : references) warnings.push_back(fom::solution_warnings(problem, ref.u));
  const std::string line = fom::solutions_warning(problem, params, warnings, "FOM references");
  return line.empty() ? line : line + " (the errors measured against those mean little)";
}

EvaluationSummary evaluate_online(const OnlineSolver& solver, const std::vector<fom::Param>& params,
                                  const std::vector<fom::FomSolution>& references, const EvaluationOptions& options) {
  if (references.size() != params.size())
    throw std::invalid_argument("evaluate_online: one reference solution per parameter expected");
  const ReducedModel& model = solver.model();
  const fom::Problem& problem = model.problem();
  EvaluationSummary s;
  s.problem = problem.name();
  s.method = solver.name();
  s.kkt = options.kkt;
  s.delta = model.delta();
  s.dictionary_size = model.dictionary_size();
  s.dual_basis_size = solver.dual_basis_size();
  s.primal_rank = model.primal_rank();
  std::vector<double> times;
  for (size_t i = 0; i < params.size(); ++i) {
    const OnlineResult res = solver.solve(params[i]);
    const fom::FomSolution& ref = references[i];
    EvaluationRow row;
    row.mu = params[i];
    const fom::ReferenceErrors errors = fom::reference_errors(problem, res.u, res.lambda, ref.u, ref.lambda);
    row.primal_error = errors.primal;
    row.dual_error = errors.dual;
    row.absolute_errors = errors.absolute;
    row.sparsity = static_cast<int>(res.selected.size());
    row.iterations = res.iterations;
    row.time_s = res.time_s;
    row.converged = res.converged;
    row.status = res.status;
    row.contact = res.contact;
    row.primal_estimate = res.primal_estimate;
    row.dual_estimate = res.dual_estimate;
    row.absolute_estimates = res.absolute_estimates;
    s.mean_estimate_time_s += res.estimate_time_s;
    for (int c : res.selected) row.selected.push_back(model.dictionary_snapshots()[c]);
    row.fom_status = ref.status;
    row.fom_time_s = ref.time_s;
    if (options.kkt) {
      row.kkt = fom::kkt_residuals(problem, params[i], res.u, res.lambda);
      s.max_kkt = std::max(s.max_kkt, row.kkt.max());
    }
    // An error against a reference that did not converge measures nothing: the row
    // keeps it (flagged by its reference_status), the statistics leave it out.
    if (ref.status == Status::Success) s.add_errors(errors);
    s.mean_sparsity += row.sparsity;
    s.max_sparsity = std::max(s.max_sparsity, row.sparsity);
    s.mean_iterations += row.iterations;
    s.mean_time_s += row.time_s;
    if (res.status == Status::Inaccurate)
      ++s.inaccurate;
    else if (!res.converged || res.status != Status::Success)
      ++s.nonconverged;
    if (ref.status != Status::Success) ++s.fom_failures;
    times.push_back(row.time_s);
    s.rows.push_back(std::move(row));
    if (options.progress) options.progress(static_cast<int>(i) + 1, static_cast<int>(params.size()));
  }
  const double n = std::max<double>(1.0, static_cast<double>(params.size()));
  s.mean_sparsity /= n;
  s.mean_iterations /= n;
  s.mean_time_s /= n;
  s.mean_estimate_time_s /= n;
  s.median_time_s = median(times);
  s.estimates = estimate_quality(s.rows);
  return s;
}

void write_evaluation_csv(const std::string& path, const fom::Problem& problem, const EvaluationSummary& summary) {
  write_file_atomically(path, [&](std::ostream& out) {
    for (const std::string& name : problem.param_names()) out << name << ',';
    out << "primal_error,dual_error,sparsity,iterations,time_s,converged,status,selected,errors,penetration,"
           "separation,primal_estimate,dual_estimate,reference_status\n";
    for (const EvaluationRow& row : summary.rows) {
      for (int k = 0; k < row.mu.size(); ++k) out << format_number(row.mu(k)) << ',';
      out << format_number(row.primal_error) << ',' << format_number(row.dual_error) << ',' << row.sparsity << ','
          << row.iterations << ',' << format_number(row.time_s) << ',' << (row.converged ? 1 : 0) << ','
          << to_string(row.status) << ',';
      for (size_t j = 0; j < row.selected.size(); ++j) out << (j ? " " : "") << row.selected[j];
      out << ',' << (row.absolute_errors ? "absolute" : "relative") << ',' << format_number(row.contact.penetration)
          << ',' << format_number(row.contact.complementarity) << ',' << format_number(row.primal_estimate) << ','
          << format_number(row.dual_estimate) << ',' << to_string(row.fom_status) << '\n';
    }
  });
}

}  // namespace contactrom::rom
