// contactrom problems [--json]
// Lists the shipped problems (problems/*.toml and the built-in rope) with their
// parameters, training plan and mesh; `--problem NAME` accepts each of them.
#include <iostream>
#include <nlohmann/json.hpp>

#include <contactrom/fom/problem.hpp>
#include <contactrom/fom/rope.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct ProblemsArgs {
  bool json = false;
};

void run_problems(const ProblemsArgs& a) {
  nlohmann::json list = nlohmann::json::array();
  for (const std::string& name : fom::shipped_problem_names()) {
    fom::ProblemDefinition def;
    if (name == "rope") {
      def = fom::make_rope_problem()->definition();
    } else {
      def = fom::read_problem_file(fom::find_problem_file(name));
    }
    nlohmann::json p;
    p["name"] = name;
    p["file"] = def.builtin.empty() ? def.path : "(built in)";
    p["mesh"] = def.mesh;
    p["parameters"] = def.parameters.range_text();
    p["training"] = def.training.kind_name();
    p["train_flag"] = def.training.selector() == "list" ? "" : "--" + def.training.selector();
    p["validation"] = def.validation.kind_name();
    p["contact_pairs"] = def.builtin.empty() ? def.contact.size() : 1;
    p["bodies"] = def.bodies.size();
    list.push_back(p);
  }
  if (a.json) {
    std::cout << json_text(nlohmann::json{{"problems", list}}) << std::endl;
    return;
  }
  std::cout << "shipped problems (" << fom::problem_directory() << "):\n";
  for (const auto& p : list) {
    std::cout << "  " << p["name"].get<std::string>() << ": " << p["parameters"].get<std::string>() << "; training "
              << p["training"].get<std::string>();
    if (!p["train_flag"].get<std::string>().empty()) std::cout << " (" << p["train_flag"].get<std::string>() << ")";
    std::cout << "; " << p["bodies"].get<size_t>() << " bodies, " << p["contact_pairs"].get<size_t>()
              << " contact pair(s); " << p["file"].get<std::string>() << "\n";
  }
}

CommandRegistrar reg("problems", [](CLI::App& app) {
  auto args = std::make_shared<ProblemsArgs>();
  auto* sub = app.add_subcommand("problems", "List the shipped problems with their parameters");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_problems(*args); });
});

}  // namespace
}  // namespace contactrom::cli
