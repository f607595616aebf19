// contactrom query --rom ROM.h5 (--param V | --params FILE.csv) [--out FILE.csv] [--fields DIR] [--json]
//                  [--fallback none|fom [--primal-tolerance P] [--dual-tolerance D]]
// Answers queries from a reduced-model file written by `contactrom reduce`: no
// FOM, no meshing. Prints the load time and, per query, the status, iterations,
// selected snapshots, contact force and online time. With --fallback fom a query
// whose reduced answer is not success or whose error estimates (× 3) exceed the
// tolerances is answered by the FOM, built from the file's problem and mesh
// (rom/fallback.hpp); the output says which answers came from where.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <nlohmann/json.hpp>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/fom/field_output.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/rom/fallback.hpp>
#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/reduced_model_file.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct QueryArgs {
  std::string rom, param, params, out, fields, fallback = "none";
  double primal_tolerance = rom::FallbackOptions().primal_tolerance, dual_tolerance = rom::FallbackOptions().dual_tolerance;
  bool tolerance_given = false;  // --primal-tolerance or --dual-tolerance
  bool json = false;
};

nlohmann::json result_json(const rom::OnlineModel& rom, const rom::OnlineResult& res) {
  std::vector<int> snapshots;
  for (int c : res.selected) snapshots.push_back(rom.model().dictionary_snapshots()[static_cast<size_t>(c)]);
  nlohmann::json j;
  j["param"] = param_json(res.mu);
  j["status"] = to_string(res.status);
  j["converged"] = res.converged;
  if (!res.message.empty()) j["message"] = res.message;
  j["iterations"] = res.iterations;
  j["sparsity"] = res.selected.size();
  j["selected"] = snapshots;
  j["coefficients"] = std::vector<double>(res.coefficients.data(), res.coefficients.data() + res.coefficients.size());
  j["contact_force"] = res.contact_force;
  j["time_s"] = res.time_s;
  j["penetration"] = res.contact.penetration;
  j["separation"] = res.contact.complementarity;
  j["primal_estimate"] = res.primal_estimate;
  j["dual_estimate"] = res.dual_estimate;
  return j;
}

