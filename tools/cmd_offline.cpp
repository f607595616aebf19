// contactrom offline --problem P (--train N | --level n) (--out DB.h5 | --append DB.h5) [--threads T] [--part k/K]
//                    [--progress] [--json]
// Computes the FOM snapshots at the training parameters in parallel (one shared
// factorisation, no warm start, deterministic) and writes them to an HDF5
// database (docs/database_format.md). With --append, only the parameters the
// database does not hold yet are computed, and the database is rewritten (atomically)
// with all its snapshots in training order. A progress bar is drawn on stderr when it
// is a terminal (or with --progress); snapshots that did not converge are
// reported on stderr and stored with their status.
//   mpirun -np N contactrom offline ...   (built with CONTACTROM_MPI) distributes the
// parameters over the ranks; rank 0 gathers them and writes the same database.
#include <unistd.h>

#include <functional>
#include <memory>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "core/format.hpp"
#include "core/errors.hpp"
#include "fom/contact_checks.hpp"
#include "rom/database_merge.hpp"
#include "rom/offline.hpp"
#ifdef CONTACTROM_HAVE_MPI
#include "rom/offline_mpi.hpp"
#endif
#include "core/atomic_file.hpp"
#include "rom/snapshot_database.hpp"
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {

struct OfflineArgs {
  std::string problem, out, append;
  int train = 0, level = 0, threads = 0, refine = 0;
  std::string part;  // "k/K": only the k-th of K contiguous parts of the training set
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

/// The part "k/K" of the training set (rom::part_range), for splitting a run over jobs.
std::vector<fom::Param> training_part(const std::vector<fom::Param>& params, const std::string& text) {
  int k = 0, parts = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &k, &parts, &tail) != 2)
    throw InputError("--part " + quoted(text, 200) + " invalid; expected k/K, e.g. 1/4");
  const auto [begin, end] = rom::part_range(static_cast<int>(params.size()), k, parts);
  return std::vector<fom::Param>(params.begin() + begin, params.begin() + end);
}

/// Removes the file of a streamed part when the run ends (a no-op once it was renamed into place).
struct TemporaryPart {
  std::string path;
  TemporaryPart(const TemporaryPart&) = delete;
  TemporaryPart& operator=(const TemporaryPart&) = delete;
  ~TemporaryPart() { std::remove(path.c_str()); }
};

/// Rank and size of the MPI run this process belongs to ({0, 1} when serial).
struct Ranks {
  int rank = 0, size = 1;
  bool root() const { return rank == 0; }
};

/// Writes the database `make()` returns on rank 0; every rank then agrees on the
/// outcome, so that all of them exit with an error if making or writing it failed.
void write_on_root(const std::string& path, const std::function<const rom::SnapshotDatabase&()>& make,
                   const Ranks& ranks) {
  try {
    if (ranks.root()) rom::write_database(path, make());
  } catch (...) {
#ifdef CONTACTROM_HAVE_MPI
    if (ranks.size > 1) rom::mpi::all_ranks_ok(false);
#endif
    throw;
  }
#ifdef CONTACTROM_HAVE_MPI
  if (ranks.size > 1 && !rom::mpi::all_ranks_ok(true))
    throw rom::mpi::RankFailure("rank 0 could not write the database");
#endif
}

