#pragma once
/// \file pod_mpi.hpp
/// \brief The POD's method of snapshots shared by MPI ranks (built with CONTACTROM_MPI).
///
/// \code
///   mpirun -np 2 contactrom reduce --db hertz2000.h5 --method greedy --out rom.h5
/// \endcode
///
/// Each rank reads a contiguous share of the snapshot matrix's rows (rom::row_share)
/// from the database file; the Gram matrix, the Cholesky-QR products and the
/// projection Y = QᵀS are summed over the ranks (MPI_Allreduce), so that every rank
/// decomposes the same small matrices; rank 0 gathers the basis and builds the
/// reduced model. The sums are the serial ones regrouped: the basis agrees with the
/// serial run to rounding (singular values to about 1e-12 relative).
#include <contactrom/rom/pod.hpp>

namespace contactrom::rom::mpi {

/// \brief PodReduction over MPI_COMM_WORLD (MPI must be active: a Session is alive).
class WorldPodReduction : public PodReduction {
 public:
  WorldPodReduction();
  int rank() const override { return m_rank; }
  int size() const override { return m_size; }
  void sum(Eigen::MatrixXd& m) const override;
  Eigen::MatrixXd gather_rows(const Eigen::MatrixXd& local) const override;

 private:
  int m_rank = 0, m_size = 1;
};

}  // namespace contactrom::rom::mpi
