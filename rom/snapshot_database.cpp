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

/// Fixed-length, null-padded UTF-8 string type of `size` bytes (at least 1).
/// Fixed-length strings only: libhdf5 1.10 can crash on corrupted variable-length ones.
hid_t fixed_string_type(size_t size) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  if (type < 0) return type;
  H5Tset_size(type, std::max<size_t>(size, 1));
  H5Tset_strpad(type, H5T_STR_NULLPAD);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

/// A 1-D dataset of fixed-length strings (one element per item).
void write_string_list(hid_t loc, hid_t dcpl, const char* name, const std::vector<std::string>& items) {
  const std::string what = std::string("dataset ") + name;
  size_t width = 1;
  for (const auto& item : items) width = std::max(width, item.size());
  Handle type(fixed_string_type(width), H5Tclose, what);
  const hsize_t dims[1] = {items.size()};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose, what);
  Handle set(H5Dcreate2(loc, name, type.id(), space.id(), H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, what);
  std::string buf(width * items.size(), '\0');
  for (size_t i = 0; i < items.size(); ++i) buf.replace(i * width, items[i].size(), items[i]);
  if (!items.empty()) check(H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()), what);
}

/// Reads a 1-D dataset of fixed-length strings (refuses variable-length ones unread),
/// at most `max_bytes` in all.
std::vector<std::string> read_string_list(hid_t loc, const char* name, std::uint64_t max_bytes) {
  const std::string what = std::string("dataset ") + name;
  Handle set(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose, what);
  Handle type(H5Dget_type(set.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != H5T_STRING || H5Tis_variable_str(type.id()) != 0)
    throw hdf5::Refused(what + " is not a list of fixed-length strings");
  Handle space(H5Dget_space(set.id()), H5Sclose, what);
  if (H5Sget_simple_extent_ndims(space.id()) != 1) throw hdf5::Refused(what + " is not one-dimensional");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.id(), &n, nullptr);
  const size_t width = H5Tget_size(type.id());
  if (width == 0 || n > max_bytes || width > max_bytes / std::max<hsize_t>(n, 1))
    throw hdf5::Refused(what + " declares more bytes than the file holds");
  std::string buf(width * n, '\0');
  if (n > 0) check(H5Dread(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()), what);
  std::vector<std::string> out;
  for (hsize_t i = 0; i < n; ++i) {
    std::string item = buf.substr(i * width, width);
    item.resize(std::min(item.find('\0'), item.size()));
    out.push_back(item);
  }
  return out;
}

/// A rank-1 or rank-2 dataset of ints or doubles (shape and size checked by hdf5_io).
template <typename T>
void read_dataset(hid_t file, const char* name, std::vector<T>& out, hsize_t& rows, hsize_t& cols) {
  if constexpr (std::is_same_v<T, int>) hdf5::read_int_dataset(file, name, out, rows, cols);
  else hdf5::read_double_dataset(file, name, out, rows, cols);
}

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

