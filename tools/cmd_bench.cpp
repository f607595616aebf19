// contactrom bench (--problem P [--train N | --level n] [--refine k] | --db DB.h5) [--delta D] [--repeats R] [--json]
// Median per-query times of every solver (baselines::benchmark, baselines/benchmark.hpp),
// all measured in the same run so that their ratios are meaningful on a noisy machine:
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
//   fom_limit       the same queries at their known final pairing (one dual QP, one
//                   back-substitution, the certificate: ActiveSetSolver::solve_at), in
//                   rounds alternating with FOM queries; ratios["fom_active_set/fom_limit"]
//                   is the quotient of those rounds' medians
//   fom_pairing_iterations  mean pairing fixed-point iterations of the FOM queries
//   fom_zone_iterations     mean solves of the contact zone alone within them
// Queries are the problem's validation parameters (thinned to --queries). The FOM
// and the ROMs are timed in --repeats interleaved rounds (one pass of each per round,
// after a warm-up pass), so that a slow spell of the machine hits them alike.
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include <contactrom/baselines/benchmark.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>
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
  j["dofs"] = problem->num_dofs();
  j["training"] = n;
  j["delta"] = a.delta;
  j["repeats"] = a.repeats;
  auto log = [&](const std::string& s) {
    if (!a.json) std::cerr << s << std::endl;
  };

  rom::OfflineOptions off;
  off.threads = a.threads;
  if (a.db.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    db = rom::generate_snapshots(*problem, n, off);
    offline_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  j["offline_s"] = offline_s;
  j["snapshots"] = db.parameters.cols();
  log("offline: " + std::to_string(db.parameters.cols()) + " snapshots in " + std::to_string(offline_s) + " s");

  rom::ReducedModelOptions ro;
  ro.delta = a.delta;
  const rom::ReducedModel model(*problem, db, ro);
  j["primal_rank"] = model.primal_rank();
  j["dictionary_size"] = model.dictionary_size();
  baselines::BenchOptions options;
  options.repeats = a.repeats;
  options.queries = a.queries;
  options.ipopt_queries = a.ipopt_queries;
  const baselines::BenchReport r = baselines::benchmark(model, rom::database_validation_set(db, *problem), options);
  j["queries"] = r.queries;
  if (r.ipopt_queries > 0) j["fom_ipopt"] = r.fom_ipopt_s;  // --ipopt-queries 0: Ipopt not timed
  j["ipopt_queries"] = r.ipopt_queries;
  j["fom_active_set"] = r.fom_active_set_s;
  j["fom_active_set_rounds"] = r.fom_active_set_rounds;  // per-round medians: the machine's noise
  if (r.fom_limit_s > 0.0) {  // timed only where the stiffness does not depend on μ
    j["fom_limit"] = r.fom_limit_s;
    j["fom_pairing_iterations"] = r.fom_pairing_iterations;
    j["fom_zone_iterations"] = r.fom_zone_iterations;
  }
  for (const baselines::BenchMethod& m : r.methods) {
    const std::string& k = m.variant.key;
    j[k] = m.timing.median_core_s;
    j[k + "_with_reconstruction"] = m.timing.median_total_s;
    if (m.timing.median_without_operators_s >= 0.0) j[k + "_without_operators"] = m.timing.median_without_operators_s;
  }
  if (!r.not_applicable.empty()) j["not_applicable"] = r.not_applicable;
  j["ratios"] = r.ratios;
  const nlohmann::json& ratios = j["ratios"];
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "contactrom bench: " << problem->name() << ", training " << n << ", delta " << a.delta << ", "
            << r.queries << " queries x " << a.repeats << " repeats (median seconds per query)\n";
  // One column of names wide enough for the longest (ratio names run to 70 characters).
  std::vector<std::pair<std::string, double>> times, quotients;
  for (auto it = j.begin(); it != j.end(); ++it)
    if ((it.key().rfind("fom_", 0) == 0 || it.key().rfind("rom_", 0) == 0) && it.value().is_number())
      times.emplace_back(it.key(), it.value().get<double>());
  for (auto it = ratios.begin(); it != ratios.end(); ++it) quotients.emplace_back(it.key(), it.value().get<double>());
  size_t width = 0;
  for (const auto* list : {&times, &quotients})
    for (const auto& [key, value] : *list) width = std::max(width, key.size());
  const auto print = [width](const std::vector<std::pair<std::string, double>>& list) {
    for (const auto& [key, value] : list)
      std::cout << "  " << std::left << std::setw(static_cast<int>(width + 2)) << key << std::setprecision(4) << value
                << "\n";
  };
  print(times);
  std::cout << "ratios:\n";
  print(quotients);
}

CommandRegistrar reg("bench", [](CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  auto* sub = app.add_subcommand("bench", "Median per-query times of the FOM solvers and every ROM, in one run");
  sub->add_option("--problem", a->problem, "a shipped problem (contactrom problems) or a problem file path");
  sub->add_option("--db", a->db, "a snapshot database instead of --problem (no offline stage)");
  add_integer(sub, "--train", a->train, "training size (default: the problem file's [training] default_size; hertz 30)", 1, 10000000);
  add_integer(sub, "--level", a->level, "training level (default: the problem file's default_size; ironing 7, ironing2 3)", 1, 20);
  add_integer(sub, "--refine", a->refine, "extra uniform mesh refinements (each splits every quad in four)", 0, 6);
  add_number(sub, "--delta", a->delta, "POD energy tolerance (default 1e-8)", Interval::closed(0, 1));
  add_integer(sub, "--repeats", a->repeats, "timing passes over the queries (default 3)", 1, 1000);
  add_integer(sub, "--queries", a->queries, "number of validation parameters timed (default 30)", 1, 1000000);
  add_integer(sub, "--ipopt-queries", a->ipopt_queries, "queries timed for Ipopt (0: Ipopt not timed; default 5)", 0, 1000000);
  add_threads(sub, a->threads, "threads of the offline stage");
  sub->add_flag("--json", a->json, "print one JSON object");
  std::string methods;
  for (const rom::OnlineMethod& m : rom::online_methods()) methods += (methods.empty() ? "" : ", ") + m.name;
  sub->footer("Every online method (" + methods + ") is timed with its default settings;\n"
              "the greedy also from the empty start, with the nested schedule and with its error estimate\n"
              "(docs/cli.md lists the JSON keys of each variant).");
  sub->callback([a] { run_bench(*a); });
});

}  // namespace
}  // namespace contactrom::cli
