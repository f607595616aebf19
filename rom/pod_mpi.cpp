#include <contactrom/rom/pod_mpi.hpp>

#include <mpi.h>

#include <vector>

namespace contactrom::rom::mpi {

WorldPodReduction::WorldPodReduction() {
  MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m_size);
}

void WorldPodReduction::sum(Eigen::MatrixXd& m) const {
  // In slices: MPI counts are ints.
  constexpr Eigen::Index kSlice = Eigen::Index{1} << 26;
  for (Eigen::Index first = 0; first < m.size(); first += kSlice) {
    const int count = static_cast<int>(std::min(kSlice, m.size() - first));
    MPI_Allreduce(MPI_IN_PLACE, m.data() + first, count, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  }
}

Eigen::MatrixXd WorldPodReduction::gather_rows(const Eigen::MatrixXd& local) const {
  // Column by column: each column of the result is the ranks' column pieces in rank order.
  int rows = static_cast<int>(local.rows());
  std::vector<int> counts(static_cast<size_t>(m_size)), displs(static_cast<size_t>(m_size));
  MPI_Gather(&rows, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  int total = 0;
  for (int r = 0; r < m_size; ++r) displs[static_cast<size_t>(r)] = total, total += counts[static_cast<size_t>(r)];
  Eigen::MatrixXd all(m_rank == 0 ? total : 0, m_rank == 0 ? local.cols() : 0);
  for (Eigen::Index c = 0; c < local.cols(); ++c)
    MPI_Gatherv(local.col(c).data(), rows, MPI_DOUBLE, m_rank == 0 ? all.col(c).data() : nullptr, counts.data(),
                displs.data(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return all;
}

}  // namespace contactrom::rom::mpi
