// contactrom query --rom ROM.h5 (--param V | --params FILE.csv) [--out FILE.csv] [--fields DIR] [--json]
// Answers queries from a reduced-model file written by `contactrom reduce`: no
// FOM, no meshing, no factorisation. Prints the load time and, per query, the
// status, iterations, selected snapshots, contact force and online time.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "fom/field_output.hpp"
#include "fom/kkt.hpp"
#include "rom/online_timing.hpp"
#include "rom/reduced_model_file.hpp"
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct QueryArgs {
  std::string rom, param, params, out, fields;
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
  j["contact_force"] = fom::contact_force(rom.problem(), res.lambda);
  j["time_s"] = res.time_s;
  j["penetration"] = res.contact.penetration;
  j["separation"] = res.contact.complementarity;
  j["primal_estimate"] = res.primal_estimate;
  j["dual_estimate"] = res.dual_estimate;
  return j;
}

void run_query(const QueryArgs& a) {
  if (a.param.empty() == a.params.empty()) throw InputError("give exactly one of --param V and --params FILE.csv");
  if (!a.out.empty()) check_output_path(a.out), check_output_not_input(a.out, {a.rom, a.params});
  const auto t0 = std::chrono::steady_clock::now();
  const rom::OnlineModel rom = rom::OnlineModel::load(a.rom);
  const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const fom::Problem& problem = rom.problem();
  const std::vector<fom::Param> params =
      a.param.empty() ? rom::read_parameter_csv(a.params, problem) : std::vector<fom::Param>{parse_problem_param(problem, a.param)};
  std::vector<rom::OnlineResult> results;
  std::vector<double> times;
  int failed = 0;
  for (const fom::Param& mu : params) {
    results.push_back(rom.solve(mu));
    times.push_back(results.back().time_s);
    if (results.back().status != Status::Success) ++failed;
  }
  // The CSV and every field file are published together, or none of them.
  if (!a.fields.empty()) {
    const std::string stem = problem.name() + "_" + rom.method();
    std::vector<fom::FieldSet> sets;
    for (size_t i = 0; i < results.size(); ++i)
      sets.push_back({results.size() == 1 ? stem : stem + "_" + std::to_string(i), results[i].mu, &results[i].u,
                      &results[i].lambda});
    std::vector<std::pair<std::string, FileWriter>> csv;
    if (!a.out.empty()) csv.emplace_back(a.out, rom::query_csv_writer(rom, results));
    fom::write_field_sets(a.fields, problem, sets, csv);
  } else if (!a.out.empty()) {
    rom::write_query_csv(a.out, rom, results);
  }
  nlohmann::json j;
  j["problem"] = problem.name();
  j["method"] = rom.method();
  j["primal_rank"] = rom.model().primal_rank();
  j["dictionary_size"] = rom.model().dictionary_size();
  j["load_time_s"] = load_s;
  j["median_time_s"] = rom::median(times);
  j["not_success"] = failed;
  j["queries"] = nlohmann::json::array();
  for (const rom::OnlineResult& res : results) j["queries"].push_back(result_json(rom, res));
  if (a.json) {
    std::cout << j.dump() << std::endl;
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
  if (!a.out.empty()) std::cout << "per-query results written to " << a.out << "\n";
  if (!a.fields.empty()) std::cout << "fields written to " << a.fields << "/\n";
}

CommandRegistrar reg("query", [](CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  auto* sub = app.add_subcommand("query", "Answer queries from a reduced-model file (no FOM)");
  sub->add_option("--rom", args->rom, "reduced-model file written by contactrom reduce")
      ->check(non_empty_path())->required();
  sub->add_option("--param", args->param, "one query V or V1,V2");
  sub->add_option("--params", args->params, "CSV file of queries, one per line (optional header of parameter names)")
      ->check(non_empty_path());
  sub->add_option("--out", args->out, "CSV file of the per-query results")->check(non_empty_path());
  sub->add_option("--fields", args->fields, "folder for the VTU/CSV fields of every query")->check(non_empty_path());
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_query(*args); });
});

}  // namespace
}  // namespace contactrom::cli
