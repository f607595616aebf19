#include "rom/online_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include "core/atomic_file.hpp"
#include "core/format.hpp"

namespace contactrom::rom {

std::vector<fom::FomSolution> compute_references(const fom::ActiveSetSolver& solver,
                                                 const std::vector<fom::Param>& params, int threads,
                                                 const ProgressCallback& progress) {
  std::vector<fom::FomSolution> out(params.size());
  parallel_for(
      static_cast<int>(params.size()), threads, [&](int i) { out[i] = solver.solve(params[i]); }, progress);
  return out;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

EvaluationSummary evaluate_online(const OnlineSolver& solver, const std::vector<fom::Param>& params,
                                  const std::vector<fom::FomSolution>& references, const EvaluationOptions& options) {
  if (references.size() != params.size())
    throw std::invalid_argument("evaluate_online: one reference solution per parameter expected");
  const ReducedModel& model = solver.model();
  const fom::Problem& problem = model.problem();
  EvaluationSummary s;
  s.method = solver.name();
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
    for (int c : res.selected) row.selected.push_back(model.dictionary_snapshots()[c]);
    row.fom_status = ref.status;
    row.fom_time_s = ref.time_s;
    if (options.kkt) {
      row.kkt = fom::kkt_residuals(problem, params[i], res.u, res.lambda);
      s.max_kkt = std::max(s.max_kkt, row.kkt.max());
    }
    if (row.absolute_errors) {
      ++s.absolute_error_rows;
    } else {
      s.mean_primal_error += row.primal_error;
      s.max_primal_error = std::max(s.max_primal_error, row.primal_error);
      s.mean_dual_error += row.dual_error;
      s.max_dual_error = std::max(s.max_dual_error, row.dual_error);
    }
    s.mean_sparsity += row.sparsity;
    s.max_sparsity = std::max(s.max_sparsity, row.sparsity);
    s.mean_iterations += row.iterations;
    s.mean_time_s += row.time_s;
    if (!res.converged || res.status != Status::Success) ++s.nonconverged;
    if (ref.status != Status::Success) ++s.fom_failures;
    times.push_back(row.time_s);
    s.rows.push_back(std::move(row));
  }
  const double n = std::max<double>(1.0, static_cast<double>(params.size()));
  const double n_relative = std::max<double>(1.0, static_cast<double>(params.size() - s.absolute_error_rows));
  s.mean_primal_error /= n_relative;
  s.mean_dual_error /= n_relative;
  s.mean_sparsity /= n;
  s.mean_iterations /= n;
  s.mean_time_s /= n;
  s.median_time_s = median(times);
  return s;
}

void write_evaluation_csv(const std::string& path, const fom::Problem& problem, const EvaluationSummary& summary) {
  write_file_atomically(path, [&](std::ostream& out) {
    for (const std::string& name : problem.param_names()) out << name << ',';
    out << "primal_h1_error,dual_l2_error,sparsity,iterations,time_s,converged,status,selected,errors\n";
    for (const EvaluationRow& row : summary.rows) {
      for (int k = 0; k < row.mu.size(); ++k) out << format_number(row.mu(k)) << ',';
      out << format_number(row.primal_error) << ',' << format_number(row.dual_error) << ',' << row.sparsity << ','
          << row.iterations << ',' << format_number(row.time_s) << ',' << (row.converged ? 1 : 0) << ','
          << to_string(row.status) << ',';
      for (size_t j = 0; j < row.selected.size(); ++j) out << (j ? " " : "") << row.selected[j];
      out << ',' << (row.absolute_errors ? "absolute" : "relative") << '\n';
    }
  });
}

OnlineTiming OnlineSamples::timing() const {
  OnlineTiming t;
  t.median_core_s = median(core);
  t.median_total_s = median(total);
  if (!core.empty() && without.size() == core.size()) t.median_without_operators_s = median(without);
  t.queries = static_cast<int>(core.size());
  return t;
}

void time_online_pass(const OnlineSolver& solver, const std::vector<fom::Param>& params, OnlineSamples& out) {
  for (const fom::Param& mu : params) {
    const auto t0 = std::chrono::steady_clock::now();
    const OnlineResult res = solver.solve(mu);
    out.total.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    out.core.push_back(res.time_s);
    if (res.operator_time_s >= 0.0) out.without.push_back(res.time_s - res.operator_time_s);
  }
}

void time_fom_pass(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, std::vector<double>& out) {
  for (const fom::Param& mu : params) {
    const auto t0 = std::chrono::steady_clock::now();
    (void)solver.solve(mu);
    out.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
}

OnlineTiming time_online(const OnlineSolver& solver, const std::vector<fom::Param>& params, int repeats) {
  if (params.empty()) return OnlineTiming{};
  for (const fom::Param& mu : params) (void)solver.solve(mu);  // warm-up (caches, allocator)
  OnlineSamples samples;
  for (int rep = 0; rep < std::max(repeats, 1); ++rep) time_online_pass(solver, params, samples);
  return samples.timing();
}

InterleavedTiming time_interleaved(const fom::ActiveSetSolver& fom, const std::vector<const OnlineSolver*>& solvers,
                                   const std::vector<fom::Param>& params, int rounds,
                                   const std::vector<const OnlineSolver*>& clocked) {
  InterleavedTiming t;
  t.online.resize(solvers.size());
  if (params.empty()) return t;
  // Each solver followed by its clocked twin, each timed as its own entry.
  std::vector<const OnlineSolver*> all;
  std::vector<size_t> own(solvers.size()), twin(solvers.size(), 0);
  for (size_t i = 0; i < solvers.size(); ++i) {
    own[i] = all.size();
    all.push_back(solvers[i]);
    if (i < clocked.size() && clocked[i]) twin[i] = all.size(), all.push_back(clocked[i]);
  }
  (void)fom.solve(params.front());  // warm-up (caches, allocator)
  for (const OnlineSolver* s : all)
    for (const fom::Param& mu : params) (void)s->solve(mu);
  std::vector<double> fom_samples;
  std::vector<OnlineSamples> samples(all.size());
  for (int round = 0; round < std::max(rounds, 1); ++round) {
    std::vector<double> this_round;
    time_fom_pass(fom, params, this_round);
    t.fom_round_median_s.push_back(median(this_round));
    fom_samples.insert(fom_samples.end(), this_round.begin(), this_round.end());
    for (size_t i = 0; i < all.size(); ++i) time_online_pass(*all[i], params, samples[i]);
  }
  t.fom_median_s = median(fom_samples);
  for (size_t i = 0; i < solvers.size(); ++i) {
    t.online[i] = samples[own[i]].timing();
    if (twin[i] > 0) t.online[i].median_without_operators_s = samples[twin[i]].timing().median_without_operators_s;
  }
  return t;
}

double time_fom(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, int repeats) {
  if (params.empty()) return 0.0;
  (void)solver.solve(params.front());  // warm-up
  std::vector<double> times;
  for (int rep = 0; rep < std::max(repeats, 1); ++rep) time_fom_pass(solver, params, times);
  return median(times);
}

}  // namespace contactrom::rom
