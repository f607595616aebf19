// contactrom offline --problem P (--train N | --level n) (--out DB.h5 | --append DB.h5) [--threads T] [--part k/K]
//                    [--progress] [--json]
// (with --append, --problem may be left out: the database's own problem file and mesh are used)
// contactrom offline --problem P --adaptive --tolerance EPS [--max-snapshots N] [--candidates M] [--batch B]
//                    [--seed S] [--indicator primal|dual|max] [--method M] [--delta D] [--train n | --level n]
//                    (--out DB.h5 | --append DB.h5) [--threads T] [--json]
// --adaptive trains where the reduced model's error estimate is largest
// (rom/adaptive_training.hpp), writes the database after every round (an interrupted
// run loses at most one round) and reports each round on stderr; --append continues it.
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

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <nlohmann/json.hpp>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/contact_checks.hpp>
#include <contactrom/rom/adaptive_training.hpp>
#include <contactrom/rom/database_merge.hpp>
#include <contactrom/rom/offline.hpp>
#ifdef CONTACTROM_HAVE_MPI
#include <contactrom/rom/offline_mpi.hpp>
#endif
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"
#include "tools/ranks.hpp"

namespace contactrom::cli {
namespace {

struct OfflineArgs {
  std::string problem, out, append;
  int train = 0, level = 0, threads = 0, refine = 0;
  std::string part;  // "k/K": only the k-th of K contiguous parts of the training set
  bool progress = false, json = false;
  // --adaptive and the settings given (rom::adaptive_option_table() keys, checked
  // text); those not given take the defaults, or the appended database's values
  bool adaptive = false;
  std::map<std::string, std::string> adaptive_settings;
};

/// The part "k/K" of the training set (rom::part_range), for splitting a run over jobs.
std::vector<fom::Param> training_part(const std::vector<fom::Param>& params, const std::string& text) {
  int k = 0, parts = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &k, &parts, &tail) != 2)
    throw InputError("--part " + quoted(text, 200) + " invalid; expected k/K, e.g. 1/4");
  const auto [begin, end] = rom::part_range(static_cast<int>(params.size()), k, parts, rom::kDefaultChain);
  return std::vector<fom::Param>(params.begin() + begin, params.begin() + end);
}

/// Removes the file of a streamed part when the run ends (a no-op once it was renamed into place).
struct TemporaryPart {
  std::string path;
  TemporaryPart(const TemporaryPart&) = delete;
  TemporaryPart& operator=(const TemporaryPart&) = delete;
  ~TemporaryPart() { std::remove(path.c_str()); }
};

/// Writes the database `make()` returns on rank 0 (every rank agrees on the outcome).
void write_on_root(const std::string& path, const std::function<const rom::SnapshotDatabase&()>& make,
                   const Ranks& ranks) {
  on_root_then_agree(ranks, [&] { rom::write_database(path, make()); }, "rank 0 could not write the database");
}

/// What every offline run checks first, on every rank (all refuse alike): one of --out
/// and --append, an output path that can be written and is not an input; then the
/// problem, whose reference-contact warnings rank 0 prints.
std::unique_ptr<fom::Problem> open_run(const OfflineArgs& a, const Ranks& ranks) {
  if (a.out.empty() == a.append.empty()) throw InputError("offline needs one of --out DB.h5 and --append DB.h5");
  const std::string& out = a.append.empty() ? a.out : a.append;
  if (a.append.empty()) declare_input_files({a.problem});
  check_output_path(out);  // before the snapshots are computed
  std::unique_ptr<fom::Problem> problem;
  if (a.problem.empty()) {
    // --append alone continues the database's own problem (its stored file and mesh).
    if (a.append.empty()) throw InputError("offline needs --problem P (a shipped problem or a problem file path)");
    if (a.refine != 0)
      throw InputError("--refine applies with --problem; --append without it keeps the database's own mesh");
    problem = rom::rebuild_database_problem(rom::read_database(a.append, false), a.append);
  } else {
    fom::ProblemOptions popt;
    popt.refine = a.refine;
    problem = fom::make_problem(a.problem, popt);
  }
  declare_problem_inputs(*problem, {out});
  if (ranks.root())
    for (const std::string& w : fom::reference_contact_warnings(*problem)) std::cerr << "contactrom: warning: " << w << "\n";
  return problem;
}

