// Convex-hull subcommands (rom/convex_hull.hpp, rom/chls.hpp; docs/convex_hull.md):
//
//   contactrom chls --db DB.h5 [--out FILE.csv] [--json]
//     Leave-one-out convex-hull least squares (CHLS) of every primal snapshot
//     against the others; CSV: parameter columns, chls_error, status,
//     iterations, support. JSON keys: chls_error (list), max_chls_error,
//     mean_chls_error, ... (rom::summary_values; docs/rom.md, "JSON keys").
//     Plotting is not done here (the CLI stays pure C++): tools/rope_experiments.py
//     plots the CSV.
//
//   contactrom hull-report --db DB.h5 [--set training|validation] [--delta D]
//                          [--basis svd|random] [--rank-l L] [--seed S]
//                          [--sum-weight W] [--no-polish] [--option KEY=VALUE ...]
//                          [--out FILE.csv] [--json]
//                          [--time [--repeats N]]
//     Convex-hull ROM on the training or validation set against the FOM, with the
//     method's statistics and the KKT compliance of every query: |1ᵀα − 1|,
//     penetration, complementarity (relative, as fom/kkt.hpp, and absolute),
//     errors, sparsity, selected snapshots and coefficients. --time also measures
//     the median online time per query with rom::time_online.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/chls.hpp>
#include <contactrom/rom/convex_hull.hpp>
#include <contactrom/rom/convex_hull_report.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {


// ---------------------------------------------------------------- chls

struct ChlsArgs {
  std::string db, out;
  bool json = false;
};

void run_chls(const ChlsArgs& a) {
  declare_input_files({a.db});
  if (!a.out.empty()) check_output_path(a.out);
  const rom::SnapshotDatabase db = rom::read_database(a.db);
  auto problem = rom::problem_from_database(db, a.db);
  declare_problem_inputs(*problem, {a.out});
  const rom::DatabaseChls chls = rom::chls_of_database(db);
  const std::vector<int>& used = chls.snapshots;
  const rom::ChlsResult& r = chls.result;
  auto support_text = [&](std::size_t k) {
    std::string s;
    for (int c : chls.support(k)) s += (s.empty() ? "" : " ") + std::to_string(c);
    return s;
  };
  if (!a.out.empty()) rom::write_chls_csv(a.out, db, chls);
  nlohmann::json j;
  j["problem"] = db.problem.name;
  j["chls_error"] = std::vector<double>(r.errors.data(), r.errors.data() + r.errors.size());
  nlohmann::json params = nlohmann::json::array();
  for (int s : used) params.push_back(param_json(db.parameter(s)));
  j["params"] = params;
  append_summary_json(j, rom::summary_values(chls));
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "CHLS (leave-one-out convex hull least squares) of " << used.size() << " " << db.problem.name
            << " primal snapshots\n"
            << std::setprecision(3);
  for (std::size_t k = 0; k < used.size(); ++k)
    std::cout << "  " << param_json(db.parameter(used[k])).dump() << "  error " << r.errors(static_cast<Eigen::Index>(k))
              << "  support [" << support_text(k) << "]\n";
  std::cout << "max error " << r.max_error << ", mean error " << r.mean_error << ", time " << r.time_s * 1e3
            << " ms\n";
  if (!a.out.empty()) std::cout << "written to " << a.out << "\n";
}

CommandRegistrar reg_chls("chls", [](CLI::App& app) {
  auto args = std::make_shared<ChlsArgs>();
  auto* sub = app.add_subcommand("chls", "Leave-one-out convex hull least squares of the primal snapshots");
  sub->add_option("--db", args->db, "snapshot database written by contactrom offline")
      ->check(non_empty_path())->required();
  sub->add_option("--out", args->out, "CSV file: parameter columns, chls_error, status, iterations, support")
      ->check(non_empty_path());
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_chls(*args); });
});

// ---------------------------------------------------------------- hull-report

struct HullArgs {
  // The convex-hull settings start at ConvexHullOptions' defaults.
  inline static const rom::ConvexHullOptions kDefaults{};
  std::string db, set = "validation", out;
  std::string basis = std::get<std::string>(rom::convex_hull_option_table().to_values(kDefaults).at("basis"));
  double delta = 1e-8, basis_delta = kDefaults.basis_delta, sum_weight = kDefaults.sum_weight;
  int rank_l = kDefaults.rank_l, threads = 0, repeats = 3, max_pairing_iterations = kDefaults.max_pairing_iterations;
  long long seed = static_cast<long long>(kDefaults.seed);
  bool polish = kDefaults.polish, json = false, time = false;
  std::vector<std::string> options;
};

