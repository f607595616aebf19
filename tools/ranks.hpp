#pragma once
// The MPI ranks a command runs on, and rank 0's work that every rank agrees on
// (offline and reduce: rank 0 writes the file, all ranks exit with its outcome).
#include <functional>

#ifdef CONTACTROM_HAVE_MPI
#include <contactrom/rom/offline_mpi.hpp>
#endif

namespace contactrom::cli {

/// Rank and size of the MPI run this process belongs to ({0, 1} when serial).
struct Ranks {
  int rank = 0, size = 1;
  bool root() const { return rank == 0; }
};

/// The ranks of this process (MPI_COMM_WORLD under mpirun).
inline Ranks current_ranks() {
#ifdef CONTACTROM_HAVE_MPI
  return Ranks{rom::mpi::world_rank(), rom::mpi::world_size()};
#else
  return Ranks{};
#endif
}

/// Runs `work` on rank 0 (nothing elsewhere); every rank then agrees on the outcome,
/// so that all of them exit with an error (RankFailure(`failure`) on the others) if
/// it failed.
inline void on_root_then_agree(const Ranks& ranks, const std::function<void()>& work, const char* failure) {
  try {
    if (ranks.root() && work) work();
  } catch (...) {
#ifdef CONTACTROM_HAVE_MPI
    if (ranks.size > 1) rom::mpi::all_ranks_ok(false);
#endif
    throw;
  }
#ifdef CONTACTROM_HAVE_MPI
  if (ranks.size > 1 && !rom::mpi::all_ranks_ok(true)) throw rom::mpi::RankFailure(failure);
#else
  (void)failure;
#endif
}

}  // namespace contactrom::cli
