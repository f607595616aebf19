#include "rom/snapshot_database.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "fom/atomic_file.hpp"

namespace contactrom::rom {
namespace {

// The HDF5 C API reports failure through negative return values and prints an
// error stack on stderr by default; we turn the printing off (the user gets our
// one-line message instead) and translate failures into exceptions.

/// Failure inside an HDF5 call sequence; `what()` names the object involved.
struct Hdf5Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

/// Owns one HDF5 identifier and closes it with the matching H5*close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer, const std::string& what) : m_id(id), m_closer(closer) {
    if (id < 0) throw Hdf5Failure(what);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (m_id >= 0) m_closer(m_id);
  }
  /// Closes now and reports failure (closing a file flushes it).
  void close(const std::string& what) {
    const herr_t rc = m_closer(m_id);
    m_id = -1;
    if (rc < 0) throw Hdf5Failure(what);
  }
  hid_t id() const { return m_id; }

 private:
  hid_t m_id;
  Closer m_closer;
};

void check(herr_t rc, const std::string& what) {
  if (rc < 0) throw Hdf5Failure(what);
}

// ---------------------------------------------------------------- writing

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

void write_string_attribute(hid_t loc, const char* name, const std::string& value) {
  // h5py returns a fixed-length string as bytes: f.attrs[name].decode().
  const std::string what = std::string("attribute ") + name;
  Handle type(fixed_string_type(value.size()), H5Tclose, what);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle attr(H5Acreate2(loc, name, type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  std::string padded = value;
  padded.resize(std::max<size_t>(value.size(), 1), '\0');
  check(H5Awrite(attr.id(), type.id(), padded.data()), what);
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

void write_scalar_attribute(hid_t loc, const char* name, hid_t file_type, hid_t mem_type, const void* value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, std::string("attribute ") + name);
  Handle attr(H5Acreate2(loc, name, file_type, space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("attribute ") + name);
  check(H5Awrite(attr.id(), mem_type, value), std::string("attribute ") + name);
}

/// Writes a dataset of rank 1 (length rows) or rank 2 (rows × cols, row-major).
void write_dataset(hid_t file, hid_t dcpl, const char* name, hid_t file_type, hid_t mem_type, int rank, hsize_t rows,
                   hsize_t cols, const void* data) {
  const std::string what = std::string("dataset /") + name;
  const hsize_t dims[2] = {rows, cols};
  Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose, what);
  Handle set(H5Dcreate2(file, name, file_type, space.id(), H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, what);
  const hsize_t count = rank == 2 ? rows * cols : rows;
  if (count > 0) check(H5Dwrite(set.id(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), what);
}

// ---------------------------------------------------------------- reading

std::string read_string_attribute(hid_t loc, const char* name) {
  const std::string what = std::string("attribute ") + name;
  Handle attr(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose, what);
  Handle type(H5Aget_type(attr.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != H5T_STRING) throw Hdf5Failure(what + " is not a string");
  // Variable-length strings are refused without reading them (libhdf5 1.10 can
  // crash on corrupted ones); contactrom writes fixed-length strings only.
  if (H5Tis_variable_str(type.id()) != 0) throw Hdf5Failure(what + " is a variable-length string");
  Handle space(H5Aget_space(attr.id()), H5Sclose, what);
  if (H5Sget_simple_extent_npoints(space.id()) != 1) throw Hdf5Failure(what + " is not a scalar");
  const size_t size = H5Tget_size(type.id());
  if (size == 0 || size > (16u << 20)) throw Hdf5Failure(what + " has an implausible size");
  std::string buf(size, '\0');
  check(H5Aread(attr.id(), type.id(), buf.data()), what);
  const size_t end = buf.find('\0');
  return end == std::string::npos ? buf : buf.substr(0, end);
}

/// Reads a 1-D dataset of fixed-length strings (refuses variable-length ones unread).
std::vector<std::string> read_string_list(hid_t loc, const char* name) {
  const std::string what = std::string("dataset ") + name;
  Handle set(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose, what);
  Handle type(H5Dget_type(set.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != H5T_STRING || H5Tis_variable_str(type.id()) != 0)
    throw Hdf5Failure(what + " is not a list of fixed-length strings");
  Handle space(H5Dget_space(set.id()), H5Sclose, what);
  if (H5Sget_simple_extent_ndims(space.id()) != 1) throw Hdf5Failure(what + " is not one-dimensional");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.id(), &n, nullptr);
  const size_t width = H5Tget_size(type.id());
  if (width == 0 || width > (1u << 20) || n > (1u << 20)) throw Hdf5Failure(what + " has an implausible size");
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

template <typename T>
T read_scalar_attribute(hid_t loc, const char* name, hid_t mem_type) {
  const std::string what = std::string("attribute ") + name;
  Handle attr(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose, what);
  Handle space(H5Aget_space(attr.id()), H5Sclose, what);
  if (H5Sget_simple_extent_npoints(space.id()) != 1) throw Hdf5Failure(what + " is not a scalar");
  T value{};
  check(H5Aread(attr.id(), mem_type, &value), what);
  return value;
}

bool has_attribute(hid_t loc, const char* name) { return H5Aexists(loc, name) > 0; }

/// Reads a dataset of rank 1 or 2 into `out` (resized to its number of
/// elements); returns its dimensions (cols = 1 for rank 1).
template <typename T>
void read_dataset(hid_t file, const char* name, hid_t mem_type, std::vector<T>& out, hsize_t& rows, hsize_t& cols) {
  const std::string what = std::string("dataset /") + name;
  Handle set(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, what);
  Handle space(H5Dget_space(set.id()), H5Sclose, what);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 1 || rank > 2) throw Hdf5Failure(what + " has rank " + std::to_string(rank) + ", expected 1 or 2");
  hsize_t dims[2] = {0, 1};
  if (H5Sget_simple_extent_dims(space.id(), dims, nullptr) < 0) throw Hdf5Failure(what);
  rows = dims[0];
  cols = rank == 2 ? dims[1] : 1;
  out.assign(static_cast<size_t>(rows * cols), T{});
  if (!out.empty()) check(H5Dread(set.id(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), what);
}

/// Reads an n_snap × width dataset into the columns of a width × n_snap matrix.
Eigen::MatrixXd read_matrix(hid_t file, const char* name, hsize_t expected_rows) {
  std::vector<double> buf;
  hsize_t rows = 0, cols = 0;
  read_dataset(file, name, H5T_NATIVE_DOUBLE, buf, rows, cols);
  if (rows != expected_rows)
    throw Hdf5Failure(std::string("dataset /") + name + " has " + std::to_string(rows) + " rows, expected " +
                      std::to_string(expected_rows) + " (one per snapshot)");
  return Eigen::Map<Eigen::MatrixXd>(buf.data(), static_cast<Eigen::Index>(cols), static_cast<Eigen::Index>(rows));
}

template <typename T>
std::vector<T> read_vector(hid_t file, const char* name, hid_t mem_type, hsize_t expected) {
  std::vector<T> out;
  hsize_t rows = 0, cols = 0;
  read_dataset(file, name, mem_type, out, rows, cols);
  if (rows != expected || cols != 1)
    throw Hdf5Failure(std::string("dataset /") + name + " has " + std::to_string(rows * cols) + " entries, expected " +
                      std::to_string(expected));
  return out;
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
  read_dataset(f, "mesh/nodes", H5T_NATIVE_DOUBLE, xy, rows, cols);
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
  read_dataset(f, "mesh/quads", H5T_NATIVE_INT, quads, rows, cols);
  if (cols != 4) throw Hdf5Failure("dataset /mesh/quads does not have 4 columns");
  check_ids(quads, "mesh/quads");
  for (size_t q = 0; q + 3 < quads.size(); q += 4) mesh->quads.push_back({quads[q], quads[q + 1], quads[q + 2], quads[q + 3]});
  mesh->quad_body = read_vector<int>(f, "mesh/quad_body", H5T_NATIVE_INT, rows);
  mesh->body_names = read_string_list(f, "mesh/body_names");
  for (int b : mesh->quad_body)
    if (b < 0 || b >= static_cast<int>(mesh->body_names.size()))
      throw Hdf5Failure("dataset /mesh/quad_body holds the body " + std::to_string(b) + " of " +
                        std::to_string(mesh->body_names.size()));
  const std::vector<std::string> curves = read_string_list(f, "mesh/curve_names");
  for (size_t i = 0; i < curves.size(); ++i) {
    const std::string base = "mesh/curve_" + std::to_string(i);
    std::vector<int> nodes, segs;
    read_dataset(f, (base + "_nodes").c_str(), H5T_NATIVE_INT, nodes, rows, cols);
    read_dataset(f, (base + "_segments").c_str(), H5T_NATIVE_INT, segs, rows, cols);
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
  const std::string tmp = temporary_path_for(path);
  try {
    // Object modification times are not stored, so that two runs on the same
    // data give the same bytes (except the timing datasets).
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation properties");
    check(H5Pset_obj_track_times(fcpl.id(), false), "file creation properties");
    Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "dataset creation properties");
    check(H5Pset_obj_track_times(dcpl.id(), false), "dataset creation properties");
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl.id(), H5P_DEFAULT), H5Fclose, "file creation");
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
    file.close("file close");
  } catch (const Hdf5Failure& e) {
    std::remove(tmp.c_str());
    throw InputError("cannot write database '" + path + "': HDF5 failed on " + e.what() +
                     " (folder missing, not writable or disk full?)");
  }
  commit_temporary(tmp, path);
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
    const int version = read_scalar_attribute<int>(f, "format_version", H5T_NATIVE_INT);
    if (version != kDatabaseFormatVersion)
      throw InputError("database '" + path + "' has format_version " + std::to_string(version) +
                       ", but this contactrom reads version " + std::to_string(kDatabaseFormatVersion) + "; rebuild it with contactrom offline");
    db.problem = read_string_attribute(f, "problem");
    db.mesh_fingerprint = read_string_attribute(f, "mesh_fingerprint");
    db.created_by = read_string_attribute(f, "created_by");
    db.training_kind = read_string_attribute(f, "training_kind");
    db.training_size = read_scalar_attribute<int>(f, "training_size", H5T_NATIVE_INT);
    db.param_names = split(read_string_attribute(f, "param_names"), ',');
    if (has_attribute(f, "setup_time_s"))
      db.setup_time_s = read_scalar_attribute<double>(f, "setup_time_s", H5T_NATIVE_DOUBLE);
    if (has_attribute(f, "wall_time_s"))
      db.wall_time_s = read_scalar_attribute<double>(f, "wall_time_s", H5T_NATIVE_DOUBLE);
    if (has_attribute(f, "threads")) db.threads = read_scalar_attribute<int>(f, "threads", H5T_NATIVE_INT);

    std::vector<int> status;
    hsize_t n = 0, cols = 0;
    read_dataset(f, "status", H5T_NATIVE_INT, status, n, cols);
    if (cols != 1) throw Hdf5Failure("dataset /status is not one-dimensional");
    db.parameters = read_matrix(f, "parameters", n);
    db.primal = read_matrix(f, "primal", n);
    db.dual = read_matrix(f, "dual", n);
    db.iterations = read_vector<int>(f, "iterations", H5T_NATIVE_INT, n);
    db.pairing_iterations = read_vector<int>(f, "pairing_iterations", H5T_NATIVE_INT, n);
    db.time_s = read_vector<double>(f, "time_s", H5T_NATIVE_DOUBLE, n);
    for (int s : status) {
      if (s < 0 || s > static_cast<int>(Status::InvalidInput))
        throw Hdf5Failure("dataset /status holds the unknown status code " + std::to_string(s));
      db.status.push_back(static_cast<Status>(s));
    }
    if (db.parameters.rows() != static_cast<Eigen::Index>(db.param_names.size()))
      throw Hdf5Failure("dataset /parameters has " + std::to_string(db.parameters.rows()) +
                        " columns but param_names lists " + std::to_string(db.param_names.size()));
    if (db.training_kind != "train" && db.training_kind != "level" && db.training_kind != "list")
      throw Hdf5Failure("attribute training_kind is '" + db.training_kind + "', expected 'train', 'level' or 'list'");
    if (H5Lexists(f, "problem_file", H5P_DEFAULT) > 0) {
      const std::vector<std::string> text = read_string_list(f, "problem_file");
      if (text.size() != 1) throw Hdf5Failure("dataset /problem_file does not hold one text");
      db.problem_text = text[0];
    }
    if (H5Lexists(f, "mesh", H5P_DEFAULT) > 0) db.mesh = read_mesh(f);
    const Eigen::MatrixXd points = read_matrix(f, "contact/points", static_cast<hsize_t>(db.dual.rows()));
    if (points.rows() != 2) throw Hdf5Failure("dataset /contact/points does not have 2 columns");
    db.contact_points = points;
    const std::vector<double> weights =
        read_vector<double>(f, "contact/weights", H5T_NATIVE_DOUBLE, static_cast<hsize_t>(db.dual.rows()));
    db.contact_weights = Eigen::Map<const Eigen::VectorXd>(weights.data(), static_cast<Eigen::Index>(weights.size()));
    std::vector<double> lift;
    hsize_t terms = 0, width = 0;
    read_dataset(f, "lifting", H5T_NATIVE_DOUBLE, lift, terms, width);
    if (width != static_cast<hsize_t>(db.primal.rows()))
      throw Hdf5Failure("dataset /lifting has " + std::to_string(width) + " columns, expected one per dof (" +
                        std::to_string(db.primal.rows()) + ")");
    db.lifting_terms = Eigen::Map<Eigen::MatrixXd>(lift.data(), static_cast<Eigen::Index>(width),
                                                   static_cast<Eigen::Index>(terms));
    file.close("file close");
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
  const std::string selector = problem.definition().training.selector();
  if (db.training_kind != selector)
    throw InputError("database '" + path + "' selects its training set by '" + db.training_kind + "', but " +
                     problem.name() + " uses '" + selector + "'");
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