/// Two runs appending to one database at once would each read, extend and rename it,
/// and one's snapshots would be lost: the second waits for the first (rank 0 holds the
/// lock until the file is written).
std::unique_ptr<FileLock> lock_for_append(const std::string& path, const Ranks& ranks) {
  if (path.empty()) return nullptr;
  // Every rank reads the database once rank 0 holds the lock, i.e. after the run it
  // waited for has written it.
  std::unique_ptr<FileLock> lock;
  on_root_then_agree(
      ranks,
      [&] {
        lock = std::make_unique<FileLock>(path, [path] {
          std::cerr << "contactrom: waiting for another run that is updating " << quoted(path, 200) << "\n";
        });
      },
      "rank 0 could not lock the database");
  return lock;
}

/// The flag of the adaptive setting `key` (max_snapshots: --max-snapshots).
std::string adaptive_flag(std::string key) {
  std::replace(key.begin(), key.end(), '_', '-');
  return "--" + key;
}

/// A flag per setting of rom::adaptive_option_table() (but `initial`: --train/--level
/// give it), needing --adaptive: help, default and range or words are the
/// declaration's; the text given is checked as it is read and kept by key.
void add_adaptive_settings(CLI::App* sub, CLI::Option* adaptive, std::map<std::string, std::string>& given) {
  const rom::OptionTable<rom::AdaptiveOptions>& table = rom::adaptive_option_table();
  for (const rom::OptionSpec& spec : table.specs()) {
    if (spec.key == "initial") continue;
    const std::string flag = adaptive_flag(spec.key), key = spec.key;
    const std::string given_default = key == "tolerance" ? "required for a new run" : "default " + spec.default_value;
    const std::string help =
        "adaptive: " + spec.help + " (" + rom::describe_option_type(spec) + "; " + given_default + ")";
    sub->add_option_function<std::string>(
           flag,
           [&given, &table, key, flag](const std::string& text) {
             rom::AdaptiveOptions checked;
             table.read(checked, key, text, flag);
             given[key] = text;
           },
           help)
        ->type_name(spec.type == rom::OptionType::Number ? "NUMBER" : spec.type == rom::OptionType::Integer ? "INT" : "WORD")
        ->needs(adaptive);
  }
}

/// The adaptive settings: the appended database's (or the defaults), overridden by
/// those given on the command line.
rom::AdaptiveOptions adaptive_options(const OfflineArgs& a, const rom::SnapshotDatabase* existing) {
  rom::AdaptiveOptions o = existing ? rom::adaptive_options_of(*existing) : rom::AdaptiveOptions{};
  for (const auto& [key, text] : a.adaptive_settings) rom::adaptive_option_table().read(o, key, text, adaptive_flag(key));
  if (a.train || a.level) o.initial = a.train ? a.train : a.level;
  o.offline.threads = a.threads;
  return o;
}

/// One line per round on stderr.
void report_round(const fom::Problem& problem, const rom::AdaptiveRound& r) {
  std::ostringstream line;
  line << std::setprecision(3) << "contactrom: adaptive round " << r.round << ": " << r.snapshots << " snapshots, "
       << r.candidates << " candidates, max indicator " << r.max_indicator << " at " << problem.parameters().text(r.worst)
       << ", mean " << r.mean_indicator;
  if (r.failed) line << ", " << r.failed << " without estimate";
  line << "; added " << r.added.size() << " (" << r.time_s << " s)";
  if (!r.stop.empty())
    line << "; stop: "
         << (r.stop == "tolerance" ? "max indicator below the tolerance"
             : r.stop == "max_snapshots" ? "--max-snapshots reached"
                                         : "no candidate left above the tolerance");
  std::cerr << line.str() << std::endl;
}

