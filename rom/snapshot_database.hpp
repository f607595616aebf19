#pragma once
/// \file snapshot_database.hpp
/// \brief The snapshot database of the offline stage: FOM primal and dual
/// snapshots at the training parameters, with their parameters and solver
/// outcome, stored in one HDF5 file (layout in docs/database_format.md; readable
/// with h5py).
///
/// In memory, snapshots are the *columns* of column-major Eigen matrices
/// (primal: n_dofs × n_snap, dual: n_c × n_snap, parameters: n_params × n_snap).
/// The column-major buffer of an n_dofs × n_snap matrix is exactly the row-major
/// buffer of an n_snap × n_dofs array, so the HDF5 datasets are
/// `/primal[n_snap][n_dofs]` (one snapshot per row, as h5py users expect) and are
/// written and read without any transposition.
///
/// Format version 2 also stores the problem itself — the problem file's text, the
/// mesh (nodes, quads, bodies, curve groups), the contact points and weights and
/// the lifting terms — so that problem_from_database() rebuilds the problem from the
/// file alone (the .toml and .geo may be gone).
///
/// Writing is atomic (temporary file + rename). Reading refuses, with one-line
/// InputError messages naming the file: a missing file, a file that is not HDF5,
/// a truncated or corrupt file, a wrong `format_version` (version-1 files are
/// refused: rebuild them with `contactrom offline`), and (check_database) a
/// database built for another mesh or problem options.
#include <map>
#include <memory>
#include <Eigen/Dense>
#include <string>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/option_table.hpp>
#include <contactrom/rom/problem_record.hpp>
#include <contactrom/rom/snapshot_blocks.hpp>

namespace contactrom::rom {

/// \brief Version of the file layout written by write_database (attribute `format_version`).
inline constexpr int kDatabaseFormatVersion = 2;
/// The `kind` attribute of a reduced-model file (rom/reduced_model_file.hpp), which
/// read_database() names when it is given one.
inline constexpr const char* kReducedModelKind = "contactrom reduced model";

/// \brief How an adaptive offline run (rom/adaptive_training.hpp) built a database
/// (training_kind "adaptive"): the settings of its latest run and one entry per round.
/// Round k evaluated the error indicator of the model built from the first
/// `round_snapshots[k]` snapshots at every remaining candidate, then added the
/// `round_added[k]` snapshots that follow them (0 in the last round of a run that
/// stopped). Stored in the group `/adaptive` (docs/database_format.md).
struct AdaptiveRecord {
  /// The settings of the latest run by key (ε, N, M, B, seed, indicator, method, δ:
  /// the options of rom::adaptive_record_table(), which declares them), stored as
  /// attributes of /adaptive; rom::adaptive_options_of() reads them back.
  std::map<std::string, OptionValue> settings;
  int initial_snapshots = 0;     ///< the first snapshots: the initial training set
  std::vector<int> round_snapshots;        ///< snapshots of the model evaluated in each round
  std::vector<double> round_max_indicator; ///< largest indicator over the candidates (inf: a failed answer)
  std::vector<double> round_mean_indicator;///< mean of the finite indicators over the candidates
  std::vector<int> round_added;            ///< snapshots added after each round's evaluation
  std::vector<double> round_time_s;        ///< wall time of each round (evaluation, FOM batch), s
  int num_rounds() const { return static_cast<int>(round_snapshots.size()); }
};

/// \brief FOM snapshots at the training parameters; see the file comment.
struct SnapshotDatabase {
  /// The problem the snapshots were computed for: name, fingerprint, parameter
  /// names, problem-file text, mesh, contact rows and lifting terms.
  ProblemRecord problem;
  std::string created_by;        ///< program and version that wrote the file
  /// How the training set was selected: "train" (`--train n`), "level" (`--level n`),
  /// "list" (the problem's listed points) or "adaptive" (offline --adaptive: the
  /// training set of size/level `training_size` first, then the points the error
  /// indicator chose, in the order they were added; see `adaptive`).
  std::string training_kind = "train";
  int training_size = 0;                  ///< n of `--train n` or `--level n`
  /// With training_kind "adaptive": how the run went; empty otherwise.
  AdaptiveRecord adaptive;
  Eigen::MatrixXd parameters;             ///< n_params × n_snap, column j = μ_j
  /// n_dofs × n_snap, u(μ_j) − u_lift(μ_j) (zero on Dirichlet dofs); n_dofs × 0 when
  /// they are left on disk (primal_files).
  Eigen::MatrixXd primal;
  /// Where a primal snapshot on disk is: row `row` of the `/primal` dataset of
  /// primal_files[file].
  struct PrimalRef {
    int file = 0;
    int row = 0;
    bool operator==(const PrimalRef& o) const { return file == o.file && row == o.row; }
  };
  /// Files holding the primal snapshots when they are not in memory (a database read
  /// with read_database(path, false), the parts of a streamed offline run); empty when
  /// `primal` holds them.
  std::vector<std::string> primal_files;
  /// With primal_files: where each snapshot's primal is (one per snapshot).
  std::vector<PrimalRef> primal_refs;
  Eigen::MatrixXd dual;                   ///< n_c × n_snap, contact pressures λ(μ_j)
  std::vector<Status> status;             ///< FOM outcome of each snapshot
  std::vector<int> iterations;            ///< FOM active-set iterations of each snapshot
  std::vector<int> pairing_iterations;    ///< FOM pairing fixed-point iterations of each snapshot
  std::vector<double> time_s;             ///< FOM wall time of each snapshot (s)
  double setup_time_s = 0.0;              ///< FOM factorisation/condensation time (s)
  double wall_time_s = 0.0;               ///< wall time of the whole offline run (s)
  int threads = 1;                        ///< worker threads of the offline run

