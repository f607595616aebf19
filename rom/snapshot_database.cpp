#include "rom/snapshot_database.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "core/atomic_file.hpp"
#include "core/format.hpp"
#include "rom/hdf5_io.hpp"
#include "rom/problem_record.hpp"

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

/// The problem part of `db` as a record (and back).
ProblemRecord problem_record(const SnapshotDatabase& db) {
  ProblemRecord r;
  r.name = db.problem;
  r.fingerprint = db.mesh_fingerprint;
  r.param_names = db.param_names;
  r.text = db.problem_text;
  r.mesh = db.mesh;
  r.contact_points = db.contact_points;
  r.contact_weights = db.contact_weights;
  r.lifting_terms = db.lifting_terms;
  return r;
}

void set_problem_record(SnapshotDatabase& db, ProblemRecord r) {
  db.problem = std::move(r.name);
  db.mesh_fingerprint = std::move(r.fingerprint);
  db.param_names = std::move(r.param_names);
  db.problem_text = std::move(r.text);
  db.mesh = std::move(r.mesh);
  db.contact_points = std::move(r.contact_points);
  db.contact_weights = std::move(r.contact_weights);
  db.lifting_terms = std::move(r.lifting_terms);
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

void write_database(const std::string& path, const SnapshotDatabase& db) {
  const hsize_t n = static_cast<hsize_t>(db.num_snapshots());
  if (db.dual.cols() != db.primal.cols() || db.parameters.cols() != db.primal.cols() || db.status.size() != n ||
      db.iterations.size() != n || db.pairing_iterations.size() != n || db.time_s.size() != n)
    throw std::invalid_argument("write_database: inconsistent snapshot counts");
  if (db.lifting_terms.rows() != db.primal.rows())
    throw std::invalid_argument("write_database: lifting terms and snapshots differ in size");
  try {
    hdf5::write_file(path, [&db](hid_t f, hid_t dcpl) {
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
      write_dataset(f, dcpl, "primal", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n, static_cast<hsize_t>(db.primal.rows()),
                    db.primal.data());
      write_dataset(f, dcpl, "dual", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, n, static_cast<hsize_t>(db.dual.rows()),
                    db.dual.data());
      std::vector<int> status(db.status.size());
      for (size_t j = 0; j < status.size(); ++j) status[j] = static_cast<int>(db.status[j]);
      write_dataset(f, dcpl, "status", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, status.data());
      write_dataset(f, dcpl, "iterations", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0, db.iterations.data());
      write_dataset(f, dcpl, "pairing_iterations", H5T_STD_I32LE, H5T_NATIVE_INT, 1, n, 0,
                    db.pairing_iterations.data());
      write_dataset(f, dcpl, "time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, n, 0, db.time_s.data());
      write_problem_record(f, dcpl, problem_record(db));
    });
  } catch (const Hdf5Failure& e) {
    throw InputError("cannot write database " + quoted(path, 200) + ": HDF5 failed on " + e.what());
  }
}

SnapshotDatabase read_database(const std::string& path) {
  Handle file(hdf5::open_file(path, "database", "contactrom offline"), H5Fclose, "the file structure");
  SnapshotDatabase db;
  try {
    const hid_t f = file.id();
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
    set_problem_record(db, read_problem_record(f, static_cast<hsize_t>(db.dual.rows()),
                                               static_cast<hsize_t>(db.primal.rows())));
    if (db.parameters.rows() != static_cast<Eigen::Index>(db.param_names.size()))
      throw hdf5::Refused("dataset /parameters has " + std::to_string(db.parameters.rows()) +
                        " columns but param_names lists " + std::to_string(db.param_names.size()));
    if (db.training_kind != "train" && db.training_kind != "level" && db.training_kind != "list")
      throw hdf5::Refused("attribute training_kind is " + quoted(db.training_kind, 200) + ", expected 'train', 'level' or 'list'");
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
  if (db.training_kind != selector)
    throw InputError("database " + quoted(path, 200) + " selects its training set by " + quoted(db.training_kind, 200) + ", but " +
                     problem.name() + " uses " + quoted(selector, 200));
  check_training_set(db, problem, path);
}

void check_database_problem(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  if (db.problem != problem.name())
    throw InputError("database " + quoted(path, 200) + " was built for problem " + quoted(db.problem, 200) + ", not " + quoted(problem.name(), 200));
  if (db.mesh_fingerprint != problem.fingerprint())
    throw InputError("database " + quoted(path, 200) + " was built for mesh fingerprint " + db.mesh_fingerprint +
                     " but the current " + problem.name() + " mesh is " + problem.fingerprint() +
                     "; rebuild it with contactrom offline");
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
  const std::string option = db.training_kind == "level" ? "level " : db.training_kind == "list" ? "the list of " : "training size ";
  std::vector<fom::Param> expected;
  try {
    expected = fom::training_set(problem, db.training_size);
  } catch (const InputError& e) {
    throw InputError("database " + quoted(path, 200) + " attribute training_size: " + e.what());
  }
  const auto mismatch = [&](const std::string& why) {
    return InputError("database " + quoted(path, 200) + " claims " + option + std::to_string(db.training_size) + " of " +
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

void describe_problem(const fom::Problem& problem, SnapshotDatabase& db) {
  set_problem_record(db, record_problem(problem));
}

std::unique_ptr<fom::Problem> rebuild_database_problem(const SnapshotDatabase& db, const std::string& path) {
  return rebuild_problem(problem_record(db), "database " + quoted(path, 200));
}

std::unique_ptr<fom::Problem> problem_from_database(const SnapshotDatabase& db, const std::string& path) {
  auto problem = rebuild_database_problem(db, path);
  check_database(db, *problem, path);
  return problem;
}

std::vector<fom::Param> database_training_set(const SnapshotDatabase& db, const fom::Problem& problem) {
  return fom::training_set(problem, db.training_size);
}

std::vector<fom::Param> database_validation_set(const SnapshotDatabase& db, const fom::Problem& problem) {
  return fom::validation_set(problem, db.training_size);
}

}  // namespace contactrom::rom