void run_offline(const OfflineArgs& a) {
#ifdef CONTACTROM_HAVE_MPI
  // Under mpirun (main() started MPI), the snapshots are distributed over the ranks
  // (rom/offline_mpi.hpp).
  const bool distributed = rom::mpi::active();
  const Ranks ranks{rom::mpi::world_rank(), rom::mpi::world_size()};
#else
  const Ranks ranks;
#endif
  if (a.out.empty() == a.append.empty()) throw InputError("offline needs one of --out DB.h5 and --append DB.h5");
  const bool appending = !a.append.empty();
  const std::string& out = appending ? a.append : a.out;
  check_output_path(out);  // before the snapshots are computed (every rank: all refuse alike)
  if (!appending) check_output_not_input(out, {a.problem});
  fom::ProblemOptions popt;
  popt.refine = a.refine;
  auto problem = fom::make_problem(a.problem, popt);
  if (ranks.root())
    for (const std::string& w : fom::reference_contact_warnings(*problem)) std::cerr << "contactrom: warning: " << w << "\n";
  const fom::SamplingPlan& plan = problem->definition().training;
  // Two runs appending to one database at once would each read, extend and
  // rename it, and one's snapshots would be lost: the second waits for the first
  // (the lock is held until the file is written).
  std::unique_ptr<FileLock> lock;
  if (appending && ranks.root())
    lock = std::make_unique<FileLock>(a.append, [&] {
      std::cerr << "contactrom: waiting for another run that is updating " << quoted(a.append, 200) << "\n";
    });
  // The database appended to is read on every rank (all refuse alike) and checked
  // against the run before any snapshot is computed.
  rom::SnapshotDatabase existing;
  if (appending) existing = rom::read_database(a.append, false);
  // --append without --train/--level: the database's training set.
  const bool size_from_db = appending && !a.train && !a.level && plan.selector() != "list";
  const int n = size_from_db ? existing.training_size
                             : fom::resolve_training_size(plan, problem->name(), a.train, a.level, false);
  if (a.threads < 0) throw InputError("--threads " + std::to_string(a.threads) + " invalid; expected >= 1");
  const std::vector<fom::Param> training = fom::training_set(*problem, n);
  std::vector<fom::Param> params = a.part.empty() ? training : training_part(training, a.part);
  if (appending) {
    rom::check_appendable(existing, a.append, *problem, plan.selector(), n);
    params = rom::parameters_not_in(existing, params);
    // Snapshots out of training order (parts merged in the wrong order by an older
    // contactrom) are put in order, as a whole run would have them.
    const rom::SnapshotDatabase sorted = rom::sorted_by_training(existing, a.append, training);
    if (params.empty() && sorted.parameters != existing.parameters) {
      write_on_root(out, [&]() -> const rom::SnapshotDatabase& { return sorted; }, ranks);
      if (ranks.root()) std::cout << (a.json ? nlohmann::json{{"problem", problem->name()}, {"snapshots", 0},
                                                              {"total_snapshots", existing.num_snapshots()},
                                                              {"out", out}, {"reordered", true}}.dump()
                                             : a.append + " holds these snapshots; rewritten in training order")
                                  << std::endl;
      return;
    }
    if (params.empty()) {  // every rank knows it: none computes, the file is left as it is
      if (ranks.root()) std::cout << (a.json ? nlohmann::json{{"problem", problem->name()}, {"snapshots", 0},
                                                              {"total_snapshots", existing.num_snapshots()},
                                                              {"out", out}}.dump()
                                             : a.append + " already holds these snapshots; nothing to compute")
                                  << std::endl;
      return;
    }
  }

  const std::string label =
      "offline " + problem->name() + (ranks.size > 1 ? " (rank 0 of " + std::to_string(ranks.size) + ")" : "");
  ProgressBar bar(std::cerr, label, ranks.root() && (a.progress || ::isatty(STDERR_FILENO)));
  rom::OfflineOptions options;
  options.threads = a.threads;
  // Snapshots are streamed to a file of this process as they are computed; it
  // becomes the database (serial), or is copied into it (append, MPI ranks), and is
  // removed when this function ends.
  options.stream_to = temporary_path_for(out);
  options.stream_label = out;
  const TemporaryPart part{options.stream_to};
  options.progress = [&bar](int done, int total) { bar.update(done, total); };
  const std::string kind = plan.selector();
#ifdef CONTACTROM_HAVE_MPI
  const rom::SnapshotDatabase db = distributed
                                       ? rom::mpi::generate_snapshots_distributed(*problem, params, kind, n, options)
                                       : rom::generate_snapshots(*problem, params, kind, n, options);
#else
  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, params, kind, n, options);
