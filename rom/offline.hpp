#pragma once
/// \file offline.hpp
/// \brief Offline stage: FOM snapshots at the training parameters, computed in
/// parallel, collected into a SnapshotDatabase.
///
/// Exact command line of the stage (see docs/rom.md):
/// \code
///   contactrom offline --problem hertz --train 30 --out hertz30.h5 --threads 2
///   contactrom offline --problem ironing --level 5 --out ironing5.h5
/// \endcode
///
/// Continuation: the parameters are solved in chains of OfflineOptions::chain
/// consecutive ones of the list (the training sets list neighbours one after the
/// other), each from the previous one's answer (its multipliers and its contact
/// response on top of the new unconstrained solution) and the first of each chain
/// from scratch; a chain's displacements come from one back-substitution
/// (fom::solve_in_chains()). A neighbour's answer is a closer start than the
/// unconstrained solution (hertz: 13.6 pairing iterations instead of 16.6,
/// two-parameter ironing 4.8 instead of 7.8), and the shared back-substitution reads
/// the factor once. A snapshot is the FOM's answer at its parameter to the pairing
/// tolerance, not bit for bit.
///
/// Determinism: one fom::ActiveSetSolver (factorisation done once) is shared by
/// all worker threads, which take whole chains; the chains start at the multiples
/// of `chain` in the list, and every snapshot is written into the column
/// preassigned to it, so the arrays are bit-identical whatever the thread count
/// and scheduling (and MPI ranks and `--part`s, which split the list at chain
/// boundaries: part_range()). Only the timing fields differ between runs. With
/// OfflineOptions::stream_to each primal snapshot goes to the file as soon as its chain
/// is finished (rom::DatabaseWriter), with the same arrays.
#include <chrono>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include <contactrom/core/parallel_for.hpp>
#include <contactrom/core/progress_bar.hpp>
#include <contactrom/core/version.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::rom {

using fom::kDefaultChain;  ///< default length of the continuation chains (OfflineOptions::chain)

/// \brief Options of generate_snapshots (documented defaults).
struct OfflineOptions {
  int threads = 0;  ///< worker threads; ≤ 0: std::thread::hardware_concurrency(). Default 0.
  /// Label written as the `created_by` attribute. Default "contactrom " + version().
  std::string created_by = "contactrom " + version();
  ProgressCallback progress;  ///< called after every snapshot (optional)
  /// Stream the primal snapshots, as they are computed, into a database file at this
  /// path (rom::DatabaseWriter; the caller renames or merges it, and removes it on
  /// failure) instead of holding them in memory: the returned database then refers
  /// to that file (primal_files) and the run's memory does not grow with the number
  /// of snapshots (the pressures, n_c per snapshot, stay in memory). Default "" (in memory).
  std::string stream_to;
  /// The database named in error messages about `stream_to` (default: stream_to itself).
  std::string stream_label;
  /// Length of the continuation chains (see the file comment); 1: every parameter
  /// from scratch. Default kDefaultChain (8).
  int chain = kDefaultChain;
};

/// \brief Computes the FOM snapshots of `problem` at `params` (in parallel; see the
/// file comment) and returns them as a database. Snapshots whose status is not
/// Success are kept (with their status) — the caller reports them, and the reduced
/// model leaves them out.
/// \param training_kind "train", "level", "list" or "adaptive" (InputError for another),
///   \param training_size n, recorded in the database so that `online` can rebuild the
///   validation set. An empty `params` gives a database of no snapshot (an MPI rank or a
///   `--part` with no parameter of its own), which a reduced model refuses.
SnapshotDatabase generate_snapshots(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                    const std::string& training_kind, int training_size,
                                    const OfflineOptions& options = {});

/// \brief Same, with the training set selected by `n` as the problem expects
/// (fom::training_set(problem, n): `--train n` or `--level n` as its training plan says).
SnapshotDatabase generate_snapshots(const fom::Problem& problem, int n, const OfflineOptions& options = {});

}  // namespace contactrom::rom