  int num_snapshots() const { return static_cast<int>(parameters.cols()); }
  /// Whether the primal snapshots are in memory (else in primal_file).
  bool primal_in_memory() const { return primal_files.empty(); }
  int num_dofs() const { return static_cast<int>(primal.rows()); }
  int num_constraints() const { return static_cast<int>(dual.rows()); }
  /// Parameter of snapshot j.
  fom::Param parameter(int j) const { return parameters.col(j); }
  /// Indices of the snapshots whose status is Success, ascending.
  std::vector<int> successful_snapshots() const;
};

/// \brief Writes `db` to `path` (HDF5) atomically: the file is built in memory,
/// written to a temporary file next to `path` and renamed over it once complete.
/// A database whose primal snapshots are on disk (primal_files) is written through
/// a DatabaseWriter instead, one snapshot at a time, to the temporary file.
/// \throws InputError naming `path` and the reason if the target is refused
///   (core/atomic_file.hpp: a link, folder or device), the folder is not writable
///   or the disk is full; no partial file is left behind.
void write_database(const std::string& path, const SnapshotDatabase& db);

/// \brief Refuses (InputError) a training kind a database cannot record: anything
/// but "train", "level", "list" or "adaptive", the kinds read_database accepts.
void check_training_kind(const std::string& kind);

/// \brief A database file written on disk snapshot by snapshot, so that no process
/// holds all the primal snapshots at once (the offline stage streams them as it
/// computes them; write_database() copies snapshots left on disk through it).
///
/// The file is created at `path` itself (callers write to a temporary path and
/// rename it: core/atomic_file.hpp) in the same layout as write_database's, with
/// `/primal` allocated whole up front (contiguous, uncompressed); write_primal()
/// fills its rows in any order, finish() writes everything else and closes it.
/// The arrays equal those write_database() writes for the same database.
class DatabaseWriter {
 public:
  /// \brief Creates `path` with room for `num_snapshots` primal snapshots of `num_dofs` values.
  /// \param label the database named in error messages (default: `path`), e.g. the
  ///   target a temporary file becomes.
  /// \throws InputError naming `label` if it cannot be created.
  DatabaseWriter(std::string path, int num_dofs, int num_snapshots, std::string label = "");
  /// Closes the file if finish() was not called (the caller removes it).
  ~DatabaseWriter();
  DatabaseWriter(const DatabaseWriter&) = delete;
  DatabaseWriter& operator=(const DatabaseWriter&) = delete;

