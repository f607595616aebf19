// contactrom bench (--problem P [--train N | --level n] [--refine k] | --db DB.h5) [--delta D] [--repeats R] [--json]
// Median per-query times of every solver, all measured in the same run so that
// their ratios are meaningful on a noisy machine:
//   fom_active_set  custom active-set FOM, factorisation reused (built before timing)
//   fom_ipopt       Ipopt on the same QP (fewer queries: it is slow)
//   rom_<method>    every registered online method (greedy, cpg, full-dictionary,
//                   convex-hull where it applies) with its defaults, nonlinear contact
//                   operators included
//   rom_greedy_init_empty, rom_greedy_nested_init_empty  the greedy schedules started
//                   from the empty set (paper Alg. 1) instead of the default warm start
//   rom_cpg_warm    CPG started from its own solutions around the query (init=cell);
//                   rom_cpg is CPG as the paper ran it (cold)
//   rom_<method>_without_operators  the same, minus the construction of the contact
//                   operators (search, assembly, reduced rows): the paper's timing
//                   convention; from a second, clocked solver (OnlineSolverOptions::
//                   time_operators) timed in the same rounds
//   fom_active_set_rounds  the FOM median of each round (how noisy the machine was)
// Queries are the problem's validation parameters (thinned to --queries). The FOM
// and the ROMs are timed in --repeats interleaved rounds (one pass of each per round,
// after a warm-up pass), so that a slow spell of the machine hits them alike.
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "baselines/ipopt_qp.hpp"
#include "fom/active_set_solver.hpp"
#include "rom/offline.hpp"
#include "rom/online_evaluation.hpp"
#include "rom/online_methods.hpp"
#include "rom/reduced_model.hpp"
#include "rom/snapshot_database.hpp"
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct BenchArgs {
  std::string problem, db;
  int refine = 0;
  int train = 0, level = 0, repeats = 3, queries = 30, ipopt_queries = 5, threads = 0;
  double delta = 1e-8;
  bool json = false;
};

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

