#include <contactrom/rom/online_timing.hpp>

#include <algorithm>
#include <chrono>

namespace contactrom::rom {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
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