/// The adaptive database `--append` continues, checked against the run's problem.
rom::SnapshotDatabase read_adaptive_database(const std::string& path, const fom::Problem& problem) {
  rom::SnapshotDatabase db = rom::read_database(path);
  rom::check_database_problem(db, problem, path);
  if (db.training_kind != "adaptive")
    throw InputError("cannot continue " + quoted(path, 200) + " adaptively: it holds the training set " +
                     db.training_kind + " " + std::to_string(db.training_size) +
                     "; expected a database written by offline --adaptive");
  return db;
}

/// Under mpirun every rank runs the loop: each answers its share of the candidates,
/// the indicators are gathered on every rank, the FOM batches are distributed over
/// the ranks and every rank gets the whole batch.
void distribute_over_ranks([[maybe_unused]] rom::AdaptiveOptions& options, [[maybe_unused]] const Ranks& ranks) {
#ifdef CONTACTROM_HAVE_MPI
  if (!rom::mpi::active() || ranks.size <= 1) return;
  options.generate = rom::mpi::generate_snapshots_on_every_rank;
  options.share_index = ranks.rank;
  options.share_count = ranks.size;
  options.gather_indicators = rom::mpi::max_over_ranks;
#endif
}

/// The run's result on stdout: one JSON object, or three lines.
void print_adaptive_summary(const OfflineArgs& a, const fom::Problem& problem, const rom::SnapshotDatabase& db,
                            int before, const Ranks& ranks) {
  const rom::AdaptiveRecord& rec = db.adaptive;
  const rom::AdaptiveOptions settings = rom::adaptive_options_of(db);
  const double worst = rec.round_max_indicator.back();
  const bool converged = worst < settings.tolerance, appending = !a.append.empty();
  const std::string& out = appending ? a.append : a.out;
  if (a.json) {
    nlohmann::json j;
    j["problem"] = problem.name();
    j["adaptive"] = true;
    j["snapshots"] = db.num_snapshots() - before;
    j["total_snapshots"] = db.num_snapshots();
    j["rounds"] = rec.num_rounds();
    j["max_indicator"] = worst;
    j["mean_indicator"] = rec.round_mean_indicator.back();
    j["tolerance"] = settings.tolerance;
    j["converged"] = converged;
    j["indicator"] = settings.indicator;
    j["threads"] = db.threads;
    j["ranks"] = ranks.size;
    j["wall_time_s"] = db.wall_time_s;
    j["out"] = out;
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << std::setprecision(3) << "offline " << problem.name() << " adaptive: " << db.num_snapshots()
            << " snapshots in " << rec.num_rounds() << (rec.num_rounds() == 1 ? " round" : " rounds") << ", max indicator (" << settings.indicator << ") " << worst
            << (converged ? " < " : " >= ") << settings.tolerance << (converged ? "" : " (not reached)") << "\n"
            << "wall time " << db.wall_time_s << " s\n"
            << (appending ? "appended to " : "database written to ") << out << "\n";
}

void run_adaptive(const OfflineArgs& a) {
  const Ranks ranks = current_ranks();
  if (!a.part.empty()) throw InputError("--part does not apply to --adaptive; expected a whole adaptive run");
  const auto problem = open_run(a, ranks);
  const bool appending = !a.append.empty();
  const std::string& out = appending ? a.append : a.out;
  const std::unique_ptr<FileLock> lock = lock_for_append(a.append, ranks);
  rom::SnapshotDatabase existing;
  if (appending) existing = read_adaptive_database(a.append, *problem);
  rom::AdaptiveOptions options = adaptive_options(a, appending ? &existing : nullptr);
  if (!appending && !a.adaptive_settings.count("tolerance"))
    throw InputError("offline --adaptive needs --tolerance EPS (e.g. 0.05)");
  if (options.model.delta >= 1.0 && ranks.root())
    std::cerr << "contactrom: warning: delta " << format_number(options.model.delta)
              << " keeps no POD mode (primal rank 0); every round's reduced solution is the offset alone and no contact "
                 "can be enforced; expected a delta well below 1 (paper: 1e-6 to 1e-10)\n";
  if (appending && options.max_snapshots <= existing.num_snapshots() && ranks.root())
    std::cerr << "contactrom: warning: " << quoted(a.append, 200) << " holds " << existing.num_snapshots()
              << " snapshots already, at least --max-snapshots " << options.max_snapshots
              << ": no round adds any; expected a larger --max-snapshots\n";
  distribute_over_ranks(options, ranks);
  // What the file holds, for the messages of a run that ends early: an interrupt or
  // a failed write leaves the last round written.
  int kept = appending ? existing.num_snapshots() : 0;
  const std::string resume = "; continue it with contactrom offline --adaptive --append " + out;
  options.on_round = [&](const rom::AdaptiveRound& r, const rom::SnapshotDatabase& db) {
    // atomically, on rank 0: the file always holds whole rounds
    set_interrupt_note_on_publish(out, "contactrom: interrupted; " + quoted(out, 200) + " holds the " +
                                           std::to_string(db.num_snapshots()) + " snapshots of the rounds done" + resume);
    try {
      write_on_root(out, [&]() -> const rom::SnapshotDatabase& { return db; }, ranks);
    } catch (const WriteFailure& e) {
      if (kept == 0) throw;
      throw WriteFailure(std::string(e.what()) + "; " + quoted(out, 200) + " still holds the " + std::to_string(kept) +
                         " snapshots written before" + resume);
    }
    kept = db.num_snapshots();
    if (ranks.root()) report_round(*problem, r);
  };
  const rom::AdaptiveTrainer trainer(*problem, options);
  const int before = appending ? existing.num_snapshots() : 0;
  const rom::SnapshotDatabase db = appending ? trainer.resume(std::move(existing), a.append) : trainer.run();
  set_interrupt_note("");
  if (ranks.root()) print_adaptive_summary(a, *problem, db, before, ranks);
}

/// What a run computes: the training set (or its part), less the parameters the
/// appended database holds.
struct OfflinePlan {
  bool appending = false;
  std::string out;                 // the database written
  int n = 0;                       // training size or level
  std::vector<fom::Param> training, params;
  rom::SnapshotDatabase existing;  // the appended database (empty otherwise)
  rom::SnapshotDatabase sorted;    // `existing` in training order
};

/// The plan of a run. The database appended to is read on every rank (all refuse
/// alike) and checked against the run before any snapshot is computed.
OfflinePlan plan_offline(const OfflineArgs& a, const fom::Problem& problem) {
  OfflinePlan plan;
  plan.appending = !a.append.empty();
  plan.out = plan.appending ? a.append : a.out;
  const fom::SamplingPlan& sampling = problem.definition().training;
  if (plan.appending) plan.existing = rom::read_database(a.append, false);
  if (plan.appending && plan.existing.training_kind == "adaptive")
    throw InputError("database " + quoted(a.append, 200) +
                     " was built by offline --adaptive; expected --adaptive to continue it");
  // --append without --train/--level: the database's training set.
  const bool size_from_db = plan.appending && !a.train && !a.level && sampling.selector() != "list";
  plan.n = size_from_db ? plan.existing.training_size
                        : fom::resolve_training_size(sampling, problem.name(), a.train, a.level, false);
  plan.training = fom::training_set(problem, plan.n);
  plan.params = a.part.empty() ? plan.training : training_part(plan.training, a.part);
  if (!a.part.empty() && plan.params.empty() && current_ranks().root())
    std::cerr << "contactrom: warning: part " << a.part << " of the " << plan.training.size()
              << " training parameters holds none (parts hold whole chains of " << rom::kDefaultChain
              << " parameters, and there are more parts than chains); its database holds no snapshot\n";
  if (plan.appending) {
    rom::check_appendable(plan.existing, a.append, problem, sampling.selector(), plan.n);
    plan.params = rom::parameters_not_in(plan.existing, plan.params);
    plan.sorted = rom::sorted_by_training(plan.existing, a.append, plan.training);
  }
  return plan;
}

/// An append with nothing to compute: the database is left as it is, or rewritten
/// in training order when its snapshots are out of it (parts merged in the wrong
/// order by an older contactrom), as a whole run would have them.
void finish_without_snapshots(const OfflineArgs& a, const fom::Problem& problem, const OfflinePlan& plan,
                              const Ranks& ranks) {
  const bool reorder = plan.sorted.parameters != plan.existing.parameters;
  if (reorder) write_on_root(plan.out, [&]() -> const rom::SnapshotDatabase& { return plan.sorted; }, ranks);
  if (!ranks.root()) return;
  nlohmann::json j{{"problem", problem.name()}, {"snapshots", 0},
                   {"total_snapshots", plan.existing.num_snapshots()}, {"out", plan.out}};
  if (reorder) j["reordered"] = true;
  std::cout << (a.json ? json_text(j)
                       : a.append + (reorder ? " holds these snapshots; rewritten in training order"
                                             : " already holds these snapshots; nothing to compute"))
            << std::endl;
}

/// The snapshots of the plan, distributed over the MPI ranks under mpirun
/// (rom/offline_mpi.hpp), else on this process's threads.
rom::SnapshotDatabase compute_snapshots(const fom::Problem& problem, const OfflinePlan& plan,
                                        const rom::OfflineOptions& options) {
  const std::string kind = problem.definition().training.selector();
#ifdef CONTACTROM_HAVE_MPI
  if (rom::mpi::active()) return rom::mpi::generate_snapshots_distributed(problem, plan.params, kind, plan.n, options);
#endif
  return rom::generate_snapshots(problem, plan.params, kind, plan.n, options);
}

/// Warns of every snapshot that failed; returns how many did.
int warn_failed_snapshots(const fom::Problem& problem, const rom::SnapshotDatabase& db) {
  int failed = 0;
  for (int j = 0; j < db.num_snapshots(); ++j) {
    if (db.status[j] == Status::Success) continue;
    ++failed;
    std::cerr << "contactrom: warning: snapshot " << j << " (" << problem.parameters().text(db.parameter(j))
              << ") status " << to_string(db.status[j]) << "; stored with its status and left out of the ROM\n";
  }
  return failed;
}

/// The summary of a run (one JSON object with --json).
void print_offline_summary(const OfflineArgs& a, const fom::Problem& problem, const OfflinePlan& plan,
                           const rom::SnapshotDatabase& db, int failed, const Ranks& ranks) {
  const int stored = plan.appending ? plan.existing.num_snapshots() : 0;
  double fom_sum = 0.0;
  for (double t : db.time_s) fom_sum += t;
  const double mean_fom = db.num_snapshots() ? fom_sum / db.num_snapshots() : 0.0;
  if (a.json) {
    nlohmann::json j;
    j["problem"] = problem.name();
    j[db.training_kind] = plan.n;
    j["snapshots"] = db.num_snapshots();
    if (plan.appending) j["total_snapshots"] = stored + db.num_snapshots();
    j["failed"] = failed;
    j["threads"] = db.threads;
    j["ranks"] = ranks.size;
    j["wall_time_s"] = db.wall_time_s;
    j["setup_time_s"] = db.setup_time_s;
    j["mean_fom_time_s"] = mean_fom;
    j["out"] = plan.out;
    std::cout << json_text(j) << std::endl;
    return;
  }
  std::cout << "offline " << problem.name() << ": " << db.num_snapshots() << " snapshots (" << db.training_kind << " "
            << plan.n << "), " << failed << " failed, " << db.threads << (db.threads == 1 ? " thread" : " threads")
            << (ranks.size > 1 ? " on " + std::to_string(ranks.size) + " MPI ranks" : std::string()) << "\n"
            << std::setprecision(3) << "wall time " << db.wall_time_s << " s (factorisation " << db.setup_time_s
            << " s, mean FOM query " << 1e3 * mean_fom << " ms)\n";
  if (plan.appending)
    std::cout << "appended to " << plan.out << " (" << stored << " snapshots before, " << stored + db.num_snapshots()
              << " now)\n";
  else
    std::cout << "database written to " << plan.out << "\n";
}

void run_offline(const OfflineArgs& a) {
  if (a.adaptive) return run_adaptive(a);
  const Ranks ranks = current_ranks();
  const auto problem = open_run(a, ranks);
  const std::unique_ptr<FileLock> lock = lock_for_append(a.append, ranks);
  const OfflinePlan plan = plan_offline(a, *problem);
  if (plan.appending && plan.params.empty()) return finish_without_snapshots(a, *problem, plan, ranks);

  const std::string label =
      "offline " + problem->name() + (ranks.size > 1 ? " (rank 0 of " + std::to_string(ranks.size) + ")" : "");
  ProgressBar bar(std::cerr, label, ranks.root() && (a.progress || ::isatty(STDERR_FILENO)));
  rom::OfflineOptions options;
  options.threads = a.threads;
  // Snapshots are streamed to a file of this process as they are computed; it
  // becomes the database (serial), or is copied into it (append, MPI ranks), and is
  // removed when this function ends.
  options.stream_to = temporary_path_for(plan.out);
  options.stream_label = plan.out;
  const TemporaryPart part{options.stream_to};
  options.progress = [&bar](int done, int total) { bar.update(done, total); };
  const rom::SnapshotDatabase db = compute_snapshots(*problem, plan, options);
  bar.finish();

  rom::SnapshotDatabase appended;
  const auto result = [&]() -> const rom::SnapshotDatabase& {
    if (plan.appending) appended = rom::append_snapshots(plan.existing, a.append, db, plan.training);
    return plan.appending ? appended : db;
  };
  if (!plan.appending && ranks.size == 1) commit_temporary(options.stream_to, plan.out);  // the streamed file is the database
  if (!ranks.root()) return write_on_root(plan.out, result, ranks);
  const int failed = warn_failed_snapshots(*problem, db);
  if (plan.appending || ranks.size > 1) write_on_root(plan.out, result, ranks);
  print_offline_summary(a, *problem, plan, db, failed, ranks);
}

CommandRegistrar reg("offline", [](CLI::App& app) {
  auto args = std::make_shared<OfflineArgs>();
  auto* sub = app.add_subcommand("offline", "Compute FOM snapshots at the training parameters into an HDF5 database");
  sub->add_option("--problem", args->problem,
                  "a shipped problem (contactrom problems) or a problem file path (with --append: optional, the "
                  "database's own problem by default)");
  auto* train = add_integer(sub, "--train", args->train,
                            "training size N, for problems with uniform or random training (hertz: d_i = 0.3 i/N)", 1, 10000000);
  auto* level = add_integer(sub, "--level", args->level,
                            "training level n, for problems with nested training (ironing: 2^n+1 points)", 1, 20);
  add_integer(sub, "--refine", args->refine, "extra uniform mesh refinements (each splits every quad in four)", 0, 6);
  train->excludes(level);
  auto* out = sub->add_option("--out", args->out, "output database (.h5)")->check(non_empty_path());
  sub->add_option("--append", args->append,
                  "existing database (.h5) of the same problem and training set: compute the parameters it does not "
                  "hold yet and rewrite it with all its snapshots, in training order")
      ->check(non_empty_path())
      ->excludes(out);
  add_threads(sub, args->threads, "worker threads");
  sub->add_option("--part", args->part,
                  "k/K: only the k-th of K contiguous parts of the training set, in whole chains of " +
                      std::to_string(rom::kDefaultChain) + " parameters (join the parts with merge)");
  sub->add_flag("--progress", args->progress, "draw the progress bar even when stderr is not a terminal");
  auto* adaptive = sub->add_flag("--adaptive", args->adaptive,
                                 "train where the reduced model's error estimate is largest (docs/rom.md, "
                                 "\"Adaptive training\"); --train/--level give the initial set (default: the coarsest)");
  add_adaptive_settings(sub, adaptive, args->adaptive_settings);
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args] { run_offline(*args); });
});

}  // namespace
}  // namespace contactrom::cli
