#pragma once
/// \file snapshot_blocks.hpp
/// \brief A snapshot matrix read by blocks of rows, so that a POD (rom/pod.hpp) can
/// work through a matrix that does not fit in memory.
///
/// The snapshot matrix \f$ X \in \mathbb{R}^{n\times m} \f$ holds one snapshot per
/// column. A source hands out any range of its rows as a dense block (rows × m);
/// the POD's method of snapshots reads \f$ X \f$ a few times from top to bottom, a
/// block of about PodOptions::block_bytes at a time, and never holds it whole.
///
/// Sources: MatrixBlocks (a matrix in memory), DatasetBlocks (the `/primal` dataset
/// of a snapshot database on disk, read as HDF5 hyperslabs), RowRangeBlocks (a range
/// of another source's rows: the share of one MPI rank).
#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

namespace contactrom::rom {

/// \brief A snapshot matrix read by blocks of rows; see the file comment.
class SnapshotBlocks {
 public:
  virtual ~SnapshotBlocks() = default;
  /// Number of rows n (dofs).
  virtual Eigen::Index rows() const = 0;
  /// Number of columns m (snapshots).
  virtual Eigen::Index cols() const = 0;
  /// \brief Rows [first, first + count) of the matrix into `out` (count × cols()).
  /// \throws InputError if the data cannot be read or are not finite.
  virtual void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const = 0;
  /// The whole matrix (rows() × cols()).
  Eigen::MatrixXd read_all() const;
};

/// \brief A matrix in memory (not copied: it must outlive the source).
class MatrixBlocks : public SnapshotBlocks {
 public:
  explicit MatrixBlocks(const Eigen::MatrixXd& matrix) : m_matrix(matrix) {}
  Eigen::Index rows() const override { return m_matrix.rows(); }
  Eigen::Index cols() const override { return m_matrix.cols(); }
  void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const override;

 private:
  const Eigen::MatrixXd& m_matrix;
};

/// \brief Rows [first, first + count) of another source (which must outlive it).
class RowRangeBlocks : public SnapshotBlocks {
 public:
  RowRangeBlocks(const SnapshotBlocks& source, Eigen::Index first, Eigen::Index count)
      : m_source(source), m_first(first), m_count(count) {}
  Eigen::Index rows() const override { return m_count; }
  Eigen::Index cols() const override { return m_source.cols(); }
  void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const override {
    m_source.read_rows(m_first + first, count, out);
  }

 private:
  const SnapshotBlocks& m_source;
  Eigen::Index m_first, m_count;
};

/// \brief A 2-D float64 dataset of an HDF5 file stored as one snapshot per dataset
/// row (`/primal` of a snapshot database: n_snap × n_dofs), seen as the n_dofs × m
/// matrix of the selected snapshots. Each read_rows() opens the file, reads the
/// hyperslab of those dofs for every stored snapshot and keeps the selected ones,
/// in the order given.
class DatasetBlocks : public SnapshotBlocks {
 public:
  /// \param path HDF5 file, \param dataset name of the dataset, \param columns the
  /// dataset rows (snapshots) to use, in order; empty: all of them.
  /// \throws InputError naming `path` if the dataset is missing or not 2-D, or a
  ///   column index is out of range.
  DatasetBlocks(std::string path, std::string dataset, std::vector<int> columns = {});
  Eigen::Index rows() const override { return m_rows; }
  Eigen::Index cols() const override { return static_cast<Eigen::Index>(m_columns.size()); }
  void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const override;

 private:
  std::string m_path, m_dataset;
  std::vector<int> m_columns;
  Eigen::Index m_rows = 0, m_stored = 0;  // dofs, stored snapshots
  bool m_all = true;                      // every stored snapshot, in order
};

/// \brief The part [begin, end) of `n` rows that rank `rank` of `size` handles
/// (contiguous, balanced: begin = ⌊rank·n/size⌋).
std::pair<Eigen::Index, Eigen::Index> row_share(Eigen::Index n, int rank, int size);

}  // namespace contactrom::rom
