#pragma once
/// \file database_merge.hpp
/// \brief Merging snapshot databases of the same problem, so that an offline run
/// can be split over several jobs (`contactrom offline --part k/K`) and put back
/// together (`contactrom merge`), or completed in place (`contactrom offline --append`).
///
/// \code
///   contactrom offline --problem hertz --train 120 --part 1/2 --out a.h5
///   contactrom offline --problem hertz --train 120 --part 2/2 --out b.h5
///   contactrom merge a.h5 b.h5 --out hertz120.h5     # the arrays of the whole run
///   contactrom offline --problem hertz --train 120 --append a.h5   # the same, in a.h5
/// \endcode
#include <string>
#include <vector>

#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::rom {

/// \brief The contiguous part k of K (1-based) of `n` items in whole chains of `chain`
/// (the offline stage's continuation chains, OfflineOptions::chain), as [begin, end):
/// of the m = ⌈n/chain⌉ chains, part k holds ⌊(k−1)m/K⌋ … ⌊km/K⌋ − 1 (the last
/// chain may be shorter). With chain 1: ⌊(k−1)n/K⌋ … ⌊kn/K⌋ − 1.
/// \throws InputError unless 1 ≤ k ≤ K.
std::pair<int, int> part_range(int n, int k, int parts, int chain);

/// \brief Concatenates the snapshots of `databases` in the given order (timing
/// fields: setup and wall times summed, threads the largest). Databases whose primal
/// snapshots are on disk (read_database(path, false), streamed offline runs) are
/// merged by reference: the result refers to their files, and write_database()
/// copies the snapshots one at a time (all inputs alike: in memory or on disk).
/// \param names file names of the databases, for error messages (same size)
/// \throws InputError naming the two files if they differ in problem, mesh
///   fingerprint, parameter names, training options (kind and size), numbers of dofs
///   or constraints, or if a parameter appears twice.
SnapshotDatabase merge_databases(const std::vector<SnapshotDatabase>& databases, const std::vector<std::string>& names);

/// \brief merge_databases(), then the snapshots sorted into the order of their
/// training set (the problem rebuilt from the first database), so that the parts of
/// `offline --part k/K` given in any order make the database of the whole run.
/// \throws InputError as merge_databases and sorted_by_training; naming the file of
///   an adaptive database (training_kind "adaptive"), which has no training set to
///   sort into and whose rounds no concatenation keeps (offline --adaptive --append
///   continues one).
SnapshotDatabase merge_in_training_order(const std::vector<SnapshotDatabase>& databases,
                                         const std::vector<std::string>& names);

/// \brief `db` with its snapshots sorted into the order of `training`.
/// \param name the file `db` was read from, for error messages
/// \throws InputError if a snapshot's parameter is not in `training`.
SnapshotDatabase sorted_by_training(const SnapshotDatabase& db, const std::string& name,
                                    const std::vector<fom::Param>& training);

/// \brief Checks, before any snapshot is computed, that snapshots of `problem` for
/// the training set (`training_kind`, `training_size`) can be appended to `db`
/// (read from `path`): same problem, mesh fingerprint and sizes (check_database's
/// checks), same training set, and every stored parameter in that training set.
/// \throws InputError naming `path`, the value and what was expected.
void check_appendable(const SnapshotDatabase& db, const std::string& path, const fom::Problem& problem,
                      const std::string& training_kind, int training_size);

/// \brief The parameters of `params` for which `db` holds no snapshot, in their order.
std::vector<fom::Param> parameters_not_in(const SnapshotDatabase& db, const std::vector<fom::Param>& params);

/// \brief `db` with the snapshots of `added`, all sorted into the order of
/// `training` (the whole training set), so that appending the parts of a run in
/// any order gives the arrays of the whole run. The timing fields combine as in
/// merge_databases.
/// \param name the file `db` was read from, for error messages
/// \throws InputError as merge_databases, or if a snapshot's parameter is not in `training`.
SnapshotDatabase append_snapshots(const SnapshotDatabase& db, const std::string& name, const SnapshotDatabase& added,
                                  const std::vector<fom::Param>& training);

}  // namespace contactrom::rom