void run_hull_report(const HullArgs& a) {
  declare_input_files({a.db});
  if (!a.out.empty()) check_output_path(a.out);
  const rom::SnapshotDatabase db = rom::read_database(a.db);
  auto problem = rom::problem_from_database(db, a.db);
  declare_problem_inputs(*problem, {a.out});
  rom::check_convex_hull_applicable(*problem);
  rom::ReducedModelOptions model_options;
  model_options.delta = a.delta;
  const rom::ReducedModel model(*problem, db, model_options);
  // One parsing path for the settings: the flags and every --option KEY=VALUE are
  // read as the method's key/value settings, as for `contactrom online`.
  std::map<std::string, std::string> values{{"basis", a.basis},
                                            {"basis_delta", format_number(a.basis_delta)},
                                            {"rank_l", std::to_string(a.rank_l)},
                                            {"seed", std::to_string(a.seed)},
                                            {"sum_weight", format_number(a.sum_weight)},
                                            {"polish", a.polish ? "true" : "false"},
                                            {"max_pairing_iterations", std::to_string(a.max_pairing_iterations)}};
  for (const std::string& kv : a.options) {
    auto [key, value] = rom::split_option(kv);
    values[key] = value;
  }
  const auto online_solver = rom::make_online_solver("convex-hull", model, rom::options_from_map("convex-hull", values));
  const auto& solver = dynamic_cast<const rom::ConvexHullSolver&>(*online_solver);

  const std::vector<fom::Param> params =
      a.set == "training" ? rom::database_training_set(db, *problem) : rom::database_validation_set(db, *problem);
  rom::HullReportOptions report_options;
  report_options.threads = a.threads;
  report_options.time = a.time;
  report_options.repeats = a.repeats;
  const rom::HullReport r = rom::convex_hull_report(solver, params, report_options);
  if (!a.out.empty()) rom::write_hull_report_csv(a.out, solver, r);

  nlohmann::json j;
  j["problem"] = problem->name();
  j["method"] = "convex-hull";
  j["set"] = a.set;
  j["delta"] = model.delta();
  j["basis"] = a.basis;
  j["projection_rank"] = solver.dictionary().projection_rank();
  j["dictionary_size"] = solver.dictionary().size();
  append_summary_json(j, rom::summary_values(r));
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "convex-hull on " << problem->name() << " (" << db.training_kind << " " << db.training_size << "), "
            << a.set << " set: " << r.rows.size() << " queries\n"
            << "dictionary " << j["dictionary_size"] << " columns, projection basis " << a.basis << " of rank "
            << j["projection_rank"] << " (delta " << model.delta() << ")\n"
            << std::setprecision(3) << std::left << std::setw(28) << "" << std::setw(12) << "mean" << "max\n"
            << std::setw(28) << "primal H1 error" << std::setw(12) << j["mean_primal_error"].get<double>()
            << j["max_primal_error"].get<double>() << "\n"
            << std::setw(28) << "dual L2 error" << std::setw(12) << j["mean_dual_error"].get<double>()
            << j["max_dual_error"].get<double>() << "\n"
            << std::setw(28) << "sparsity" << std::setw(12) << j["mean_sparsity"].get<double>()
            << j["max_sparsity"].get<int>() << "\n"
            << std::setw(28) << "|1'alpha - 1|" << std::setw(12) << "" << j["max_sum_violation"].get<double>() << "\n"
            << std::setw(28) << "penetration (rel / abs)" << std::setw(12) << j["max_penetration"].get<double>()
            << j["max_penetration_abs"].get<double>() << "\n"
            << std::setw(28) << "complementarity (rel / abs)" << std::setw(12) << j["max_complementarity"].get<double>()
            << j["max_complementarity_abs"].get<double>() << "\n"
            << "not converged: " << j["nonconverged"] << " of " << r.rows.size() << "\n";
  if (r.absolute_error_rows)
    std::cout << r.absolute_error_rows << " queries with a near-zero FOM displacement left out of the errors "
              << "(absolute errors: max primal " << r.max_absolute_primal_error << ", max dual "
              << r.max_absolute_dual_error << "; per query in the CSV)\n";
  if (a.time)
    std::cout << "median online time per query " << j["median_time_s"].get<double>() * 1e6 << " us (with full field "
              << j["median_total_time_s"].get<double>() * 1e6 << " us)\n";
  if (!a.out.empty()) std::cout << "per-query results written to " << a.out << "\n";
}

CommandRegistrar reg_hull("hull-report", [](CLI::App& app) {
  auto args = std::make_shared<HullArgs>();
  auto* sub = app.add_subcommand("hull-report", "Convex-hull ROM errors, sparsity and KKT compliance per query");
  sub->add_option("--db", args->db, "snapshot database written by contactrom offline")
      ->check(non_empty_path())->required();
  add_word(sub, "--set", args->set, "training | validation (default)", {"training", "validation"});
  add_number(sub, "--delta", args->delta, "POD/SVD energy tolerance (default 1e-8; paper rope: 1e-7)", Interval::closed(0, 1));
  const auto& hull = rom::convex_hull_option_table();
  add_setting(sub, "--basis", args->basis, hull, "basis");
  add_setting(sub, "--basis-delta", args->basis_delta, hull, "basis_delta");
  add_setting(sub, "--rank-l", args->rank_l, hull, "rank_l");
  add_setting(sub, "--seed", args->seed, hull, "seed");
  add_setting(sub, "--sum-weight", args->sum_weight, hull, "sum_weight");
  add_setting_negation(sub, "--no-polish", args->polish, hull, "polish");
  add_setting(sub, "--max-pairing-iterations", args->max_pairing_iterations, hull, "max_pairing_iterations");
  std::string keys;
  for (const rom::OptionSpec& spec : rom::online_method("convex-hull").options)
    keys += (keys.empty() ? "" : ", ") + spec.key;
  sub->add_option("--option", args->options, "further convex-hull setting KEY=VALUE (repeatable; keys: " + keys + ")");
  sub->add_option("--out", args->out, "CSV file, one row per query")
      ->check(non_empty_path());
  add_threads(sub, args->threads, "threads for the FOM references");
  sub->add_flag("--time", args->time, "also time the online solve (rom::time_online)");
  add_integer(sub, "--repeats", args->repeats, "passes over the set for --time (default 3)", 1, 1000);
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_hull_report(*args); });
});

}  // namespace
}  // namespace contactrom::cli
