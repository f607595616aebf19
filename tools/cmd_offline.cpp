// contactrom offline --problem P (--train N | --level n) --out DB.h5 [--threads T] [--progress] [--json]
// Computes the FOM snapshots at the training parameters in parallel (one shared
// factorisation, no warm start, deterministic) and writes them to an HDF5
// database (docs/database_format.md). A progress bar is drawn on stderr when it
// is a terminal (or with --progress); snapshots that did not converge are
// reported on stderr and stored with their status.
#include <unistd.h>

#include <cstdio>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "fom/errors.hpp"
#include "rom/offline.hpp"
#include "rom/snapshot_database.hpp"
#include "fom/atomic_file.hpp"
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct OfflineArgs {
  std::string problem, out;
  int train = 0, level = 0, threads = 0;
  bool progress = false, json = false;
};

std::string param_text(const fom::Problem& problem, const fom::Param& mu) {
  std::string out;
  for (int k = 0; k < mu.size(); ++k) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s=%.10g", k ? ", " : "", problem.param_names()[k].c_str(), mu(k));
    out += buf;
  }
  return out;
}

void run_offline(const OfflineArgs& a) {
  check_output_path(a.out);  // before the snapshots are computed
  auto problem = fom::make_problem(a.problem);
  int n = 0;
  if (problem->uses_levels()) {
    if (a.train) throw InputError("problem '" + a.problem + "' selects its training set with --level n, not --train");
    if (!a.level) throw InputError("problem '" + a.problem + "' needs --level n");
    n = a.level;
  } else {
    if (a.level) throw InputError("problem '" + a.problem + "' selects its training set with --train N, not --level");
    if (!a.train && problem->name() != "rope") throw InputError("problem '" + a.problem + "' needs --train N");
    // rope has one fixed training set (DESIGN §1); record its size.
    n = a.train ? a.train : static_cast<int>(problem->training_set(1).size());
  }
  if (a.threads < 0) throw InputError("--threads " + std::to_string(a.threads) + " invalid; expected >= 1");
  const std::vector<fom::Param> params = problem->training_set(n);

  rom::ProgressBar bar(std::cerr, "offline " + problem->name(), a.progress || ::isatty(STDERR_FILENO));
  rom::OfflineOptions options;
  options.threads = a.threads;
  options.progress = [&bar](int done, int total) { bar.update(done, total); };
  const rom::SnapshotDatabase db =
      rom::generate_snapshots(*problem, params, problem->uses_levels() ? "level" : "train", n, options);
  bar.finish();

  int failed = 0;
  for (int j = 0; j < db.num_snapshots(); ++j) {
    if (db.status[j] == Status::Success) continue;
    ++failed;
    std::cerr << "contactrom: warning: snapshot " << j << " (" << param_text(*problem, db.parameter(j))
              << ") status " << to_string(db.status[j]) << "; stored with its status and left out of the ROM\n";
  }
  rom::write_database(a.out, db);

  double fom_sum = 0.0;
  for (double t : db.time_s) fom_sum += t;
  if (a.json) {
    nlohmann::json j;
    j["problem"] = problem->name();
    j[db.training_kind] = n;
    j["snapshots"] = db.num_snapshots();
    j["failed"] = failed;
    j["threads"] = db.threads;
    j["wall_time_s"] = db.wall_time_s;
    j["setup_time_s"] = db.setup_time_s;
    j["mean_fom_time_s"] = db.num_snapshots() ? fom_sum / db.num_snapshots() : 0.0;
    j["out"] = a.out;
    std::cout << j.dump() << std::endl;
    return;
  }
  std::cout << "offline " << problem->name() << ": " << db.num_snapshots() << " snapshots (" << db.training_kind << " "
            << n << "), " << failed << " failed, " << db.threads << " threads\n"
            << std::setprecision(3) << "wall time " << db.wall_time_s << " s (factorisation " << db.setup_time_s
            << " s, mean FOM query " << (db.num_snapshots() ? 1e3 * fom_sum / db.num_snapshots() : 0.0) << " ms)\n"
            << "database written to " << a.out << "\n";
}

CommandRegistrar reg("offline", [](CLI::App& app) {
  auto args = std::make_shared<OfflineArgs>();
  auto* sub = app.add_subcommand("offline", "Compute FOM snapshots at the training parameters into an HDF5 database");
  sub->add_option("--problem", args->problem, "rope | hertz | ironing | ironing2")->required();
  auto* train = add_integer(sub, "--train", args->train, "training size N (hertz: d_i = 0.3 i/N)", 1, 100000);
  auto* level = add_integer(sub, "--level", args->level, "nested training level n (ironing, ironing2)", 1, 12);
  train->excludes(level);
  sub->add_option("--out", args->out, "output database (.h5)")
      ->check(non_empty_path())->required();
  add_integer(sub, "--threads", args->threads, "worker threads (default: hardware concurrency)", 1, 1024);
  sub->add_flag("--progress", args->progress, "draw the progress bar even when stderr is not a terminal");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_offline(*args); });
});

}  // namespace
}  // namespace contactrom::cli