  /// \brief Writes primal snapshot j (0 ≤ j < num_snapshots). Thread-safe (serialised).
  /// \throws InputError naming the file if the write fails (disk full).
  void write_primal(int j, const Eigen::VectorXd& u);
  /// \brief Writes every other field of `db` (its own primal is not read), then closes the file.
  /// \throws InputError naming the file if a write or the close fails.
  void finish(const SnapshotDatabase& db);

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// \brief Deletes the files of `db.primal_files` (the temporary parts of a streamed run,
/// once written into their database). Errors are ignored.
void remove_primal_files(const SnapshotDatabase& db);

/// \brief Reads a database written by write_database.
/// \throws InputError (one line, naming `path`) if the file is missing, is not an
///   HDF5 file, is truncated or corrupt, has another `format_version`, has
///   inconsistent dataset sizes or an attribute of the wrong shape or type, declares
///   a dataset larger than the file, or holds values no offline run writes
///   (non-finite numbers, negative pressures, times or counts).
/// \param load_primal false: the primal snapshots stay on disk (`primal` gets 0 columns,
///   `primal_files` = {path}); primal_blocks() reads them by blocks and write_database()
///   copies them row by row, checking them as they go.
SnapshotDatabase read_database(const std::string& path, bool load_primal = true);

/// \brief The primal snapshots of `db` (n_dofs × n_snap) by blocks of rows: from memory,
/// or from `db.primal_files`, restricted to `columns` (database snapshot indices, in
/// order; empty: all). The database must outlive the source.
std::unique_ptr<SnapshotBlocks> primal_blocks(const SnapshotDatabase& db, const std::vector<int>& columns = {});

/// \brief Checks that `db` (read from `path`) was built for `problem`: same
/// problem name, same mesh fingerprint (mesh + problem options), same numbers of
/// dofs, constraints and parameters.
/// \throws InputError, e.g. "database X was built for mesh fingerprint A but the
///   current hertz mesh is B".
void check_database(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path);

/// \brief The first part of check_database: same problem name, mesh fingerprint and
/// numbers of dofs, constraints and parameters, whatever snapshots `db` holds.
/// \throws InputError as check_database.
void check_database_problem(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path);

/// \brief Rebuilds the problem from the database alone (problem-file text and mesh;
/// `rope` by name), whatever snapshots it holds (a part of a run, for `merge`).
/// \throws InputError naming `path` if the stored problem cannot be rebuilt.
std::unique_ptr<fom::Problem> rebuild_database_problem(const SnapshotDatabase& db, const std::string& path);

/// \brief rebuild_database_problem(), then check_database(): the database must be
/// that problem's complete training set, in order.
std::unique_ptr<fom::Problem> problem_from_database(const SnapshotDatabase& db, const std::string& path);

/// \brief Checks that every stored parameter lies in `problem`'s range and that
/// the snapshots are those of the training set named by the database's
/// training_size (same count, same parameters): a database relabelled with
/// another size or level is refused. An adaptive database must start with that
/// training set and its rounds must account for its snapshots. Called by check_database.
/// \throws InputError naming `path`, the dataset or attribute and the value.
void check_training_set(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path);

/// \brief Training set of `problem` selected by the database's options
/// (training_set(training_size)); the database's own parameters when it is adaptive.
std::vector<fom::Param> database_training_set(const SnapshotDatabase& db, const fom::Problem& problem);

/// \brief Validation set associated with the database's training options
/// (validation_set(training_size)).
/// \throws InputError for an adaptive database, which has none (its points are not
///   a grid): evaluate it on a parameter list (`online --validation --params FILE.csv`).
std::vector<fom::Param> database_validation_set(const SnapshotDatabase& db, const fom::Problem& problem);

}  // namespace contactrom::rom