void run_bench(const BenchArgs& a) {
  if (a.repeats < 1) throw InputError("--repeats " + std::to_string(a.repeats) + " invalid; expected >= 1");
  if (a.queries < 1) throw InputError("--queries " + std::to_string(a.queries) + " invalid; expected >= 1");
  // The problem and its snapshots: from --db (no meshing, no offline stage), or
  // built from --problem with an offline stage of its own.
  if (a.db.empty() == a.problem.empty()) throw InputError("bench needs exactly one of --problem and --db");
  rom::SnapshotDatabase db;
  std::unique_ptr<fom::Problem> problem;
  double offline_s = 0.0;
  if (!a.db.empty()) {
    if (a.train || a.level || a.refine) throw InputError("--train, --level and --refine go with --problem, not --db");
    db = rom::read_database(a.db);
    problem = rom::problem_from_database(db, a.db);
  } else {
    fom::ProblemOptions popt;
    popt.refine = a.refine;
    problem = fom::make_problem(a.problem, popt);
  }
  const int n = a.db.empty()
                    ? fom::resolve_training_size(problem->definition().training, problem->name(), a.train, a.level, true)
                    : db.training_size;

  nlohmann::json j;
  j["problem"] = problem->name();
  j["training"] = n;
  j["delta"] = a.delta;
  j["repeats"] = a.repeats;
  auto log = [&](const std::string& s) {
    if (!a.json) std::cerr << s << std::endl;
  };

  fom::ActiveSetSolver fom_solver(*problem);
  rom::OfflineOptions off;
  off.threads = a.threads;
  if (a.db.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    db = rom::generate_snapshots(*problem, n, off);
    offline_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const std::vector<fom::Param> queries = thin(rom::database_validation_set(db, *problem), a.queries);
  j["queries"] = queries.size();
  j["offline_s"] = offline_s;
  j["snapshots"] = db.parameters.cols();
  log("offline: " + std::to_string(db.parameters.cols()) + " snapshots in " + std::to_string(offline_s) + " s");

  {
    baselines::IpoptQpSolver ipopt(*problem);
    std::vector<double> times;
    for (const fom::Param& mu : thin(queries, a.ipopt_queries)) {
      const auto s0 = std::chrono::steady_clock::now();
      ipopt.solve(mu);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count());
    }
    j["fom_ipopt"] = rom::median(times);
    j["ipopt_queries"] = times.size();
  }

  rom::ReducedModelOptions ro;
  ro.delta = a.delta;
  const rom::ReducedModel model(*problem, db, ro);
  j["primal_rank"] = model.primal_rank();
  j["dictionary_size"] = model.dictionary_size();
  nlohmann::json skipped = nlohmann::json::object();
  // Every ROM twice: as is, and clocking the construction of the contact operators
  // (the paper's convention, times without it; a separate solver so that the clock
  // reads do not touch the main times). All timed with the FOM in interleaved rounds.
  std::vector<std::string> keys;
  std::vector<std::unique_ptr<rom::OnlineSolver>> owned;
  std::vector<const rom::OnlineSolver*> solvers, clocked;
  rom::OnlineSolverOptions clock_options;
  clock_options.time_operators = true;
  // Every registered method with its defaults, then the variants that make the
  // comparison honest: the greedy schedules started as in the paper's Alg. 1
  // (init=empty) and CPG warm-started like the greedy (init=cell).
  struct Variant {
    std::string key, method;
    std::map<std::string, std::string> extra;
  };
  std::vector<Variant> variants;
  for (const std::string& method : rom::online_solver_names()) variants.push_back({key_of(method), method, {}});
  for (const char* method : {"greedy", "greedy-nested"})
    variants.push_back({key_of(method) + "_init_empty", method, {{"init", "empty"}}});
  variants.push_back({"rom_cpg_warm", "cpg", {{"init", "cell"}}});
  for (const Variant& v : variants) {
    rom::OnlineSolverOptions options, clocked_options = clock_options;
    options.extra = clocked_options.extra = v.extra;
    try {
      owned.push_back(rom::make_online_solver(v.method, model, options));
    } catch (const InputError& e) {
      skipped[v.key] = e.what();  // e.g. convex-hull on a non-convex feasible set
      continue;
    }
    solvers.push_back(owned.back().get());
    owned.push_back(rom::make_online_solver(v.method, model, clocked_options));
    clocked.push_back(owned.back().get());
    keys.push_back(v.key);
  }
  const rom::InterleavedTiming timing = rom::time_interleaved(fom_solver, solvers, queries, a.repeats, clocked);
  const double t_fom = timing.fom_median_s;
  j["fom_active_set"] = t_fom;
  j["fom_active_set_rounds"] = timing.fom_round_median_s;  // per-round medians: the machine's noise
  for (size_t i = 0; i < keys.size(); ++i) {
    const rom::OnlineTiming& t = timing.online[i];
    j[keys[i]] = t.median_core_s;
    j[keys[i] + "_with_reconstruction"] = t.median_total_s;
    if (t.median_without_operators_s >= 0.0) j[keys[i] + "_without_operators"] = t.median_without_operators_s;
  }
  if (!skipped.empty()) j["not_applicable"] = skipped;

  nlohmann::json ratios = nlohmann::json::object();
  ratios["fom_ipopt/fom_active_set"] = j["fom_ipopt"].get<double>() / t_fom;
  for (const std::string& k : keys) {
    ratios["fom_active_set/" + k] = t_fom / j[k].get<double>();
    if (k.rfind("rom_greedy", 0) == 0) {
      // The paper's starting point against the default one.
      const std::string warm = k.substr(0, k.size() - std::string("_init_empty").size());
      if (k.size() > warm.size() && k.compare(warm.size(), std::string::npos, "_init_empty") == 0 && j.contains(warm))
        ratios[k + "/" + warm] = j[k].get<double>() / j[warm].get<double>();
      if (k == "rom_greedy_nested" && j.contains("rom_greedy"))
        ratios[k + "/rom_greedy"] = j[k].get<double>() / j["rom_greedy"].get<double>();
      continue;
    }
    // The baselines against both greedy schedules, with and without the construction
    // of the contact operators (the paper's timing convention).
    for (const std::string greedy : {"rom_greedy", "rom_greedy_nested"}) {
      if (j.contains(greedy)) ratios[k + "/" + greedy] = j[k].get<double>() / j[greedy].get<double>();
      const std::string kw = k + "_without_operators", gw = greedy + "_without_operators";
      if (j.contains(kw) && j.contains(gw)) ratios[kw + "/" + gw] = j[kw].get<double>() / j[gw].get<double>();
    }
  }
  j["ratios"] = ratios;
  if (a.json) {
    std::cout << j.dump() << std::endl;
    return;
  }
  std::cout << "contactrom bench: " << problem->name() << ", training " << n << ", delta " << a.delta << ", "
            << queries.size() << " queries x " << a.repeats << " repeats (median seconds per query)\n";
  for (auto it = j.begin(); it != j.end(); ++it)
    if ((it.key().rfind("fom_", 0) == 0 || it.key().rfind("rom_", 0) == 0) && it.value().is_number())
      std::cout << "  " << std::left << std::setw(40) << it.key() << std::setprecision(4) << it.value().get<double>() << "\n";
  std::cout << "ratios:\n";
  for (auto it = ratios.begin(); it != ratios.end(); ++it)
    std::cout << "  " << std::left << std::setw(40) << it.key() << std::setprecision(4) << it.value().get<double>() << "\n";
}

CommandRegistrar reg("bench", [](CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  auto* sub = app.add_subcommand("bench", "Median per-query times of the FOM solvers and every ROM, in one run");
  sub->add_option("--problem", a->problem, "a shipped problem (contactrom problems) or a problem file path");
  sub->add_option("--db", a->db, "a snapshot database instead of --problem (no offline stage)");
  add_integer(sub, "--train", a->train, "training size (default: the problem file's [training] default_size; hertz 30)", 1, 10000000);
  add_integer(sub, "--level", a->level, "training level (default: the problem file's default_size; ironing 7, ironing2 3)", 0, 20);
  add_integer(sub, "--refine", a->refine, "extra uniform mesh refinements (each splits every quad in four)", 0, 6);
  add_number(sub, "--delta", a->delta, "POD energy tolerance (default 1e-8)", Interval::closed(0, 1));
  add_integer(sub, "--repeats", a->repeats, "timing passes over the queries (default 3)", 1, 1000);
  add_integer(sub, "--queries", a->queries, "number of validation parameters timed (default 30)", 1, 1000000);
  add_integer(sub, "--ipopt-queries", a->ipopt_queries, "queries timed for Ipopt (default 5)", 1, 1000000);
  add_integer(sub, "--threads", a->threads, "threads of the offline stage (default: all cores)", 1, 1024);
  sub->add_flag("--json", a->json, "print one JSON object");
  sub->footer(rom::describe_online_methods());
  sub->callback([a] { run_bench(*a); });
});

}  // namespace
}  // namespace contactrom::cli
