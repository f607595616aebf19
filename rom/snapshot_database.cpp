#include <contactrom/rom/snapshot_database.hpp>

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <type_traits>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/rom/adaptive_training.hpp>
#include <contactrom/rom/hdf5_io.hpp>
#include <contactrom/rom/problem_record_io.hpp>

namespace contactrom::rom {
namespace {

/// Negative pressures down to this fraction of the largest |pressure| (at least 1)
/// are rounding; below it a database is refused.
constexpr double kNegativePressureTolerance = 1e-9;
/// Relative distance within which a stored parameter equals its training-set value.
constexpr double kParameterMatchTolerance = 1e-12;

// The HDF5 C API reports failure through negative return values and prints an
// error stack on stderr by default; rom/hdf5_io turns the printing off (the user
// gets our one-line message instead), checks shapes, types and sizes before
// reading, and translates failures into exceptions.
using hdf5::Handle;
using hdf5::write_dataset;
using hdf5::write_scalar_attribute;
using hdf5::write_string_attribute;
using hdf5::read_string_attribute;
using hdf5::has_attribute;
using Hdf5Failure = hdf5::Failure;


/// Reads an n_snap × width dataset into the columns of a width × n_snap matrix.
Eigen::MatrixXd read_matrix(hid_t file, const char* name, hsize_t expected_rows) {
  std::vector<double> buf;
  hsize_t rows = 0, cols = 0;
  const std::vector<hsize_t> dims = hdf5::dataset_shape(file, name);
  if (dims[0] != expected_rows || dims.size() != 2)
    throw hdf5::Refused(std::string("dataset /") + name + " has " + std::to_string(dims[0]) + " rows" +
                      (dims.size() != 2 ? " and rank 1" : "") + ", expected " + std::to_string(expected_rows) +
                      " (one per snapshot) and rank 2");
  hdf5::read_double_dataset(file, name, buf, rows, cols);
  return Eigen::Map<Eigen::MatrixXd>(buf.data(), static_cast<Eigen::Index>(cols), static_cast<Eigen::Index>(rows));
}

template <typename T>
std::vector<T> read_vector(hid_t file, const char* name, hsize_t expected) {
  std::vector<T> out;
  hsize_t rows = 0, cols = 0;
  // Shape first: the size of /status bounds every other dataset before any allocation.
  const std::vector<hsize_t> dims = hdf5::dataset_shape(file, name);
  if (dims.size() != 1 || dims[0] != expected)
    throw hdf5::Refused(std::string("dataset /") + name + " has shape (" + std::to_string(dims[0]) +
                      (dims.size() == 2 ? ", " + std::to_string(dims[1]) : std::string()) + "), expected (" +
                      std::to_string(expected) + ")");
  if constexpr (std::is_same_v<T, int>) hdf5::read_int_dataset(file, name, out, rows, cols);
  else hdf5::read_double_dataset(file, name, out, rows, cols);
  return out;
}

/// Refuses values that no offline run writes: non-finite numbers, negative
/// pressures (beyond rounding), negative counts or times, a training size < 1.
void validate_values(const SnapshotDatabase& db) {
  const auto first_bad = [](const Eigen::MatrixXd& m, const auto& bad) -> std::string {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i)
        if (bad(m(i, j)))
          return "row " + std::to_string(j) + ", column " + std::to_string(i) + " holds " + format_number(m(i, j));
    return "";
  };
  const auto not_finite = [](double v) { return !std::isfinite(v); };
  for (const auto& [name, m] : {std::pair<const char*, const Eigen::MatrixXd*>{"parameters", &db.parameters},
                                {"primal", &db.primal}, {"dual", &db.dual}})
    if (const std::string where = first_bad(*m, not_finite); !where.empty())
      throw hdf5::Refused(std::string("dataset /") + name + " " + where + ", expected finite numbers");
  // Contact pressures are >= 0; the FOM's dual QP may leave rounding-level negatives.
  const double scale = std::max(1.0, db.dual.size() ? db.dual.cwiseAbs().maxCoeff() : 0.0);
  if (const std::string where = first_bad(db.dual, [&](double v) { return v < -kNegativePressureTolerance * scale; });
      !where.empty())
    throw hdf5::Refused("dataset /dual " + where + ", expected contact pressures >= 0");
  for (size_t j = 0; j < db.time_s.size(); ++j)
    if (!(db.time_s[j] >= 0.0) || !std::isfinite(db.time_s[j]) || db.iterations[j] < 0 || db.pairing_iterations[j] < 0)
      throw hdf5::Refused("snapshot " + std::to_string(j) + " has a negative or non-finite time or iteration count");
  if (db.training_size < 1)
    throw hdf5::Refused("attribute training_size is " + std::to_string(db.training_size) + ", expected >= 1");
}

}  // namespace

