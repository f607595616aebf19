#pragma once
/// \file database_merge.hpp
/// \brief Merging snapshot databases of the same problem, so that an offline run
/// can be split over several jobs (`contactrom offline --part k/K`) and put back
/// together (`contactrom merge`).
///
/// \code
///   contactrom offline --problem hertz --train 120 --part 1/2 --out a.h5
///   contactrom offline --problem hertz --train 120 --part 2/2 --out b.h5
///   contactrom merge a.h5 b.h5 --out hertz120.h5     # the arrays of the whole run
/// \endcode
#include <string>
#include <vector>

#include "rom/snapshot_database.hpp"

namespace contactrom::rom {

/// \brief The contiguous, balanced part k of K (1-based) of `n` items, as [begin, end):
/// part k starts at ⌊(k−1)n/K⌋ and ends at ⌊kn/K⌋.
/// \throws InputError unless 1 ≤ k ≤ K.
std::pair<int, int> part_range(int n, int k, int parts);

/// \brief Concatenates the snapshots of `databases` in the given order (timing
/// fields: setup and wall times summed, threads the largest).
/// \param names file names of the databases, for error messages (same size)
/// \throws InputError naming the two files if they differ in problem, mesh
///   fingerprint, parameter names, training options (kind and size), numbers of dofs
///   or constraints, or if a parameter appears twice.
SnapshotDatabase merge_databases(const std::vector<SnapshotDatabase>& databases, const std::vector<std::string>& names);

}  // namespace contactrom::rom