#endif
  bar.finish();
  rom::SnapshotDatabase appended;
  const auto result = [&]() -> const rom::SnapshotDatabase& {
    if (appending) appended = rom::append_snapshots(existing, a.append, db, training);
    return appending ? appended : db;
  };
  if (!appending && ranks.size == 1) {  // the streamed file is the database: publish it as it is
    commit_temporary(options.stream_to, out);
  }
  if (!ranks.root()) {
    write_on_root(out, result, ranks);
    return;
  }

  int failed = 0;
  for (int j = 0; j < db.num_snapshots(); ++j) {
    if (db.status[j] == Status::Success) continue;
    ++failed;
    std::cerr << "contactrom: warning: snapshot " << j << " (" << param_text(*problem, db.parameter(j))
              << ") status " << to_string(db.status[j]) << "; stored with its status and left out of the ROM\n";
  }
  const int stored = appending ? existing.num_snapshots() : 0;
  if (appending || ranks.size > 1) write_on_root(out, result, ranks);

  double fom_sum = 0.0;
  for (double t : db.time_s) fom_sum += t;
  if (a.json) {
    nlohmann::json j;
    j["problem"] = problem->name();
    j[db.training_kind] = n;
    j["snapshots"] = db.num_snapshots();
    if (appending) j["total_snapshots"] = stored + db.num_snapshots();
    j["failed"] = failed;
    j["threads"] = db.threads;
    j["ranks"] = ranks.size;
    j["wall_time_s"] = db.wall_time_s;
    j["setup_time_s"] = db.setup_time_s;
    j["mean_fom_time_s"] = db.num_snapshots() ? fom_sum / db.num_snapshots() : 0.0;
    j["out"] = out;
    std::cout << j.dump() << std::endl;
    return;
  }
  std::cout << "offline " << problem->name() << ": " << db.num_snapshots() << " snapshots (" << db.training_kind << " "
            << n << "), " << failed << " failed, " << db.threads << " threads"
            << (ranks.size > 1 ? " on " + std::to_string(ranks.size) + " MPI ranks" : std::string()) << "\n"
            << std::setprecision(3) << "wall time " << db.wall_time_s << " s (factorisation " << db.setup_time_s
            << " s, mean FOM query " << (db.num_snapshots() ? 1e3 * fom_sum / db.num_snapshots() : 0.0) << " ms)\n";
  if (appending)
    std::cout << "appended to " << out << " (" << stored << " snapshots before, " << stored + db.num_snapshots()
              << " now)\n";
  else
    std::cout << "database written to " << out << "\n";
}

CommandRegistrar reg("offline", [](CLI::App& app) {
  auto args = std::make_shared<OfflineArgs>();
  auto* sub = app.add_subcommand("offline", "Compute FOM snapshots at the training parameters into an HDF5 database");
  sub->add_option("--problem", args->problem, "a shipped problem (contactrom problems) or a problem file path")->required();
  auto* train = add_integer(sub, "--train", args->train,
                            "training size N, for problems with uniform or random training (hertz: d_i = 0.3 i/N)", 1, 10000000);
  auto* level = add_integer(sub, "--level", args->level,
                            "training level n, for problems with nested training (ironing: 2^n+1 points)", 0, 20);
  add_integer(sub, "--refine", args->refine, "extra uniform mesh refinements (each splits every quad in four)", 0, 6);
  train->excludes(level);
  auto* out = sub->add_option("--out", args->out, "output database (.h5)")->check(non_empty_path());
  sub->add_option("--append", args->append,
                  "existing database (.h5) of the same problem and training set: compute the parameters it does not "
                  "hold yet and rewrite it with all its snapshots, in training order")
      ->check(non_empty_path())
      ->excludes(out);
  add_integer(sub, "--threads", args->threads, "worker threads (default: hardware concurrency)", 1, 1024);
  sub->add_option("--part", args->part,
                  "k/K: only the k-th of K contiguous parts of the training set (join the parts with merge)");
  sub->add_flag("--progress", args->progress, "draw the progress bar even when stderr is not a terminal");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_offline(*args); });
});

}  // namespace
}  // namespace contactrom::cli
