#include <contactrom/rom/snapshot_blocks.hpp>

#include <hdf5.h>

#include <cmath>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/rom/hdf5_io.hpp>

namespace contactrom::rom {

Eigen::MatrixXd SnapshotBlocks::read_all() const {
  Eigen::MatrixXd out;
  read_rows(0, rows(), out);
  return out;
}

void MatrixBlocks::read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const {
  out = m_matrix.middleRows(first, count);
}

namespace {

using hdf5::Handle;

}  // namespace

DatasetBlocks::DatasetBlocks(std::string path, std::string dataset, std::vector<int> columns)
    : m_path(std::move(path)), m_dataset(std::move(dataset)), m_columns(std::move(columns)) {
  Handle file(hdf5::open_file(m_path, "database", "contactrom offline"), H5Fclose, "the file structure");
  std::vector<hsize_t> dims;
  try {
    dims = hdf5::dataset_shape(file.id(), m_dataset.c_str());
  } catch (const hdf5::Failure& e) {
    throw InputError("database '" + m_path + "' cannot be read: " + e.what());
  }
  if (dims.size() != 2) throw InputError("database '" + m_path + "' dataset /" + m_dataset + " is not two-dimensional");
  m_stored = static_cast<Eigen::Index>(dims[0]);
  m_rows = static_cast<Eigen::Index>(dims[1]);
  if (m_columns.empty()) {
    for (Eigen::Index j = 0; j < m_stored; ++j) m_columns.push_back(static_cast<int>(j));
  } else {
    for (size_t c = 0; c < m_columns.size(); ++c) {
      if (m_columns[c] < 0 || m_columns[c] >= m_stored)
        throw InputError("database '" + m_path + "' dataset /" + m_dataset + " has no snapshot " +
                         std::to_string(m_columns[c]));
      m_all = m_all && m_columns[c] == static_cast<int>(c);
    }
    m_all = m_all && static_cast<Eigen::Index>(m_columns.size()) == m_stored;
  }
}

void DatasetBlocks::read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const {
  out.resize(count, cols());
  if (count == 0 || cols() == 0) return;
  const std::string what = "dataset /" + m_dataset;
  try {
    hdf5::silence();
    Handle file(H5Fopen(m_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "the file structure");
    Handle set(H5Dopen2(file.id(), m_dataset.c_str(), H5P_DEFAULT), H5Dclose, what);
    Handle space(H5Dget_space(set.id()), H5Sclose, what);
    // Every stored snapshot's dofs [first, first + count): in memory a row-major
    // m_stored × count array, i.e. the column-major count × m_stored block.
    const hsize_t start[2] = {0, static_cast<hsize_t>(first)};
    const hsize_t size[2] = {static_cast<hsize_t>(m_stored), static_cast<hsize_t>(count)};
    hdf5::check(H5Sselect_hyperslab(space.id(), H5S_SELECT_SET, start, nullptr, size, nullptr), what);
    Handle memory(H5Screate_simple(2, size, nullptr), H5Sclose, what);
    Eigen::MatrixXd block;
    Eigen::MatrixXd& target = m_all ? out : block;
    target.resize(count, m_stored);
    hdf5::check(H5Dread(set.id(), H5T_NATIVE_DOUBLE, memory.id(), space.id(), H5P_DEFAULT, target.data()), what);
    if (!m_all)
      for (Eigen::Index c = 0; c < cols(); ++c) out.col(c) = block.col(m_columns[static_cast<size_t>(c)]);
    file.close("file close");
  } catch (const hdf5::Failure& e) {
    throw InputError("database '" + m_path + "' is truncated or corrupt (HDF5 cannot read " + e.what() + ")");
  }
  for (Eigen::Index c = 0; c < out.cols(); ++c)
    for (Eigen::Index i = 0; i < count; ++i)
      if (!std::isfinite(out(i, c)))
        throw InputError("database '" + m_path + "' is not a valid contactrom database: dataset /" + m_dataset +
                         " row " + std::to_string(m_columns[static_cast<size_t>(c)]) + ", column " +
                         std::to_string(first + i) + " holds " + format_number(out(i, c)) + ", expected finite numbers");
}

std::pair<Eigen::Index, Eigen::Index> row_share(Eigen::Index n, int rank, int size) {
  return {n * rank / size, n * (rank + 1) / size};
}

}  // namespace contactrom::rom
