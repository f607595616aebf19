#pragma once
/// \file adaptive_training.hpp
/// \brief Adaptive offline stage: FOM snapshots only where the reduced model's error
/// estimate says they are needed (a weak greedy in the sense of reduced-basis
/// methods, with the a posteriori estimate of rom/error_indicator.hpp).
///
/// \code
///   contactrom offline --problem ironing2 --adaptive --tolerance 0.05 --max-snapshots 400 --out ir2_adaptive.h5
///   contactrom offline --problem ironing2 --adaptive --tolerance 0.02 --append ir2_adaptive.h5   # continue it
/// \endcode
///
/// The loop (AdaptiveTrainer::run):
///  1. start from the problem's coarsest training set (level 1, or 2 uniform points,
///     or the listed points; AdaptiveOptions::initial);
///  2. build the reduced model of the snapshots so far and answer every candidate
///     parameter not yet in the database with it, each answer with its error
///     estimate (ROM queries only, in parallel on threads, and shared out over MPI
///     ranks with AdaptiveOptions::share_index);
///  3. record the round (snapshots, largest and mean indicator) and stop when the
///     largest indicator is below the tolerance ε, or the database holds N snapshots;
///  4. else solve the FOM at the B worst candidates (generate_snapshots: one
///     factorisation, worker threads; in parallel on MPI ranks with
///     AdaptiveOptions::generate), append them, and go to 2.
///
/// The candidates are a Latin hypercube of M points (fom::SamplingPlan "random",
/// seeded), fixed for the whole run. The batch is picked worst first, but a pick at μ
/// is expected to correct the candidates closer to μ than μ is to its nearest
/// snapshot (distances in the parameter box scaled to the unit cube): those are
/// skipped, so that one round trains several error peaks rather than B neighbours of
/// one; if that leaves fewer than B, the batch is filled with the worst skipped ones.
/// Only candidates whose indicator is at least ε are taken.
///
/// Determinism: every step depends on the database alone (the candidate answers are
/// computed independently and reduced in candidate order), so the database after k
/// rounds is the same whatever the thread count, and a run continued from its file
/// (resume(), `--append`) ends with the same database as a run never interrupted —
/// only the timing fields differ.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/option_table.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::rom {

/// \brief One round of an adaptive run, as reported to AdaptiveOptions::on_round.
struct AdaptiveRound {
  int round = 0;                 ///< 0-based index among the database's rounds
  int snapshots = 0;             ///< snapshots of the model evaluated in this round
  int candidates = 0;            ///< candidates evaluated (those not yet in the database)
  double max_indicator = 0.0;    ///< largest indicator over them (inf: a failed answer)
  double mean_indicator = 0.0;   ///< mean of the finite indicators
  int failed = 0;                ///< candidates whose answer had no finite estimate
  fom::Param worst;              ///< the candidate of the largest indicator
  std::vector<fom::Param> added; ///< the parameters whose FOM snapshots were added
  double time_s = 0.0;           ///< wall time of the round (s)
  /// Why the run stops after this round ("" while it goes on): "tolerance",
  /// "max_snapshots" or "candidates" (none left at or above ε).
  std::string stop;
};

/// \brief Options of AdaptiveTrainer (documented defaults).
struct AdaptiveOptions {
  /// ε: the run stops once the largest indicator over the candidates is below it
  /// (a relative error: H¹ for the displacement, L²(Γc) for the pressure). Default 0.05.
  double tolerance = 0.05;
  /// N: the run stops once the database holds this many snapshots (the initial
  /// ones included); the last batch is cut to fit. Default 200.
  int max_snapshots = 200;
  /// M: number of candidate parameters (Latin hypercube). Default 1000.
  int candidates = 1000;
  /// B: FOM snapshots added per round, at most. Default 4.
  int batch = 4;
  /// Seed of the candidates' Latin hypercube. Default 1.
  int seed = 1;
  /// Which estimate ranks the candidates: "primal" (relative H¹ of the
  /// displacement), "dual" (relative L²(Γc) of the pressure) or "max" (the larger
  /// of the two; ε then bounds both). Default "max".
  std::string indicator = "max";
  /// Initial training set: the problem's training set of this size or level (as
  /// `offline --train n` / `--level n`); 0: the coarsest useful one (level 1,
  /// 2 uniform points, or the listed points). Default 0.
  int initial = 0;
  /// Online method whose answers are estimated. Default "greedy".
  std::string method = "greedy";
  /// Reduced models built in every round (δ = model.delta, default 1e-8).
  ReducedModelOptions model;
  /// Options of the online method (`estimate` is forced on).
  OnlineSolverOptions online;
  /// FOM snapshots of each batch, and the threads of the candidate evaluation
  /// (offline.threads; ≤ 0: hardware concurrency). offline.progress reports the
  /// candidates evaluated, then the snapshots of the batch.
  OfflineOptions offline;
  /// Computes the FOM snapshots of a batch. Default generate_snapshots (threads);
  /// the CLI passes the MPI-distributed one under mpirun. Every process that runs the
  /// loop must receive the whole batch.
  std::function<SnapshotDatabase(const fom::Problem&, const std::vector<fom::Param>&, const std::string&, int,
                                 const OfflineOptions&)>
      generate;
  /// This process's share of the candidate evaluation: the candidates q (in the
  /// order of the remaining ones) with q mod `share_count` = `share_index`; the
  /// others stay −∞ until `gather_indicators` completes the vector (every answer is
  /// computed independently, so the shares give the serial indicators bit for bit).
  /// Default 0 of 1, no gather: every candidate here. The CLI, under mpirun: the
  /// rank, the number of ranks and rom::mpi::max_over_ranks.
  int share_index = 0;
  int share_count = 1;  ///< see share_index
  /// Completes the indicators of a round from every share (see share_index); optional.
  std::function<void(std::vector<double>&)> gather_indicators;
  /// Called after every round with the database as it stands (its record includes
  /// the round): the CLI writes it there, so that an interrupted run loses at most
  /// one round. Optional.
  std::function<void(const AdaptiveRound&, const SnapshotDatabase&)> on_round;
};