std::vector<int> SnapshotDatabase::successful_snapshots() const {
  std::vector<int> out;
  for (int j = 0; j < num_snapshots(); ++j)
    if (j < static_cast<int>(status.size()) && status[j] == Status::Success) out.push_back(j);
  return out;
}

namespace {

/// The group /adaptive of an adaptive database (AdaptiveRecord): settings as
/// attributes (numbers as 64-bit reals, integers as 32-bit integers, words as
/// strings), one dataset per round column.
void write_adaptive(hid_t f, hid_t dcpl, const AdaptiveRecord& a) {
  Handle group(H5Gcreate2(f, "adaptive", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /adaptive");
  const hid_t g = group.id();
  for (const auto& [key, value] : a.settings) {
    if (const double* d = std::get_if<double>(&value)) {
      write_scalar_attribute(g, key.c_str(), H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, d);
    } else if (const long long* i = std::get_if<long long>(&value)) {
      const int v = static_cast<int>(*i);  // the table's integer ranges fit 32 bits
      write_scalar_attribute(g, key.c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, &v);
    } else {
      write_string_attribute(g, key.c_str(), option_text(value));
    }
  }
  write_scalar_attribute(g, "initial_snapshots", H5T_STD_I32LE, H5T_NATIVE_INT, &a.initial_snapshots);
  const hsize_t r = static_cast<hsize_t>(a.num_rounds());
  write_dataset(g, dcpl, "round_snapshots", H5T_STD_I32LE, H5T_NATIVE_INT, 1, r, 0, a.round_snapshots.data());
  write_dataset(g, dcpl, "round_added", H5T_STD_I32LE, H5T_NATIVE_INT, 1, r, 0, a.round_added.data());
  write_dataset(g, dcpl, "round_max_indicator", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, r, 0, a.round_max_indicator.data());
  write_dataset(g, dcpl, "round_mean_indicator", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, r, 0,
                a.round_mean_indicator.data());
  write_dataset(g, dcpl, "round_time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, r, 0, a.round_time_s.data());
}

/// Reads the group written by write_adaptive, checking what an adaptive run writes.
AdaptiveRecord read_adaptive(hid_t f) {
  if (H5Lexists(f, "adaptive", H5P_DEFAULT) <= 0)
    throw hdf5::Refused("training_kind is 'adaptive' but the group /adaptive is missing");
  Handle group(H5Gopen2(f, "adaptive", H5P_DEFAULT), H5Gclose, "group /adaptive");
  const hid_t g = group.id();
  AdaptiveRecord a;
  for (const OptionSpec& spec : adaptive_record_table().specs()) {
    const char* key = spec.key.c_str();
    OptionValue value;
    if (spec.type == OptionType::Number) value = hdf5::read_double_attribute(g, key);
    else if (spec.type == OptionType::Integer) value = static_cast<long long>(hdf5::read_int_attribute(g, key));
    else value = read_string_attribute(g, key);
    try {  // the declaration (a registered method is checked when the run continues)
      check_option_value(spec, value, "attribute /adaptive/" + spec.key);
    } catch (const InputError& e) {
      throw hdf5::Refused(e.what());
    }
    a.settings[spec.key] = value;
  }
  a.initial_snapshots = hdf5::read_int_attribute(g, "initial_snapshots");
  // Datasets by path from the file: the readers check their sizes against the file's.
  hsize_t rows = 0, cols = 0;
  const hsize_t r = hdf5::dataset_shape(f, "adaptive/round_snapshots")[0];
  hdf5::read_int_dataset(f, "adaptive/round_snapshots", a.round_snapshots, rows, cols);
  hdf5::read_int_dataset(f, "adaptive/round_added", a.round_added, rows, cols);
  hdf5::read_double_dataset(f, "adaptive/round_max_indicator", a.round_max_indicator, rows, cols);
  hdf5::read_double_dataset(f, "adaptive/round_mean_indicator", a.round_mean_indicator, rows, cols);
  hdf5::read_double_dataset(f, "adaptive/round_time_s", a.round_time_s, rows, cols);
  if (a.round_added.size() != r || a.round_max_indicator.size() != r || a.round_mean_indicator.size() != r ||
      a.round_time_s.size() != r)
    throw hdf5::Refused("the datasets of /adaptive differ in length; expected one value per round");
  if (a.initial_snapshots < 1)
    throw hdf5::Refused("attribute /adaptive/initial_snapshots is " + std::to_string(a.initial_snapshots) +
                        ", expected >= 1");
  for (hsize_t k = 0; k < r; ++k)
    if (a.round_snapshots[k] < 1 || a.round_added[k] < 0 || !(a.round_mean_indicator[k] >= 0.0) ||
        !(a.round_max_indicator[k] >= 0.0) || !(a.round_time_s[k] >= 0.0))
      throw hdf5::Refused("round " + std::to_string(k) + " of /adaptive holds a negative or undefined value");
  return a;
}

/// Every field of `db`, in write_database's layout; the primal snapshots by `write_primal`
/// (which does nothing when they were streamed into the file).
void write_fields(hid_t f, hid_t dcpl, const SnapshotDatabase& db, const std::function<void()>& write_primal) {
  const hsize_t n = static_cast<hsize_t>(db.num_snapshots());
  const int version = kDatabaseFormatVersion;
  write_scalar_attribute(f, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT, &version);
  write_string_attribute(f, "created_by", db.created_by);
  write_string_attribute(f, "training_kind", db.training_kind);
  write_scalar_attribute(f, "training_size", H5T_STD_I32LE, H5T_NATIVE_INT, &db.training_size);
  write_string_attribute(f, "status_names", "success,no_convergence,numerical_issue,invalid_input");
  write_scalar_attribute(f, "setup_time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &db.setup_time_s);
  write_scalar_attribute(f, "wall_time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &db.wall_time_s);
  write_scalar_attribute(f, "threads", H5T_STD_I32LE, H5T_NATIVE_INT, &db.threads);

  // Column-major width × n_snap == row-major n_snap × width: no transposition.
  write_dataset(f, dcpl, "parameters", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n,
                static_cast<hsize_t>(db.parameters.rows()), db.parameters.data());
  write_primal();
  write_dataset(f, dcpl, "dual", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n, static_cast<hsize_t>(db.dual.rows()),
                db.dual.data());
  std::vector<int> status(db.status.size());
  for (size_t j = 0; j < status.size(); ++j) status[j] = static_cast<int>(db.status[j]);
  write_dataset(f, dcpl, "status", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, status.data());
  write_dataset(f, dcpl, "iterations", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, db.iterations.data());
  write_dataset(f, dcpl, "pairing_iterations", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, db.pairing_iterations.data());
  write_dataset(f, dcpl, "time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, n, 0, db.time_s.data());
  write_problem_record(f, dcpl, db.problem);
  if (db.training_kind == "adaptive") write_adaptive(f, dcpl, db.adaptive);
}

/// Reads single primal snapshots (dataset rows) of the files of a database left on disk.
class PrimalRowReader {
 public:
  explicit PrimalRowReader(const SnapshotDatabase& db) : m_db(db) {
    for (const std::string& path : db.primal_files)
      m_files.push_back(std::make_unique<Handle>(hdf5::open_file(path, "database", "contactrom offline"), H5Fclose,
                                                 "the file structure"));
  }
  /// Primal snapshot j of the database.
  void read(int j, Eigen::VectorXd& u) const {
    const SnapshotDatabase::PrimalRef& ref = m_db.primal_refs.at(static_cast<size_t>(j));
    const std::string& path = m_db.primal_files.at(static_cast<size_t>(ref.file));
    u.resize(m_db.num_dofs());
    try {
      Handle set(H5Dopen2(m_files[static_cast<size_t>(ref.file)]->id(), "primal", H5P_DEFAULT), H5Dclose, "dataset /primal");
      Handle space(H5Dget_space(set.id()), H5Sclose, "dataset /primal");
      const hsize_t start[2] = {static_cast<hsize_t>(ref.row), 0}, count[2] = {1, static_cast<hsize_t>(u.size())};
      hdf5::check(H5Sselect_hyperslab(space.id(), H5S_SELECT_SET, start, nullptr, count, nullptr), "dataset /primal");
      Handle memory(H5Screate_simple(2, count, nullptr), H5Sclose, "dataset /primal");
      hdf5::check(H5Dread(set.id(), H5T_NATIVE_DOUBLE, memory.id(), space.id(), H5P_DEFAULT, u.data()), "dataset /primal");
    } catch (const Hdf5Failure& e) {
      throw InputError("database '" + path + "' is truncated or corrupt (HDF5 cannot read " + e.what() + ")");
    }
    for (Eigen::Index i = 0; i < u.size(); ++i)
      if (!std::isfinite(u(i)))
        throw InputError("database '" + path + "' is not a valid contactrom database: dataset /primal row " +
                         std::to_string(ref.row) + ", column " + std::to_string(i) + " holds " + format_number(u(i)) +
                         ", expected finite numbers");
  }

 private:
  const SnapshotDatabase& m_db;
  std::vector<std::unique_ptr<Handle>> m_files;
};

}  // namespace

struct DatabaseWriter::Impl {
  std::string path, label;
  int num_dofs = 0, num_snapshots = 0;
  std::mutex mutex;
  bool failed = false;
  std::unique_ptr<Handle> file, dcpl, primal;
};

DatabaseWriter::DatabaseWriter(std::string path, int num_dofs, int num_snapshots, std::string label)
    : m_impl(std::make_unique<Impl>()) {
  m_impl->path = std::move(path);
  m_impl->label = label.empty() ? m_impl->path : std::move(label);
  m_impl->num_dofs = num_dofs;
  m_impl->num_snapshots = num_snapshots;
  // The space of the snapshots is reserved first: a disk that cannot hold them is
  // refused here, before libhdf5 (which may crash closing a file it failed to write).
  {
    const int fd = ::open(m_impl->path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const off_t bytes = static_cast<off_t>(num_dofs) * num_snapshots * static_cast<off_t>(sizeof(double)) + (off_t{1} << 20);
    const int err = fd < 0 ? errno : ::posix_fallocate(fd, 0, bytes);
    if (fd >= 0) ::close(fd);
    if (err != 0) {
      std::remove(m_impl->path.c_str());
      throw WriteFailure("cannot write database '" + m_impl->label + "': " + std::strerror(err));
    }
  }
  hdf5::silence();
  try {
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation properties");
    hdf5::check(H5Pset_obj_track_times(fcpl.id(), false), "file creation properties");
    Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access properties");
    // The 1.8 format with checksummed metadata, as hdf5::create_memory_file().
    hdf5::check(H5Pset_libver_bounds(fapl.id(), H5F_LIBVER_V18, H5F_LIBVER_V18), "file access properties");
    m_impl->file = std::make_unique<Handle>(H5Fcreate(m_impl->path.c_str(), H5F_ACC_TRUNC, fcpl.id(), fapl.id()),
                                            H5Fclose, "file creation");
    m_impl->dcpl = std::make_unique<Handle>(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "dataset creation properties");
    hdf5::check(H5Pset_obj_track_times(m_impl->dcpl->id(), false), "dataset creation properties");
    Handle primal_dcpl(H5Pcopy(m_impl->dcpl->id()), H5Pclose, "dataset creation properties");
    // Allocated whole now (its declared size is then within the file's), never filled:
    // every row is written once.
    hdf5::check(H5Pset_layout(primal_dcpl.id(), H5D_CONTIGUOUS), "dataset creation properties");
    hdf5::check(H5Pset_alloc_time(primal_dcpl.id(), H5D_ALLOC_TIME_EARLY), "dataset creation properties");
    hdf5::check(H5Pset_fill_time(primal_dcpl.id(), H5D_FILL_TIME_NEVER), "dataset creation properties");
    const hsize_t dims[2] = {static_cast<hsize_t>(num_snapshots), static_cast<hsize_t>(num_dofs)};
    Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose, "dataset /primal");
    m_impl->primal = std::make_unique<Handle>(
        H5Dcreate2(m_impl->file->id(), "primal", H5T_IEEE_F64LE, space.id(), H5P_DEFAULT, primal_dcpl.id(), H5P_DEFAULT),
        H5Dclose, "dataset /primal");
  } catch (const Hdf5Failure& e) {
    throw InputError("cannot write database '" + m_impl->label + "': HDF5 failed on " + e.what());
  }
}

DatabaseWriter::~DatabaseWriter() {
  // After a failed write (disk full) libhdf5 may crash flushing the file on close:
  // the identifiers are left open (the process reports the error and the caller
  // removes the file).
  if (m_impl && m_impl->failed) {
    (void)m_impl->primal.release();
    (void)m_impl->dcpl.release();
    (void)m_impl->file.release();
  }
}

void DatabaseWriter::write_primal(int j, const Eigen::VectorXd& u) {
  std::lock_guard<std::mutex> lock(m_impl->mutex);
  if (!m_impl->primal || j < 0 || j >= m_impl->num_snapshots || u.size() != m_impl->num_dofs)
    throw std::invalid_argument("DatabaseWriter::write_primal: snapshot index or size out of range");
  if (m_impl->failed) throw WriteFailure("cannot write database '" + m_impl->label + "': an earlier write failed (disk full?)");
  hdf5::silence();  // per thread in a thread-safe libhdf5: the workers write
  try {
    Handle space(H5Dget_space(m_impl->primal->id()), H5Sclose, "dataset /primal");
    const hsize_t start[2] = {static_cast<hsize_t>(j), 0}, count[2] = {1, static_cast<hsize_t>(u.size())};
    hdf5::check(H5Sselect_hyperslab(space.id(), H5S_SELECT_SET, start, nullptr, count, nullptr), "dataset /primal");
    Handle memory(H5Screate_simple(2, count, nullptr), H5Sclose, "dataset /primal");
    if (u.size() > 0)
      hdf5::check(H5Dwrite(m_impl->primal->id(), H5T_NATIVE_DOUBLE, memory.id(), space.id(), H5P_DEFAULT, u.data()),
                  "dataset /primal");
  } catch (const Hdf5Failure& e) {
    m_impl->failed = true;
    throw WriteFailure("cannot write database '" + m_impl->label + "': HDF5 failed on " + e.what() + " (disk full?)");
  }
}

void DatabaseWriter::finish(const SnapshotDatabase& db) {
  std::lock_guard<std::mutex> lock(m_impl->mutex);
  if (db.num_snapshots() != m_impl->num_snapshots || db.num_dofs() != m_impl->num_dofs)
    throw std::invalid_argument("DatabaseWriter::finish: the database's sizes differ from the file's");
  try {
    write_fields(m_impl->file->id(), m_impl->dcpl->id(), db, [] {});
    // The checksum of /primal, whose rows were written in any order: read back in
    // blocks of rows, in file order (memory: one block).
    {
      const hsize_t rows = static_cast<hsize_t>(m_impl->num_snapshots), cols = static_cast<hsize_t>(m_impl->num_dofs);
      hdf5::DataChecksum sum(static_cast<std::size_t>(rows * cols * sizeof(double)));
      const hsize_t block = std::max<hsize_t>(1, (hsize_t{1} << 22) / std::max<hsize_t>(cols, 1));  // ≈ 32 MB
      std::vector<double> buffer;
      Handle space(H5Dget_space(m_impl->primal->id()), H5Sclose, "dataset /primal");
      for (hsize_t r0 = 0; r0 < rows && cols > 0; r0 += block) {
        const hsize_t start[2] = {r0, 0}, count[2] = {std::min(block, rows - r0), cols};
        buffer.resize(static_cast<size_t>(count[0] * cols));
        hdf5::check(H5Sselect_hyperslab(space.id(), H5S_SELECT_SET, start, nullptr, count, nullptr), "dataset /primal");
        Handle memory(H5Screate_simple(2, count, nullptr), H5Sclose, "dataset /primal");
        hdf5::check(H5Dread(m_impl->primal->id(), H5T_NATIVE_DOUBLE, memory.id(), space.id(), H5P_DEFAULT, buffer.data()),
                    "dataset /primal");
        sum.add(buffer.data(), buffer.size() * sizeof(double));
      }
      hdf5::write_checksum_attribute(m_impl->primal->id(), sum.value(), "dataset /primal");
    }
    m_impl->primal->close("dataset /primal");
    m_impl->primal.reset();
    m_impl->file->close("file close");
  } catch (const Hdf5Failure& e) {
    m_impl->failed = true;
    throw WriteFailure("cannot write database '" + m_impl->label + "': HDF5 failed on " + e.what() + " (disk full?)");
  }
}

void remove_primal_files(const SnapshotDatabase& db) {
  for (const std::string& path : db.primal_files) std::remove(path.c_str());
}

namespace {
bool is_training_kind(const std::string& kind) {
  return kind == "train" || kind == "level" || kind == "list" || kind == "adaptive";
}
}  // namespace

void check_training_kind(const std::string& kind) {
  if (!is_training_kind(kind))
    throw InputError("training kind " + quoted(kind, 200) + " unknown; expected 'train', 'level', 'list' or 'adaptive'");
}

void write_database(const std::string& path, const SnapshotDatabase& db) {
  check_training_kind(db.training_kind);
  const hsize_t n = static_cast<hsize_t>(db.num_snapshots());
  const hsize_t stored = db.primal_in_memory() ? static_cast<hsize_t>(db.primal.cols()) : db.primal_refs.size();
  if (db.dual.cols() != db.parameters.cols() || stored != n || db.status.size() != n || db.iterations.size() != n ||
      db.pairing_iterations.size() != n || db.time_s.size() != n)
    throw std::invalid_argument("write_database: inconsistent snapshot counts");
  if (db.problem.lifting_terms.rows() != db.primal.rows())
    throw std::invalid_argument("write_database: lifting terms and snapshots differ in size");
  if (!db.primal_in_memory()) {  // snapshot by snapshot through a temporary file
    check_output_path(path);
    const std::string tmp = temporary_path_for(path);
    try {
      {
        const PrimalRowReader reader(db);
        DatabaseWriter writer(tmp, db.num_dofs(), db.num_snapshots(), path);
        Eigen::VectorXd u;
        for (int j = 0; j < db.num_snapshots(); ++j) {
          reader.read(j, u);
          writer.write_primal(j, u);
        }
        writer.finish(db);
      }
      commit_temporary(tmp, path);
    } catch (...) {
      std::remove(tmp.c_str());
      throw;
    }
    return;
  }
  try {
    hdf5::write_file(path, [&db](hid_t f, hid_t dcpl) {
      write_fields(f, dcpl, db, [&] {
        write_dataset(f, dcpl, "primal", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, static_cast<hsize_t>(db.num_snapshots()),
                      static_cast<hsize_t>(db.primal.rows()), db.primal.data());
      });
    });
  } catch (const Hdf5Failure& e) {
    throw InputError("cannot write database " + quoted(path, 200) + ": HDF5 failed on " + e.what());
  }
}

namespace {

/// Columns `columns` (all if empty) of a matrix in memory.
class SelectedColumns : public SnapshotBlocks {
 public:
  SelectedColumns(const Eigen::MatrixXd& m, std::vector<int> columns) : m_matrix(m), m_columns(std::move(columns)) {
    if (m_columns.empty())
      for (Eigen::Index j = 0; j < m.cols(); ++j) m_columns.push_back(static_cast<int>(j));
  }
  Eigen::Index rows() const override { return m_matrix.rows(); }
  Eigen::Index cols() const override { return static_cast<Eigen::Index>(m_columns.size()); }
  void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const override {
    out.resize(count, cols());
    for (Eigen::Index c = 0; c < cols(); ++c) out.col(c) = m_matrix.col(m_columns[static_cast<size_t>(c)]).segment(first, count);
  }

 private:
  const Eigen::MatrixXd& m_matrix;
  std::vector<int> m_columns;
};

/// Columns on disk, possibly in several files: one DatasetBlocks per file, its
/// columns scattered into place.
class ReferencedColumns : public SnapshotBlocks {
 public:
  ReferencedColumns(const SnapshotDatabase& db, std::vector<int> columns) : m_rows(db.num_dofs()) {
    if (columns.empty())
      for (int j = 0; j < db.num_snapshots(); ++j) columns.push_back(j);
    std::vector<std::vector<int>> rows(db.primal_files.size());
    for (int j : columns) {
      const SnapshotDatabase::PrimalRef& ref = db.primal_refs.at(static_cast<size_t>(j));
      m_place.push_back({ref.file, static_cast<int>(rows.at(static_cast<size_t>(ref.file)).size())});
      rows[static_cast<size_t>(ref.file)].push_back(ref.row);
    }
    for (size_t f = 0; f < rows.size(); ++f)
      m_files.push_back(rows[f].empty() ? nullptr : std::make_unique<DatasetBlocks>(db.primal_files[f], "primal", rows[f]));
  }
  Eigen::Index rows() const override { return m_rows; }
  Eigen::Index cols() const override { return static_cast<Eigen::Index>(m_place.size()); }
  void read_rows(Eigen::Index first, Eigen::Index count, Eigen::MatrixXd& out) const override {
    std::vector<Eigen::MatrixXd> parts(m_files.size());
    for (size_t f = 0; f < m_files.size(); ++f)
      if (m_files[f]) m_files[f]->read_rows(first, count, parts[f]);
    out.resize(count, cols());
    for (size_t c = 0; c < m_place.size(); ++c)
      out.col(static_cast<Eigen::Index>(c)) = parts[static_cast<size_t>(m_place[c].first)].col(m_place[c].second);
  }

 private:
  Eigen::Index m_rows;
  std::vector<std::unique_ptr<DatasetBlocks>> m_files;
  std::vector<std::pair<int, int>> m_place;  // (file, column among that file's)
};

}  // namespace

std::unique_ptr<SnapshotBlocks> primal_blocks(const SnapshotDatabase& db, const std::vector<int>& columns) {
  if (db.primal_in_memory()) return std::make_unique<SelectedColumns>(db.primal, columns);
  // One file read in order: a single DatasetBlocks.
  bool identity = db.primal_files.size() == 1;
  for (int j = 0; identity && j < db.num_snapshots(); ++j) identity = db.primal_refs[static_cast<size_t>(j)].row == j;
  if (identity) return std::make_unique<DatasetBlocks>(db.primal_files[0], "primal", columns);
  return std::make_unique<ReferencedColumns>(db, columns);
}

SnapshotDatabase read_database(const std::string& path, bool load_primal) {
  Handle file(hdf5::open_file(path, "database", "contactrom offline"), H5Fclose, "the file structure");
  SnapshotDatabase db;
  try {
    const hid_t f = file.id();
    if (has_attribute(f, "kind") && read_string_attribute(f, "kind") == kReducedModelKind)
      throw InputError("database " + quoted(path, 200) + " is a reduced-model file (contactrom reduce), not a snapshot "
                       "database; a reduced model is read with --rom (contactrom query), a database with --db");
    if (!has_attribute(f, "format_version"))
      throw InputError("database " + quoted(path, 200) + " has no format_version attribute; not a contactrom database");
    const int version = hdf5::read_int_attribute(f, "format_version");
    if (version != kDatabaseFormatVersion)
      throw InputError("database " + quoted(path, 200) + " has format_version " + std::to_string(version) +
                       ", but this contactrom reads version " + std::to_string(kDatabaseFormatVersion) + "; rebuild it with contactrom offline");
    db.created_by = read_string_attribute(f, "created_by");
    db.training_kind = read_string_attribute(f, "training_kind");
    db.training_size = hdf5::read_int_attribute(f, "training_size");
    if (has_attribute(f, "setup_time_s"))
      db.setup_time_s = hdf5::read_double_attribute(f, "setup_time_s");
    if (has_attribute(f, "wall_time_s"))
      db.wall_time_s = hdf5::read_double_attribute(f, "wall_time_s");
    if (has_attribute(f, "threads")) db.threads = hdf5::read_int_attribute(f, "threads");

    std::vector<int> status;
    hsize_t n = 0, cols = 0;
    if (hdf5::dataset_shape(f, "status").size() != 1) throw hdf5::Refused("dataset /status is not one-dimensional");
    hdf5::read_int_dataset(f, "status", status, n, cols);
    db.parameters = read_matrix(f, "parameters", n);
    if (load_primal) {
      db.primal = read_matrix(f, "primal", n);
    } else {  // shape only; DatasetBlocks checks the values as it reads them
      const std::vector<hsize_t> dims = hdf5::dataset_shape(f, "primal");
      if (dims.size() != 2 || dims[0] != n)
        throw hdf5::Refused("dataset /primal has " + std::to_string(dims[0]) + " rows, expected " + std::to_string(n) +
                            " (one per snapshot) and rank 2");
      if (dims[1] * n > hdf5::file_size(f) / sizeof(double))
        throw hdf5::Refused("dataset /primal declares more bytes than the file holds");
      db.primal.resize(static_cast<Eigen::Index>(dims[1]), 0);
      db.primal_files = {path};
      for (hsize_t j = 0; j < n; ++j) db.primal_refs.push_back({0, static_cast<int>(j)});
    }
    db.dual = read_matrix(f, "dual", n);
    db.iterations = read_vector<int>(f, "iterations", n);
    db.pairing_iterations = read_vector<int>(f, "pairing_iterations", n);
    db.time_s = read_vector<double>(f, "time_s", n);
    for (int s : status) {
      if (s < 0 || s > static_cast<int>(Status::InvalidInput))
        throw hdf5::Refused("dataset /status holds the unknown status code " + std::to_string(s));
      db.status.push_back(static_cast<Status>(s));
    }
    db.problem = (read_problem_record(f, static_cast<hsize_t>(db.dual.rows()),
                                               static_cast<hsize_t>(db.primal.rows())));
    if (db.parameters.rows() != static_cast<Eigen::Index>(db.problem.param_names.size()))
      throw hdf5::Refused("dataset /parameters has " + std::to_string(db.parameters.rows()) +
                        " columns but param_names lists " + std::to_string(db.problem.param_names.size()));
    if (!is_training_kind(db.training_kind))
      throw hdf5::Refused("attribute training_kind is " + quoted(db.training_kind, 200) +
                          ", expected 'train', 'level', 'list' or 'adaptive'");
    if (db.training_kind == "adaptive") db.adaptive = read_adaptive(f);
    validate_values(db);
    file.close("file close");
  } catch (const hdf5::Refused& e) {
    throw InputError("database " + quoted(path, 200) + " is not a valid contactrom database: " + e.what());
  } catch (const Hdf5Failure& e) {
    throw InputError("database " + quoted(path, 200) + " is truncated or corrupt (HDF5 cannot read " + e.what() + ")");
  }
  return db;
}

void check_database(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  check_database_problem(db, problem, path);
  const std::string selector = problem.definition().training.selector();
  if (db.training_kind != selector && db.training_kind != "adaptive")
    throw InputError("database " + quoted(path, 200) + " selects its training set by " + quoted(db.training_kind, 200) + ", but " +
                     problem.name() + " uses " + quoted(selector, 200));
  check_training_set(db, problem, path);
}

void check_database_problem(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  if (db.problem.name != problem.name())
    throw InputError("database " + quoted(path, 200) + " was built for problem " + quoted(db.problem.name, 200) + ", not " + quoted(problem.name(), 200));
  if (db.problem.fingerprint != problem.fingerprint()) {
    // The fingerprint hashes the problem file's text and the mesh: say which changed.
    const bool text_changed = !db.problem.text.empty() && db.problem.text != problem.definition().text;
    throw InputError("database " + quoted(path, 200) + " was built for mesh fingerprint " + db.problem.fingerprint +
                     " but the current " + problem.name() + " mesh is " + problem.fingerprint() + " (" +
                     (text_changed ? "the problem file's text differs from the copy the database stores, comments and "
                                     "spacing included"
                                   : "the mesh differs: the .geo file, the refinement or gmsh's node order") +
                     "); rebuild it with contactrom offline");
  }
  if (db.num_dofs() != problem.num_dofs() || db.num_constraints() != problem.contact().num_constraints() ||
      db.parameters.rows() != problem.num_params())
    throw InputError("database " + quoted(path, 200) + " holds " + std::to_string(db.num_dofs()) + " dofs, " +
                     std::to_string(db.num_constraints()) + " contact rows and " +
                     std::to_string(db.parameters.rows()) + " parameters, but " + problem.name() + " has " +
                     std::to_string(problem.num_dofs()) + ", " + std::to_string(problem.contact().num_constraints()) +
                     " and " + std::to_string(problem.num_params()));
}

void check_training_set(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  for (int j = 0; j < db.num_snapshots(); ++j) {
    try {
      problem.check_param(db.parameter(j));
    } catch (const InputError& e) {
      throw InputError("database " + quoted(path, 200) + " dataset /parameters row " + std::to_string(j) + ": " + e.what());
    }
  }
  const bool adaptive = db.training_kind == "adaptive";
  const std::string kind = adaptive ? problem.definition().training.selector() : db.training_kind;
  const std::string option = (adaptive ? "an adaptive run started from " : "") +
                             std::string(kind == "level" ? "level " : kind == "list" ? "the list of " : "training size ");
  std::vector<fom::Param> expected;
  try {
    expected = fom::training_set(problem, db.training_size);
  } catch (const InputError& e) {
    throw InputError("database " + quoted(path, 200) + " attribute training_size: " + e.what());
  }
  const auto mismatch = [&](const std::string& why, const std::string& expected = "the snapshots of that training set") {
    return InputError("database " + quoted(path, 200) + " claims " + option + std::to_string(db.training_size) + " of " +
                      problem.name() + ", but " + why + "; expected " + expected);
  };
  if (adaptive) {
    const AdaptiveRecord& a = db.adaptive;
    int held = a.initial_snapshots;
    for (int k = 0; k < a.num_rounds(); ++k) {
      if (a.round_snapshots[k] != held)
        throw mismatch("its round " + std::to_string(k) + " evaluated " + std::to_string(a.round_snapshots[k]) +
                       " snapshots where the earlier rounds leave " + std::to_string(held));
      held += a.round_added[k];
    }
    if (held != db.num_snapshots() || a.initial_snapshots != static_cast<int>(expected.size()))
      throw mismatch("its rounds account for " + std::to_string(held) + " snapshots from " +
                     std::to_string(a.initial_snapshots) + " initial ones, and it holds " +
                     std::to_string(db.num_snapshots()) + " from " + std::to_string(expected.size()));
  } else if (static_cast<int>(expected.size()) != db.num_snapshots()) {
    if (db.num_snapshots() < static_cast<int>(expected.size()))  // a part (offline --part k/K), or an interrupted append
      throw mismatch("it holds " + std::to_string(db.num_snapshots()) + " of its " + std::to_string(expected.size()) +
                         " snapshots (a part of it)",
                     "the whole set: complete it with contactrom offline --append, or join the parts with contactrom merge");
    throw mismatch("it holds " + std::to_string(db.num_snapshots()) + " snapshots instead of " +
                   std::to_string(expected.size()));
  }
  for (int j = 0; j < static_cast<int>(expected.size()); ++j) {
    const double scale = std::max(1.0, expected[j].cwiseAbs().maxCoeff());
    if ((db.parameter(j) - expected[j]).cwiseAbs().maxCoeff() > kParameterMatchTolerance * scale)
      throw mismatch("its snapshot " + std::to_string(j) + " is not at the training parameter of that set");
  }
}

std::unique_ptr<fom::Problem> rebuild_database_problem(const SnapshotDatabase& db, const std::string& path) {
  return rebuild_problem(db.problem, "database " + quoted(path, 200));
}

std::unique_ptr<fom::Problem> problem_from_database(const SnapshotDatabase& db, const std::string& path) {
  auto problem = rebuild_database_problem(db, path);
  check_database(db, *problem, path);
  return problem;
}

std::vector<fom::Param> database_training_set(const SnapshotDatabase& db, const fom::Problem& problem) {
  if (db.training_kind == "adaptive") {
    std::vector<fom::Param> out;
    for (int j = 0; j < db.num_snapshots(); ++j) out.push_back(db.parameter(j));
    return out;
  }
  return fom::training_set(problem, db.training_size);
}

std::vector<fom::Param> database_validation_set(const SnapshotDatabase& db, const fom::Problem& problem) {
  if (db.training_kind == "adaptive")
    throw InputError("database of " + problem.name() + " was built adaptively and has no validation set of its own; "
                     "expected a parameter list (online --validation --params FILE.csv)");
  return fom::validation_set(problem, db.training_size);
}

}  // namespace contactrom::rom
