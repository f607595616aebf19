// contactrom merge A.h5 B.h5 ... --out C.h5 [--json]
// Concatenates databases of the same problem and training set (e.g. the parts of
// `contactrom offline --part k/K`), sorted into the order of their training set; refuses databases of another
// problem, mesh or training set and repeated parameters (rom/database_merge.hpp).
#include <iostream>
#include <nlohmann/json.hpp>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/rom/database_merge.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct MergeArgs {
  std::vector<std::string> inputs;
  std::string out;
  bool json = false;
};

void run_merge(const MergeArgs& a) {
  declare_input_files(a.inputs);
  check_output_path(a.out);
  std::vector<rom::SnapshotDatabase> dbs;
  // The primal snapshots stay on disk: the merged file is written one snapshot at a time.
  for (const auto& path : a.inputs) dbs.push_back(rom::read_database(path, false));
  const rom::SnapshotDatabase merged = rom::merge_in_training_order(dbs, a.inputs);
  rom::write_database(a.out, merged);
  if (a.json) {
    nlohmann::json j;
    j["problem"] = merged.problem.name;
    j["inputs"] = a.inputs.size();
    j["snapshots"] = merged.num_snapshots();
    j["out"] = a.out;
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "merged " << a.inputs.size() << " databases of " << merged.problem.name << ": "
            << merged.num_snapshots() << " snapshots written to " << a.out << "\n";
}

CommandRegistrar reg("merge", [](CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  auto* sub = app.add_subcommand("merge", "Concatenate snapshot databases of the same problem and training set");
  sub->add_option("inputs", args->inputs, "databases (.h5), in any order (the snapshots are sorted into training order)")->required();
  sub->add_option("--out", args->out, "merged database (.h5)")->required();
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_merge(*args); });
});

}  // namespace
}  // namespace contactrom::cli
