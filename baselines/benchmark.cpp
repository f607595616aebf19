#include <contactrom/baselines/benchmark.hpp>

#include <algorithm>
#include <chrono>
#include <memory>

#include <contactrom/baselines/ipopt_qp.hpp>
#include <contactrom/baselines/online_methods.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/rom/error_indicator.hpp>

namespace contactrom::baselines {
namespace {

std::vector<fom::Param> thin(const std::vector<fom::Param>& all, int n) {
  if (n <= 0 || static_cast<int>(all.size()) <= n) return all;
  std::vector<fom::Param> out;
  for (int i = 0; i < n; ++i) out.push_back(all[(static_cast<size_t>(i) * (all.size() - 1)) / std::max(n - 1, 1)]);
  return out;
}

std::string key_of(const std::string& method) {
  std::string k = "rom_" + method;
  std::replace(k.begin(), k.end(), '-', '_');
  return k;
}

double time_ipopt(const fom::Problem& problem, const std::vector<fom::Param>& params) {
  const IpoptQpSolver ipopt(problem);
  std::vector<double> times;
  for (const fom::Param& mu : params) {
    const auto t0 = std::chrono::steady_clock::now();
    (void)ipopt.solve(mu);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return rom::median(times);
}

/// The FOM's limit: each query again at its own final pairing (solve_at), in rounds
/// that alternate a FOM query and a limit query, so that both meet the same load.
void time_fom_limit(const fom::ActiveSetSolver& solver, const std::vector<fom::Param>& params, int repeats,
                    BenchReport& r) {
  const fom::ContactModel& contact = solver.problem().contact();
  std::vector<fom::FomSolution> solutions;
  double iterations = 0.0, zone = 0.0;
  for (const fom::Param& mu : params) {
    solutions.push_back(solver.solve(mu));
    iterations += solutions.back().pairing_iterations;
    zone += solutions.back().zone_iterations;
    if (solver.solve_at(mu, solutions.back().pairing, contact.restrict_to_surface(solutions.back().u)).status ==
        Status::InvalidInput)
      return;
  }
  r.fom_pairing_iterations = params.empty() ? 0.0 : iterations / static_cast<double>(params.size());
  r.fom_zone_iterations = params.empty() ? 0.0 : zone / static_cast<double>(params.size());
  std::vector<double> limit, fom;
  const auto clock = [](auto&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  for (int round = 0; round < repeats; ++round)
    for (size_t i = 0; i < params.size(); ++i) {
      const fom::FomSolution& s = solutions[i];
      const Eigen::VectorXd x_s = contact.restrict_to_surface(s.u);
      fom.push_back(clock([&] { (void)solver.solve(params[i]); }));
      limit.push_back(clock([&] { (void)solver.solve_at(params[i], s.pairing, x_s); }));
    }
  r.fom_limit_s = rom::median(limit);
  r.ratios["fom_active_set/fom_limit"] = rom::median(fom) / r.fom_limit_s;
}

void add_ratios(BenchReport& r) {
  std::map<std::string, double> t;
  for (const BenchMethod& m : r.methods) {
    t[m.variant.key] = m.timing.median_core_s;
    if (m.timing.median_without_operators_s >= 0.0)
      t[m.variant.key + "_without_operators"] = m.timing.median_without_operators_s;
  }
  if (r.ipopt_queries > 0) r.ratios["fom_ipopt/fom_active_set"] = r.fom_ipopt_s / r.fom_active_set_s;
  const std::string empty = "_init_empty";
  for (const BenchMethod& m : r.methods) {
    const std::string& k = m.variant.key;
    r.ratios["fom_active_set/" + k] = r.fom_active_set_s / t[k];
    if (k.rfind("rom_greedy_with_estimate", 0) == 0) {  // the cost of the error estimate
      if (t.count("rom_greedy")) r.ratios[k + "/rom_greedy"] = t[k] / t["rom_greedy"];
      continue;
    }
    if (k.rfind("rom_greedy", 0) == 0) {
      // The paper's starting point against the default one.
      if (k.size() > empty.size() && k.compare(k.size() - empty.size(), std::string::npos, empty) == 0) {
        const std::string warm = k.substr(0, k.size() - empty.size());
        if (t.count(warm)) r.ratios[k + "/" + warm] = t[k] / t[warm];
      }
      if (k == "rom_greedy_nested" && t.count("rom_greedy")) r.ratios[k + "/rom_greedy"] = t[k] / t["rom_greedy"];
      continue;
    }
    // The baselines against both greedy schedules, with and without the construction
    // of the contact operators (the paper's timing convention).
    for (const std::string greedy : {"rom_greedy", "rom_greedy_nested"}) {
      if (t.count(greedy)) r.ratios[k + "/" + greedy] = t[k] / t[greedy];
      const std::string kw = k + "_without_operators", gw = greedy + "_without_operators";
      if (t.count(kw) && t.count(gw)) r.ratios[kw + "/" + gw] = t[kw] / t[gw];
    }
  }
}

}  // namespace

std::vector<BenchVariant> default_bench_variants() {
  std::vector<BenchVariant> v;
  for (const rom::OnlineMethod& m : builtin_online_methods()) v.push_back({key_of(m.name), m.name, {}});
  for (const char* method : {"greedy", "greedy-nested"}) v.push_back({key_of(method) + "_init_empty", method, {{"init", "empty"}}});
  v.push_back({"rom_cpg_warm", "cpg", {{"init", "cell"}}});
  v.push_back({"rom_greedy_with_estimate", "greedy", {{"estimate", "true"}}});
  v.push_back({"rom_greedy_with_estimate_1", "greedy", {{"estimate", "true"}, {"estimate_pairings", "1"}}});
  return v;
}

BenchReport benchmark(const rom::ReducedModel& model, const std::vector<fom::Param>& all_params,
                      const BenchOptions& options) {
  if (options.repeats < 1) throw InputError("bench repeats " + std::to_string(options.repeats) + " invalid; expected >= 1");
  const fom::Problem& problem = model.problem();
  const std::vector<fom::Param> params = thin(all_params, options.queries);
  BenchReport r;
  r.queries = static_cast<int>(params.size());
  const std::vector<fom::Param> ipopt_params = thin(params, options.ipopt_queries);
  if (options.ipopt_queries > 0 && !ipopt_params.empty()) {
    r.fom_ipopt_s = time_ipopt(problem, ipopt_params);
    r.ipopt_queries = static_cast<int>(ipopt_params.size());
  }
  // Every variant twice: as is, and clocking the construction of the contact
  // operators (a separate solver, so that the clock reads do not touch the main times).
  std::vector<std::unique_ptr<rom::OnlineSolver>> owned;
  std::vector<const rom::OnlineSolver*> solvers, clocked;
  for (const BenchVariant& v : options.variants) {
    rom::OnlineSolverOptions o = rom::options_from_map(v.method, v.options);
    // The reduced answer is timed alone (the error estimate is a separate variant).
    if (!v.options.count("estimate")) o.estimate = false;
    if (const std::string why = rom::no_error_estimate_reason(problem); o.estimate && !why.empty()) {
      r.not_applicable[v.key] = "no error estimate: " + why;
      continue;
    }
    try {
      owned.push_back(rom::make_online_solver(v.method, model, o));
    } catch (const InputError& e) {
      r.not_applicable[v.key] = e.what();
      continue;
    }
    solvers.push_back(owned.back().get());
    o.time_operators = true;
    owned.push_back(rom::make_online_solver(v.method, model, o));
    clocked.push_back(owned.back().get());
    r.methods.push_back({v, {}});
  }
  const fom::ActiveSetSolver fom_solver(problem);
  const rom::InterleavedTiming timing = rom::time_interleaved(fom_solver, solvers, params, options.repeats, clocked);
  r.fom_active_set_s = timing.fom_median_s;
  r.fom_active_set_rounds = timing.fom_round_median_s;
  time_fom_limit(fom_solver, params, options.repeats, r);
  for (size_t i = 0; i < r.methods.size(); ++i) r.methods[i].timing = timing.online[i];
  add_ratios(r);
  return r;
}

}  // namespace contactrom::baselines
