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
#include <memory>
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "fom/problem.hpp"

namespace contactrom::rom {

/// \brief Version of the file layout written by write_database (attribute `format_version`).
inline constexpr int kDatabaseFormatVersion = 2;

/// \brief FOM snapshots at the training parameters; see the file comment.
struct SnapshotDatabase {
  std::string problem;           ///< problem name
  /// Text of the problem file the snapshots were computed for ("" for `rope`, which is built in).
  std::string problem_text;
  std::shared_ptr<const fom::Mesh> mesh;  ///< the (refined) mesh; null for `rope`
  Eigen::MatrixXd contact_points;         ///< reference coordinates of the constraint rows (dim × n_c)
  Eigen::VectorXd contact_weights;        ///< tributary lengths of the constraint rows
  Eigen::MatrixXd lifting_terms;          ///< n_dofs × n_terms: the lifting basis L_k
  std::string mesh_fingerprint;  ///< Problem::fingerprint() of the discretisation
  std::string created_by;        ///< program and version that wrote the file
  /// How the training set was selected: "train" (`--train n`), "level" (`--level n`)
  /// or "list" (the problem's listed points).
  std::string training_kind = "train";
  int training_size = 0;                  ///< n of `--train n` or `--level n`
  std::vector<std::string> param_names;   ///< names of the parameter components
  Eigen::MatrixXd parameters;             ///< n_params × n_snap, column j = μ_j
  Eigen::MatrixXd primal;                 ///< n_dofs × n_snap, u(μ_j) − u_lift(μ_j) (zero on Dirichlet dofs)
  Eigen::MatrixXd dual;                   ///< n_c × n_snap, contact pressures λ(μ_j)
  std::vector<Status> status;             ///< FOM outcome of each snapshot
  std::vector<int> iterations;            ///< FOM active-set iterations of each snapshot
  std::vector<int> pairing_iterations;    ///< FOM pairing fixed-point iterations of each snapshot
  std::vector<double> time_s;             ///< FOM wall time of each snapshot (s)
  double setup_time_s = 0.0;              ///< FOM factorisation/condensation time (s)
  double wall_time_s = 0.0;               ///< wall time of the whole offline run (s)
  int threads = 1;                        ///< worker threads of the offline run

  int num_snapshots() const { return static_cast<int>(primal.cols()); }
  int num_dofs() const { return static_cast<int>(primal.rows()); }
  int num_constraints() const { return static_cast<int>(dual.rows()); }
  /// Parameter of snapshot j.
  fom::Param parameter(int j) const { return parameters.col(j); }
  /// Indices of the snapshots whose status is Success, ascending.
  std::vector<int> successful_snapshots() const;
};

/// \brief Writes `db` to `path` (HDF5) atomically: the file is built in memory,
/// written to a temporary file next to `path` and renamed over it once complete.
/// \throws InputError naming `path` and the reason if the target is refused
///   (core/atomic_file.hpp: a link, folder or device), the folder is not writable
///   or the disk is full; no partial file is left behind.
void write_database(const std::string& path, const SnapshotDatabase& db);

/// \brief Reads a database written by write_database.
/// \throws InputError (one line, naming `path`) if the file is missing, is not an
///   HDF5 file, is truncated or corrupt, has another `format_version`, has
///   inconsistent dataset sizes or an attribute of the wrong shape or type, declares
///   a dataset larger than the file, or holds values no offline run writes
///   (non-finite numbers, negative pressures, times or counts).
SnapshotDatabase read_database(const std::string& path);

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
/// `rope` by name) and checks that it matches (check_database).
/// \throws InputError naming `path` if the stored problem cannot be rebuilt.
std::unique_ptr<fom::Problem> problem_from_database(const SnapshotDatabase& db, const std::string& path);

/// \brief Fills the problem fields of `db` (name, fingerprint, text, mesh, contact
/// points, lifting terms) from `problem`.
void describe_problem(const fom::Problem& problem, SnapshotDatabase& db);

/// \brief Checks that every stored parameter lies in `problem`'s range and that
/// the snapshots are those of the training set named by the database's
/// training_size (same count, same parameters): a database relabelled with
/// another size or level is refused. Called by check_database.
/// \throws InputError naming `path`, the dataset or attribute and the value.
void check_training_set(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path);

/// \brief Training set of `problem` selected by the database's options
/// (training_set(training_size)).
std::vector<fom::Param> database_training_set(const SnapshotDatabase& db, const fom::Problem& problem);

/// \brief Validation set associated with the database's training options
/// (validation_set(training_size)).
std::vector<fom::Param> database_validation_set(const SnapshotDatabase& db, const fom::Problem& problem);

}  // namespace contactrom::rom