void run_query(const QueryArgs& a) {
  if (a.param.empty() == a.params.empty()) throw InputError("give exactly one of --param V and --params FILE.csv");
  const bool use_fom = a.fallback == "fom";
  if (a.tolerance_given && !use_fom)
    throw InputError("--primal-tolerance and --dual-tolerance apply to --fallback fom only");
  if (!a.out.empty() && !a.fields.empty() && std::filesystem::path(a.out).lexically_normal() ==
                                                 std::filesystem::path(a.fields).lexically_normal())
    throw InputError("--out and --fields name the same path " + quoted(a.out, 200) +
                     "; expected a CSV file and a folder of fields");
  declare_input_files({a.rom, a.params});
  if (!a.out.empty()) check_output_path(a.out);
  const auto t0 = std::chrono::steady_clock::now();
  const rom::OnlineModel rom = rom::OnlineModel::load(a.rom);
  const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const fom::Problem& problem = rom.problem();
  declare_problem_inputs(problem, {a.out});
  const std::vector<fom::Param> params =
      a.param.empty() ? rom::read_parameter_csv(a.params, problem) : std::vector<fom::Param>{parse_problem_param(problem, a.param)};
  rom::FallbackOptions fallback_options;
  fallback_options.primal_tolerance = a.primal_tolerance;
  fallback_options.dual_tolerance = a.dual_tolerance;
  std::optional<rom::FallbackSolver> fallback;
  if (use_fom) fallback.emplace(rom.solver(), fallback_options);
  std::vector<rom::OnlineResult> results;
  std::vector<rom::FallbackAnswer> answers;
  std::vector<double> times;
  int failed = 0, from_fom = 0;
  for (const fom::Param& mu : params) {
    if (use_fom) {
      answers.push_back(fallback->solve(mu));
      results.push_back(answers.back().result);
      from_fom += answers.back().from_fom ? 1 : 0;
      // A FOM answer is warned about as `fom` warns (elements turned inside out).
      for (const std::string& w : answers.back().warnings)
        std::cerr << "contactrom: warning: FOM answer at " << problem.parameters().text(mu) << ": " << w << "\n";
    } else {
      results.push_back(rom.solve(mu));
    }
    times.push_back(results.back().time_s);
    if (results.back().status != Status::Success) ++failed;
  }
  // The CSV and every field file are published together, or none of them.
  if (!a.fields.empty()) {
    // <problem>_<method>[_i], or _fom[_i] for an answer the FOM gave; i is the query's row.
    std::vector<fom::FieldSet> sets;
    for (size_t i = 0; i < results.size(); ++i) {
      const bool fom_answer = use_fom && answers[i].from_fom;
      const std::string stem = problem.name() + "_" + (fom_answer ? std::string("fom") : rom.method());
      sets.push_back({results.size() == 1 ? stem : stem + "_" + std::to_string(i), results[i].mu, &results[i].u,
                      &results[i].lambda});
    }
    std::vector<std::pair<std::string, FileWriter>> csv;
    if (!a.out.empty()) csv.emplace_back(a.out, rom::query_csv_writer(rom, results, answers));
    fom::write_field_sets(a.fields, problem, sets, csv);
  } else if (!a.out.empty()) {
    rom::write_query_csv(a.out, rom, results, answers);
  }
  nlohmann::json j;
  j["problem"] = problem.name();
  j["method"] = rom.method();
  j["primal_rank"] = rom.model().primal_rank();
  j["dictionary_size"] = rom.model().dictionary_size();
  j["load_time_s"] = load_s;
  j["median_time_s"] = rom::median(times);
  j["not_success"] = failed;
  double mean_time = 0.0;
  for (double t : times) mean_time += t / static_cast<double>(std::max<size_t>(1, times.size()));
  j["mean_time_s"] = mean_time;
  if (use_fom) {
    j["fallbacks"] = from_fom;
    j["fom_setup_time_s"] = fallback->fom_setup_time();
  }
  j["queries"] = nlohmann::json::array();
  for (size_t i = 0; i < results.size(); ++i) {
    nlohmann::json q = result_json(rom, results[i]);
    if (use_fom) {
      const rom::FallbackAnswer& f = answers[i];
      q["source"] = f.from_fom ? "fom" : "rom";
      if (f.from_fom) {
        q["fallback_reason"] = f.reason;
        q["rom_status"] = to_string(f.rom_status);
        q["rom_primal_estimate"] = f.rom_primal_estimate;
        q["rom_dual_estimate"] = f.rom_dual_estimate;
      }
      q["rom_time_s"] = f.rom_time_s;
      q["fom_time_s"] = f.fom_time_s;
    }
    j["queries"].push_back(q);
  }
  if (a.json) {
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "reduced model of " << problem.name() << " (" << rom.method() << ", primal rank "
            << rom.model().primal_rank() << ", dictionary " << rom.model().dictionary_size() << ") loaded in "
            << std::setprecision(3) << load_s * 1e3 << " ms\n";
  if (results.size() == 1) {
    const nlohmann::json& q = j["queries"][0];
    std::cout << "at " << q["param"].dump() << ": " << q["status"].get<std::string>()
              << (results[0].message.empty() ? "" : " (" + results[0].message + ")") << ", " << results[0].iterations
              << " iterations, selected snapshots " << q["selected"].dump() << "\n"
              << "contact force " << std::setprecision(6) << q["contact_force"].get<double>() << ", time "
              << std::setprecision(3) << results[0].time_s * 1e6 << " us\n";
  } else {
    std::cout << results.size() << " queries, " << failed << " not successful, median time " << rom::median(times) * 1e6
              << " us per query\n";
  }
  if (use_fom) {
    std::cout << from_fom << " of " << results.size() << " answered by the FOM (reduced status not success or error "
              << "estimates above tolerance), mean time " << mean_time * 1e6 << " us per query\n";
  }
  if (!a.out.empty()) std::cout << "per-query results written to " << a.out << "\n";
  if (!a.fields.empty()) std::cout << "fields written to " << a.fields << "/\n";
}

CommandRegistrar reg("query", [](CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  auto* sub = app.add_subcommand("query", "Answer queries from a reduced-model file (the FOM only with --fallback fom)");
  sub->add_option("--rom", args->rom, "reduced-model file written by contactrom reduce")
      ->check(non_empty_path())->required();
  sub->add_option("--param", args->param, "one query V or V1,V2");
  sub->add_option("--params", args->params, "CSV file of queries, one per line (optional header of parameter names)")
      ->check(non_empty_path());
  sub->add_option("--out", args->out, "CSV file of the per-query results")->check(non_empty_path());
  sub->add_option("--fields", args->fields, "folder for the VTU/CSV fields of every query")->check(non_empty_path());
  add_word(sub, "--fallback", args->fallback,
           "fom: answer by the FOM a query whose reduced answer is not success or whose error estimates (x 3) "
           "exceed the tolerances; none (default): the reduced answer always",
           {"none", "fom"});
  auto* primal = add_number(sub, "--primal-tolerance", args->primal_tolerance,
             "--fallback fom: largest relative H1 error of an answer kept from the ROM (default 0.05)",
             Interval::greater_than(0));
  auto* dual = add_number(sub, "--dual-tolerance", args->dual_tolerance,
             "--fallback fom: largest relative L2 pressure error of an answer kept from the ROM (default 0.2)",
             Interval::greater_than(0));
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args, primal, dual] {
    args->tolerance_given = primal->count() > 0 || dual->count() > 0;
    run_query(*args);
  });
});

}  // namespace
}  // namespace contactrom::cli
