#pragma once
/// \file offline_mpi.hpp
/// \brief Offline stage distributed over MPI ranks (built with CONTACTROM_MPI).
///
/// \code
///   mpirun -np 4 contactrom offline --problem hertz --train 120 --out hertz120.h5 --threads 1
/// \endcode
///
/// Rank r of R computes the continuation chains c ≡ r (mod R) of the training
/// parameters (chains of OfflineOptions::chain consecutive parameters, rom/offline.hpp)
/// with generate_snapshots() (its own factorisation, `threads` worker threads), so
/// every rank gets the same number of chains up to one and a share of each part of
/// the parameter range (the cost of a FOM query grows with the contact zone). The
/// snapshots are gathered on rank 0 into the columns of the serial order: each
/// chain is computed exactly as in a serial run, so the database's arrays are
/// bit-identical to the serial ones; only timing fields differ. With
/// OfflineOptions::stream_to (a path of each rank's own), each rank streams its
/// primal snapshots into that file and only the pressures and outcomes are gathered:
/// rank 0's database refers to the ranks' files (SnapshotDatabase::primal_files, which
/// must be visible to rank 0: one machine or a shared file system), and
/// write_database() copies them into the database one snapshot at a time.
#include <string>
#include <vector>

#include <contactrom/rom/offline.hpp>

namespace contactrom::rom::mpi {

/// \brief Whether this process was started by an MPI launcher (mpirun/mpiexec set
/// the rank in the environment), without initialising MPI.
bool launched_by_mpi();

/// \brief Scoped MPI session: MPI_Init on construction; on destruction a barrier,
/// then MPI_Finalize. Create it first thing in main() and let it end after the
/// error messages are printed: the barrier keeps every rank alive until rank 0 has
/// reported (a launcher aborts the whole job as soon as one rank exits with an
/// error, which could otherwise cut rank 0 short).
class Session {
 public:
  Session();
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  int rank() const { return m_rank; }
  int size() const { return m_size; }

 private:
  int m_rank = 0, m_size = 1;
};

/// \brief Whether MPI is initialised and not yet finalised (a Session is alive).
bool active();
/// \brief Rank of this process in MPI_COMM_WORLD (0 when MPI is not active).
int world_rank();
/// \brief Number of ranks in MPI_COMM_WORLD (1 when MPI is not active).
int world_size();

/// \brief A failure on some rank, reported on every rank (rank 0 carries the
/// failing rank's message) so that all ranks stop together.
class RankFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief The distributed offline stage (see the file comment); collective over
/// MPI_COMM_WORLD. `options.progress` is called on rank 0 only, with rank 0's share.
/// \returns on rank 0 the whole database (threads = worker threads over all ranks,
///   setup_time_s = rank 0's factorisation, wall_time_s = until the gather ended);
///   on the other ranks an empty database.
/// \throws InputError (on every rank) for a parameter outside the range;
///   RankFailure (on every rank) if a rank's computation threw.
SnapshotDatabase generate_snapshots_distributed(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                                const std::string& training_kind, int training_size,
                                                const OfflineOptions& options = {});

/// \brief As generate_snapshots_distributed(), but every rank returns the whole
/// database (the ranks' snapshots are exchanged with MPI_Allgatherv): for a loop that
/// runs on every rank and needs the snapshots there, the adaptive offline stage
/// (rom/adaptive_training.hpp). `options.stream_to` must be empty.
SnapshotDatabase generate_snapshots_on_every_rank(const fom::Problem& problem, const std::vector<fom::Param>& params,
                                                  const std::string& training_kind, int training_size,
                                                  const OfflineOptions& options = {});

/// \brief Element-wise maximum of `values` over the ranks, on every rank
/// (collective; same size everywhere): the adaptive stage's indicators, each
/// computed on one rank and −∞ on the others (AdaptiveOptions::gather_indicators).
void max_over_ranks(std::vector<double>& values);

/// \brief Whether `ok` holds on every rank (collective; an agreement step, e.g.
/// after rank 0 wrote the file, so that every rank exits with the same outcome).
bool all_ranks_ok(bool ok);

}  // namespace contactrom::rom::mpi
