// contactrom reduce --db DB.h5 --method M [--delta D] [--option K=V]... --out ROM.h5 [--json]
// Builds the reduced model (POD basis, dual dictionary, reduced operators) and its
// online method from a snapshot database and writes it to a reduced-model file,
// which `contactrom query` (and Python's contactrom.ReducedModel.load) answer
// queries from without the FOM.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "rom/online_methods.hpp"
#include "rom/reduced_model_file.hpp"
#include "rom/snapshot_database.hpp"
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct ReduceArgs : MethodArgs {
  std::string db, out;
  bool json = false;
};

void run_reduce(const ReduceArgs& a) {
  check_output_path(a.out);
  check_output_not_input(a.out, {a.db});
  rom::check_online_method(a.method);
  const auto t0 = std::chrono::steady_clock::now();
  const rom::SnapshotDatabase db = rom::read_database(a.db);
  std::shared_ptr<const fom::Problem> problem = rom::problem_from_database(db, a.db);
  const rom::OnlineModel rom(problem, db, a.model_options(), a.method, a.solver_options());
  warn_if_no_primal_modes(rom.model());
  rom.save(a.out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(a.out, ec);
  nlohmann::json j;
  j["problem"] = problem->name();
  j["method"] = rom.method();
  j["delta"] = rom.model().delta();
  j["primal_rank"] = rom.model().primal_rank();
  j["dictionary_size"] = rom.model().dictionary_size();
  j["dual_basis_size"] = rom.solver().dual_basis_size();
  j["options"] = rom::options_to_map(rom.method(), rom.options());
  j["out"] = a.out;
  j["bytes"] = ec ? 0 : bytes;
  j["time_s"] = seconds;
  if (a.json) {
    std::cout << j.dump() << std::endl;
    return;
  }
  std::cout << "reduced model of " << problem->name() << " (" << rom.method() << "): primal rank "
            << rom.model().primal_rank() << " (delta " << rom.model().delta() << "), dictionary "
            << rom.model().dictionary_size() << " columns (dual basis " << rom.solver().dual_basis_size() << ")\n"
            << "written to " << a.out << " (" << (ec ? 0 : bytes) / 1024 << " KiB) in " << seconds << " s\n";
}

CommandRegistrar reg("reduce", [](CLI::App& app) {
  auto args = std::make_shared<ReduceArgs>();
  auto* sub = app.add_subcommand("reduce", "Build a reduced model from a snapshot database and save it to a file");
  sub->add_option("--db", args->db, "snapshot database written by contactrom offline")
      ->check(non_empty_path())->required();
  add_method_options(sub, *args);
  sub->add_option("--out", args->out, "reduced-model file to write (HDF5)")->check(non_empty_path())->required();
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_reduce(*args); });
});

}  // namespace
}  // namespace contactrom::cli