/// The problem part of format 2: problem file text, mesh, contact rows, lifting.
void write_problem(hid_t f, hid_t dcpl, const SnapshotDatabase& db) {
  const hsize_t nc = static_cast<hsize_t>(db.contact_weights.size());
  if (db.contact_points.cols() != db.contact_weights.size() || db.lifting_terms.rows() != db.primal.rows())
    throw std::invalid_argument("write_database: inconsistent problem description");
  if (!db.problem_text.empty()) write_string_list(f, dcpl, "problem_file", {db.problem_text});
  Handle contact(H5Gcreate2(f, "contact", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /contact");
  write_dataset(f, dcpl, "contact/points", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, nc, 2, db.contact_points.data());
  write_dataset(f, dcpl, "contact/weights", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, nc, 0, db.contact_weights.data());
  // n_dofs × n_terms column-major == row-major n_terms × n_dofs: one term per row.
  write_dataset(f, dcpl, "lifting", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, static_cast<hsize_t>(db.lifting_terms.cols()),
                static_cast<hsize_t>(db.lifting_terms.rows()), db.lifting_terms.data());
  if (!db.mesh) return;
  const fom::Mesh& m = *db.mesh;
  Handle group(H5Gcreate2(f, "mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /mesh");
  write_dataset(f, dcpl, "mesh/nodes", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, static_cast<hsize_t>(m.num_nodes()), 2,
                m.nodes.data());
  write_dataset(f, dcpl, "mesh/quads", H5T_STD_I32LE, H5T_NATIVE_INT, 2, static_cast<hsize_t>(m.num_quads()), 4,
                m.quads.data());
  write_dataset(f, dcpl, "mesh/quad_body", H5T_STD_I32LE, H5T_NATIVE_INT, 1, static_cast<hsize_t>(m.num_quads()), 0,
                m.quad_body.data());
  write_string_list(f, dcpl, "mesh/body_names", m.body_names);
  std::vector<std::string> curves;
  for (const auto& [name, nodes] : m.curve_nodes) curves.push_back(name);
  write_string_list(f, dcpl, "mesh/curve_names", curves);
  for (size_t i = 0; i < curves.size(); ++i) {
    const auto& nodes = m.curve_nodes.at(curves[i]);
    const auto& segs = m.segments.at(curves[i]);
    const std::string base = "mesh/curve_" + std::to_string(i);
    write_dataset(f, dcpl, (base + "_nodes").c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, 1, nodes.size(), 0, nodes.data());
    write_dataset(f, dcpl, (base + "_segments").c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, 2, segs.size(), 2, segs.data());
  }
}

/// Reads the mesh of format 2, checking every index against the node count.
std::shared_ptr<const fom::Mesh> read_mesh(hid_t f) {
  auto mesh = std::make_shared<fom::Mesh>();
  std::vector<double> xy;
  hsize_t rows = 0, cols = 0;
  read_dataset(f, "mesh/nodes", xy, rows, cols);
  if (cols != 2) throw Hdf5Failure("dataset /mesh/nodes does not have 2 columns");
  for (double v : xy)
    if (!std::isfinite(v)) throw Hdf5Failure("dataset /mesh/nodes holds a non-finite coordinate");
  mesh->nodes = Eigen::Map<Eigen::Matrix2Xd>(xy.data(), 2, static_cast<Eigen::Index>(rows));
  const int nn = static_cast<int>(rows);
  auto check_ids = [&](const std::vector<int>& ids, const std::string& what) {
    for (int id : ids)
      if (id < 0 || id >= nn) throw Hdf5Failure("dataset /" + what + " refers to node " + std::to_string(id) +
                                                ", expected 0.." + std::to_string(nn - 1));
  };
  std::vector<int> quads;
  read_dataset(f, "mesh/quads", quads, rows, cols);
  if (cols != 4) throw Hdf5Failure("dataset /mesh/quads does not have 4 columns");
  check_ids(quads, "mesh/quads");
  for (size_t q = 0; q + 3 < quads.size(); q += 4) mesh->quads.push_back({quads[q], quads[q + 1], quads[q + 2], quads[q + 3]});
  mesh->quad_body = read_vector<int>(f, "mesh/quad_body", rows);
  mesh->body_names = read_string_list(f, "mesh/body_names", hdf5::file_size(f));
  for (int b : mesh->quad_body)
    if (b < 0 || b >= static_cast<int>(mesh->body_names.size()))
      throw Hdf5Failure("dataset /mesh/quad_body holds the body " + std::to_string(b) + " of " +
                        std::to_string(mesh->body_names.size()));
  const std::vector<std::string> curves = read_string_list(f, "mesh/curve_names", hdf5::file_size(f));
  for (size_t i = 0; i < curves.size(); ++i) {
    const std::string base = "mesh/curve_" + std::to_string(i);
    std::vector<int> nodes, segs;
    read_dataset(f, (base + "_nodes").c_str(), nodes, rows, cols);
    read_dataset(f, (base + "_segments").c_str(), segs, rows, cols);
    if (cols != 2 && !segs.empty()) throw Hdf5Failure("dataset /" + base + "_segments does not have 2 columns");
    check_ids(nodes, base + "_nodes");
    check_ids(segs, base + "_segments");
    mesh->curve_nodes[curves[i]] = nodes;
    auto& out = mesh->segments[curves[i]];
    for (size_t k = 0; k + 1 < segs.size(); k += 2) out.push_back({segs[k], segs[k + 1]});
  }
  return mesh;
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
    write_problem(f, dcpl.id(), db);
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
                       ", but this contactrom reads version " + std::to_string(kDatabaseFormatVersion) + "; rebuild it with contactrom offline");
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
    if (db.training_kind != "train" && db.training_kind != "level" && db.training_kind != "list")
      throw hdf5::Refused("attribute training_kind is '" + db.training_kind + "', expected 'train', 'level' or 'list'");
    if (H5Lexists(f, "problem_file", H5P_DEFAULT) > 0) {
      const std::vector<std::string> text = read_string_list(f, "problem_file", hdf5::file_size(f));
      if (text.size() != 1) throw hdf5::Refused("dataset /problem_file does not hold one text");
      db.problem_text = text[0];
    }
    if (H5Lexists(f, "mesh", H5P_DEFAULT) > 0) db.mesh = read_mesh(f);
    const Eigen::MatrixXd points = read_matrix(f, "contact/points", static_cast<hsize_t>(db.dual.rows()));
    if (points.rows() != 2) throw hdf5::Refused("dataset /contact/points does not have 2 columns");
    db.contact_points = points;
    const std::vector<double> weights =
        read_vector<double>(f, "contact/weights", static_cast<hsize_t>(db.dual.rows()));
    db.contact_weights = Eigen::Map<const Eigen::VectorXd>(weights.data(), static_cast<Eigen::Index>(weights.size()));
    std::vector<double> lift;
    hsize_t terms = 0, width = 0;
    read_dataset(f, "lifting", lift, terms, width);
    if (width != static_cast<hsize_t>(db.primal.rows()))
      throw hdf5::Refused("dataset /lifting has " + std::to_string(width) + " columns, expected one per dof (" +
                        std::to_string(db.primal.rows()) + ")");
    db.lifting_terms = Eigen::Map<Eigen::MatrixXd>(lift.data(), static_cast<Eigen::Index>(width),
                                                   static_cast<Eigen::Index>(terms));
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
  check_database_problem(db, problem, path);
  const std::string selector = problem.definition().training.selector();
  if (db.training_kind != selector)
    throw InputError("database '" + path + "' selects its training set by '" + db.training_kind + "', but " +
                     problem.name() + " uses '" + selector + "'");
  check_training_set(db, problem, path);
}

void check_database_problem(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
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
}

void check_training_set(const SnapshotDatabase& db, const fom::Problem& problem, const std::string& path) {
  for (int j = 0; j < db.num_snapshots(); ++j) {
    try {
      problem.check_param(db.parameter(j));
    } catch (const InputError& e) {
      throw InputError("database '" + path + "' dataset /parameters row " + std::to_string(j) + ": " + e.what());
    }
  }
  const std::string option = db.training_kind == "level" ? "level " : db.training_kind == "list" ? "the list of " : "training size ";
  std::vector<fom::Param> expected;
  try {
    expected = fom::training_set(problem, db.training_size);
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

void describe_problem(const fom::Problem& problem, SnapshotDatabase& db) {
  db.problem = problem.name();
  db.mesh_fingerprint = problem.fingerprint();
  db.param_names = problem.param_names();
  db.problem_text = problem.definition().builtin.empty() ? problem.definition().text : "";
  db.mesh = problem.mesh() ? std::make_shared<const fom::Mesh>(*problem.mesh()) : nullptr;
  db.contact_points = problem.contact().constraint_points();
  db.contact_weights = problem.contact().weights();
  db.lifting_terms.resize(problem.num_dofs(), problem.num_load_terms());
  for (int k = 0; k < problem.num_load_terms(); ++k) db.lifting_terms.col(k) = problem.lifting_terms()[k];
}

std::unique_ptr<fom::Problem> problem_from_database(const SnapshotDatabase& db, const std::string& path) {
  std::unique_ptr<fom::Problem> problem;
  if (db.problem_text.empty()) {
    if (db.problem != "rope")
      throw InputError("database '" + path + "' stores no problem file for problem '" + db.problem +
                       "'; expected a database written by contactrom offline");
    problem = fom::make_rope_problem();
  } else {
    if (!db.mesh) throw InputError("database '" + path + "' stores a problem file but no mesh (dataset /mesh)");
    // Messages about the stored file name the database.
    fom::ProblemDefinition def = fom::parse_problem_text(db.problem_text, path + ":/problem_file");
    problem = fom::build_problem(std::move(def), *db.mesh);
  }
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
