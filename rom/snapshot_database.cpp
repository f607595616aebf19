#include "rom/snapshot_database.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "fom/atomic_file.hpp"
#include "rom/hdf5_io.hpp"

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
using hdf5::check;
using hdf5::write_dataset;
using hdf5::write_scalar_attribute;
using hdf5::write_string_attribute;
using hdf5::read_string_attribute;
using hdf5::has_attribute;
using Hdf5Failure = hdf5::Failure;

void silence_hdf5() { hdf5::silence(); }

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

std::string format_value(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// Refuses values that no offline run writes: non-finite numbers, negative
/// pressures (beyond rounding), negative counts or times, a training size < 1.
void validate_values(const SnapshotDatabase& db) {
  const auto first_bad = [](const Eigen::MatrixXd& m, const auto& bad) -> std::string {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i)
        if (bad(m(i, j)))
          return "row " + std::to_string(j) + ", column " + std::to_string(i) + " holds " + format_value(m(i, j));
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

std::string join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  size_t start = 0;
  for (;;) {
    const size_t end = text.find(sep, start);
    out.push_back(text.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

}  // namespace

std::vector<int> SnapshotDatabase::successful_snapshots() const {
  std::vector<int> out;
  for (int j = 0; j < num_snapshots(); ++j)
    if (j < static_cast<int>(status.size()) && status[j] == Status::Success) out.push_back(j);
  return out;
}

void write_database(const std::string& path, const SnapshotDatabase& db) {
  const hsize_t n = static_cast<hsize_t>(db.num_snapshots());
  if (db.dual.cols() != db.primal.cols() || db.parameters.cols() != db.primal.cols() || db.status.size() != n ||
      db.iterations.size() != n || db.pairing_iterations.size() != n || db.time_s.size() != n)
    throw std::invalid_argument("write_database: inconsistent snapshot counts");
  silence_hdf5();
  check_output_path(path);
  // The file is built in memory and written by write_file_atomically: HDF5 never
  // writes to the disk, so a full disk is our error to report, not a half-closed
  // file left inside libhdf5.
  std::string image;
  try {
    // Object modification times are not stored, so that two runs on the same
    // data give the same bytes (except the timing datasets).
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation properties");
    check(H5Pset_obj_track_times(fcpl.id(), false), "file creation properties");
    Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "dataset creation properties");
    check(H5Pset_obj_track_times(dcpl.id(), false), "dataset creation properties");
    Handle file(hdf5::create_memory_file(path, fcpl.id()), H5Fclose, "file creation");
    const hid_t f = file.id();

    const int version = kDatabaseFormatVersion;
    write_scalar_attribute(f, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT, &version);
    write_string_attribute(f, "problem", db.problem);
    write_string_attribute(f, "mesh_fingerprint", db.mesh_fingerprint);
    write_string_attribute(f, "created_by", db.created_by);
    write_string_attribute(f, "training_kind", db.training_kind);
    write_scalar_attribute(f, "training_size", H5T_STD_I32LE, H5T_NATIVE_INT, &db.training_size);
    write_string_attribute(f, "param_names", join(db.param_names, ","));
    write_string_attribute(f, "status_names", "success,no_convergence,numerical_issue,invalid_input");
    write_scalar_attribute(f, "setup_time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &db.setup_time_s);
    write_scalar_attribute(f, "wall_time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &db.wall_time_s);
    write_scalar_attribute(f, "threads", H5T_STD_I32LE, H5T_NATIVE_INT, &db.threads);

    // Column-major width × n_snap == row-major n_snap × width: no transposition.
    write_dataset(f, dcpl.id(), "parameters", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n,
                  static_cast<hsize_t>(db.parameters.rows()), db.parameters.data());
    write_dataset(f, dcpl.id(), "primal", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n, static_cast<hsize_t>(db.primal.rows()),
                  db.primal.data());
    write_dataset(f, dcpl.id(), "dual", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n, static_cast<hsize_t>(db.dual.rows()),
                  db.dual.data());
    std::vector<int> status(db.status.size());
    for (size_t j = 0; j < status.size(); ++j) status[j] = static_cast<int>(db.status[j]);
    write_dataset(f, dcpl.id(), "status", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, status.data());
    write_dataset(f, dcpl.id(), "iterations", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, db.iterations.data());
    write_dataset(f, dcpl.id(), "pairing_iterations", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0,
                  db.pairing_iterations.data());
    write_dataset(f, dcpl.id(), "time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, n, 0, db.time_s.data());
    image = hdf5::file_image(f);
    file.close("file close");
  } catch (const Hdf5Failure& e) {
    throw InputError("cannot write database '" + path + "': HDF5 failed on " + e.what());
  }
  write_file_atomically(path, [&image](std::ostream& out) { out.write(image.data(), static_cast<std::streamsize>(image.size())); });
}

SnapshotDatabase read_database(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError("database '" + path + "' not found");
  if (fs::is_directory(path, ec)) throw InputError("database '" + path + "' is a directory, expected an HDF5 file");
  silence_hdf5();
  const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
  if (is_hdf5 <= 0)
    throw InputError("database '" + path + "' is not an HDF5 file (expected one written by contactrom offline)");
  SnapshotDatabase db;
  try {
    Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "the file structure");
    const hid_t f = file.id();
    if (!has_attribute(f, "format_version"))
      throw InputError("database '" + path + "' has no format_version attribute; not a contactrom database");
    const int version = hdf5::read_int_attribute(f, "format_version");
    if (version != kDatabaseFormatVersion)
      throw InputError("database '" + path + "' has format_version " + std::to_string(version) +
                       ", but this contactrom reads version " + std::to_string(kDatabaseFormatVersion));
    db.problem = read_string_attribute(f, "problem");
    db.mesh_fingerprint = read_string_attribute(f, "mesh_fingerprint");
    db.created_by = read_string_attribute(f, "created_by");
    db.training_kind = read_string_attribute(f, "training_kind");
    db.training_size = hdf5::read_int_attribute(f, "training_size");
    db.param_names = split(read_string_attribute(f, "param_names"), ',');
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
    db.primal = read_matrix(f, "primal", n);
    db.dual = read_matrix(f, "dual", n);
    db.iterations = read_vector<int>(f, "iterations", n);
    db.pairing_iterations = read_vector<int>(f, "pairing_iterations", n);
    db.time_s = read_vector<double>(f, "time_s", n);
    for (int s : status) {
      if (s < 0 || s > static_cast<int>(Status::InvalidInput))
        throw hdf5::Refused("dataset /status holds the unknown status code " + std::to_string(s));
      db.status.push_back(static_cast<Status>(s));
    }
    if (db.parameters.rows() != static_cast<Eigen::Index>(db.param_names.size()))
      throw hdf5::Refused("dataset /parameters has " + std::to_string(db.parameters.rows()) +
                        " columns but param_names lists " + std::to_string(db.param_names.size()));
    if (db.training_kind != "train" && db.training_kind != "level")
      throw hdf5::Refused("attribute training_kind is '" + db.training_kind + "', expected 'train' or 'level'");
    validate_values(db);
    file.close("file close");
  } catch (const hdf5::Refused& e) {
    throw InputError("database '" + path + "' is not a valid contactrom database: " + e.what());
  } catch (const Hdf5Failure& e) {
    throw InputError("database '" + path + "' is truncated or corrupt (HDF5 cannot read " + e.what() + ")");
  }
  return db;
}

void check_database(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  if (db.problem != problem.name())
    throw InputError("database '" + path + "' was built for problem '" + db.problem + "', not '" + problem.name() + "'");
  if (db.mesh_fingerprint != problem.fingerprint())
    throw InputError("database '" + path + "' was built for mesh fingerprint " + db.mesh_fingerprint +
                     " but the current " + problem.name() + " mesh is " + problem.fingerprint() +
                     "; rebuild it with contactrom offline");
  if (db.num_dofs() != problem.num_dofs() || db.num_constraints() != problem.contact().num_constraints() ||
      db.parameters.rows() != problem.num_params())
    throw InputError("database '" + path + "' holds " + std::to_string(db.num_dofs()) + " dofs, " +
                     std::to_string(db.num_constraints()) + " contact rows and " +
                     std::to_string(db.parameters.rows()) + " parameters, but " + problem.name() + " has " +
                     std::to_string(problem.num_dofs()) + ", " + std::to_string(problem.contact().num_constraints()) +
                     " and " + std::to_string(problem.num_params()));
  if ((db.training_kind == "level") != problem.uses_levels())
    throw InputError("database '" + path + "' selects its training set by '" + db.training_kind + "', but " +
                     problem.name() + " uses " + (problem.uses_levels() ? "'level'" : "'train'"));
  check_training_set(db, problem, path);
}

void check_training_set(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  for (int j = 0; j < db.num_snapshots(); ++j) {
    try {
      problem.check_param(db.parameter(j));
    } catch (const InputError& e) {
      throw InputError("database '" + path + "' dataset /parameters row " + std::to_string(j) + ": " + e.what());
    }
  }
  const std::string option = db.training_kind == "level" ? "level " : "training size ";
  std::vector<fom::Param> expected;
  try {
    expected = problem.training_set(db.training_size);
  } catch (const InputError& e) {
    throw InputError("database '" + path + "' attribute training_size: " + e.what());
  }
  const auto mismatch = [&](const std::string& why) {
    return InputError("database '" + path + "' claims " + option + std::to_string(db.training_size) + " of " +
                      problem.name() + ", but " + why + "; expected the snapshots of that training set");
  };
  if (static_cast<int>(expected.size()) != db.num_snapshots())
    throw mismatch("it holds " + std::to_string(db.num_snapshots()) + " snapshots instead of " +
                   std::to_string(expected.size()));
  for (int j = 0; j < db.num_snapshots(); ++j) {
    const double scale = std::max(1.0, expected[j].cwiseAbs().maxCoeff());
    if ((db.parameter(j) - expected[j]).cwiseAbs().maxCoeff() > kParameterMatchTolerance * scale)
      throw mismatch("its snapshot " + std::to_string(j) + " is not at the training parameter of that set");
  }
}

std::vector<fom::Param> database_training_set(const SnapshotDatabase& db, const fom::Problem& problem) {
  return problem.training_set(db.training_size);
}

std::vector<fom::Param> database_validation_set(const SnapshotDatabase& db, const fom::Problem& problem) {
  return problem.validation_set(db.training_size);
}

}  // namespace contactrom::rom
