// contactrom reduce --db DB.h5 --method M [--delta D] [--option K=V]... --out ROM.h5 [--threads T] [--json]
//   mpirun -np N contactrom reduce ...   (built with CONTACTROM_MPI): the ranks share the POD
// Builds the reduced model (POD basis, dual dictionary, reduced operators) and its
// online method from a snapshot database and writes it to a reduced-model file,
// which `contactrom query` (and Python's contactrom.ReducedModel.load) answer
// queries from without the FOM.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model_file.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#ifdef CONTACTROM_HAVE_MPI
#include <contactrom/rom/offline_mpi.hpp>
#include <contactrom/rom/pod_mpi.hpp>
#endif
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"
#include "tools/ranks.hpp"

namespace contactrom::cli {
namespace {

struct ReduceArgs : MethodArgs {
  std::string db, out;
  int threads = 0;
  std::string pod = "auto";
  bool json = false;
};

void run_reduce(const ReduceArgs& a) {
  declare_input_files({a.db});
  check_output_path(a.out);
  rom::check_online_method(a.method);
  // Every rank checks the method's settings before the ranks share the POD: a rank
  // that refused them after it would leave the others waiting in a collective step.
  rom::validate_online_options(a.method, a.solver_options());
  const auto t0 = std::chrono::steady_clock::now();
  // The primal snapshots stay on disk: the POD reads them by blocks (rom/pod.hpp).
  const rom::SnapshotDatabase db = rom::read_database(a.db, false);
  std::shared_ptr<const fom::Problem> problem = rom::problem_from_database(db, a.db);
  rom::ReducedModelOptions model_options = a.model_options();
  model_options.pod.threads = a.threads;
  model_options.pod.algorithm = a.pod == "svd"         ? rom::PodAlgorithm::Svd
                                : a.pod == "snapshots" ? rom::PodAlgorithm::Snapshots
                                                       : rom::PodAlgorithm::Auto;
  // Under mpirun the ranks share the POD (rom/pod_mpi.hpp); rank 0 builds and writes
  // the model, and every rank exits with its outcome.
  const Ranks ranks = current_ranks();
  const char* const failure = "rank 0 could not build or write the reduced model";
#ifdef CONTACTROM_HAVE_MPI
  std::unique_ptr<rom::mpi::WorldPodReduction> reduction;
  if (ranks.size > 1) {
    if (a.pod == "svd")
      throw InputError("--pod svd computes the POD in the memory of one process; under mpirun expected --pod "
                       "snapshots or auto");
    reduction = std::make_unique<rom::mpi::WorldPodReduction>();
    model_options.pod.reduction = reduction.get();
    if (!ranks.root()) {
      rom::share_reduced_model_pod(*problem, db, model_options);
      on_root_then_agree(ranks, {}, failure);
      return;
    }
  }
#endif
  std::unique_ptr<const rom::OnlineModel> built;
  on_root_then_agree(
      ranks,
      [&] {
        built = std::make_unique<const rom::OnlineModel>(problem, db, model_options, a.method, a.solver_options());
        warn_if_no_primal_modes(built->model());
        built->save(a.out);
      },
      failure);
  const rom::OnlineModel& rom = *built;
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
  j["pod_time_s"] = rom.model().pod_time();
  if (a.json) {
    std::cout << json_text(j) << std::endl;
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
  add_word(sub, "--pod", args->pod,
           "POD algorithm: auto (svd up to 2^24 snapshot entries, else snapshots), svd (BDCSVD in memory) or "
           "snapshots (method of snapshots with a Rayleigh-Ritz step, read by blocks)",
           {"auto", "svd", "snapshots"});
  add_threads(sub, args->threads, "worker threads of the POD");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_reduce(*args); });
});

}  // namespace
}  // namespace contactrom::cli