/// \brief The binding table of AdaptiveOptions (rom/option_table.hpp): the key,
/// member, range or words and help of every setting a user gives (ε, N, M, B, seed,
/// indicator, method, δ, initial), its default read from AdaptiveOptions{}. The flags
/// of `offline --adaptive`, Python's `offline_adaptive` keywords,
/// check_adaptive_options() and the settings an adaptive database records
/// (AdaptiveRecord::settings, adaptive_record_table()) are generated from it.
const OptionTable<AdaptiveOptions>& adaptive_option_table();

/// \brief The settings an adaptive database records: adaptive_option_table()
/// without `initial` (the database's training_size holds it).
const OptionTable<AdaptiveOptions>& adaptive_record_table();

/// \brief Refuses option values outside their declarations (adaptive_option_table())
/// and a share index outside [0, count).
/// \throws InputError naming the option, the value and what was expected.
void check_adaptive_options(const AdaptiveOptions& options);

/// \brief The options recorded in an adaptive database (AdaptiveRecord::settings, and
/// its training size as `initial`), for continuing it.
/// \throws InputError if a recorded value is outside its declaration.
AdaptiveOptions adaptive_options_of(const SnapshotDatabase& db);

/// \brief The adaptive offline stage; see the file comment.
class AdaptiveTrainer {
 public:
  /// \param problem must outlive the trainer \throws InputError as check_adaptive_options().
  AdaptiveTrainer(const fom::Problem& problem, AdaptiveOptions options);

  /// \brief A new run from the initial training set.
  SnapshotDatabase run() const;
  /// \brief Continues the adaptive database `db` (read from `path`) with this
  /// trainer's tolerance, N and B. A last round that added nothing is evaluated again
  /// (it gives the same indicators).
  /// \throws InputError if `db` is not an adaptive database of this problem, or its
  ///   candidates, seed, indicator, method, δ or initial set differ from the options'.
  SnapshotDatabase resume(SnapshotDatabase db, const std::string& path) const;

  /// The candidate parameters (M points).
  const std::vector<fom::Param>& candidates() const { return m_candidates; }
  /// The initial training set.
  std::vector<fom::Param> initial_set() const;

  /// \brief The indicator of one answer (AdaptiveOptions::indicator of its
  /// estimates); +inf when it is not finite (a failed answer is the worst).
  double indicator(const OnlineResult& answer) const;
  /// \brief The indicators of the reduced model of `db` at `params` (ROM queries, in parallel).
  std::vector<double> evaluate(const SnapshotDatabase& db, const std::vector<fom::Param>& params) const;

 private:
  SnapshotDatabase loop(SnapshotDatabase db) const;
  /// The candidates to solve the FOM at (indices), given the indicators of the
  /// candidates (−inf for those already in the database) and room for `room` snapshots.
  std::vector<int> select_batch(const std::vector<double>& indicators, const SnapshotDatabase& db, int room) const;
  AdaptiveRound evaluate_round(const SnapshotDatabase& db, std::vector<double>& indicators) const;
  void add_batch(SnapshotDatabase& db, const std::vector<fom::Param>& batch) const;
  void record_settings(AdaptiveRecord& record) const;
  int initial_size() const;

  const fom::Problem& m_problem;
  AdaptiveOptions m_options;
  std::vector<fom::Param> m_candidates;
};

}  // namespace contactrom::rom
