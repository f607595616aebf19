#include <contactrom/rom/hdf5_io.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>

#include <contactrom/core/format.hpp>
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/input_file.hpp>

namespace contactrom::rom::hdf5 {
namespace {

std::string attribute_what(const char* name) { return std::string("attribute ") + name; }
std::string dataset_what(const char* name) { return std::string("dataset /") + name; }

/// Bob Jenkins' lookup3 hash (hashlittle, public domain), with which HDF5
/// checksums its metadata (initial value 0).
std::uint32_t lookup3(const unsigned char* k, size_t length) {
  auto rot = [](std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); };
  auto word = [](const unsigned char* p, size_t n) {
    std::uint32_t w = 0;
    for (size_t i = 0; i < n && i < 4; ++i) w |= static_cast<std::uint32_t>(p[i]) << (8 * i);
    return w;
  };
  std::uint32_t a = 0xdeadbeef + static_cast<std::uint32_t>(length), b = a, c = a;
  while (length > 12) {
    a += word(k, 4), b += word(k + 4, 4), c += word(k + 8, 4);
    a -= c, a ^= rot(c, 4), c += b, b -= a, b ^= rot(a, 6), a += c;
    c -= b, c ^= rot(b, 8), b += a, a -= c, a ^= rot(c, 16), c += b;
    b -= a, b ^= rot(a, 19), a += c, c -= b, c ^= rot(b, 4), b += a;
    length -= 12, k += 12;
  }
  if (length == 0) return c;
  a += word(k, length), b += length > 4 ? word(k + 4, length - 4) : 0, c += length > 8 ? word(k + 8, length - 8) : 0;
  c ^= b, c -= rot(b, 14), a ^= c, a -= rot(c, 11), b ^= a, b -= rot(a, 25);
  c ^= b, c -= rot(b, 16), a ^= c, a -= rot(c, 4), b ^= a, b -= rot(a, 14);
  c ^= b, c -= rot(b, 24);
  return c;
}


/// Number of elements of an attribute's dataspace (scalar: 1).
hssize_t attribute_elements(hid_t attr, const std::string& what) {
  Handle space(H5Aget_space(attr), H5Sclose, what);
  const hssize_t n = H5Sget_simple_extent_npoints(space.id());
  if (n < 0) throw Refused(what + " has an unreadable dataspace");
  return n;
}

/// Opens a numeric attribute and checks it holds one element of class `cls`.
template <typename T>
T read_numeric_attribute(hid_t loc, const char* name, H5T_class_t cls, hid_t mem_type, const char* expected) {
  const std::string what = attribute_what(name);
  Handle attr(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose, what);
  Handle type(H5Aget_type(attr.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != cls) throw Refused(what + " is not " + expected);
  const hssize_t n = attribute_elements(attr.id(), what);
  if (n != 1) throw Refused(what + " has " + std::to_string(n) + " elements, expected a single " + expected);
  T value{};
  check(H5Aread(attr.id(), mem_type, &value), what);
  return value;
}


/// Stores the checksum of the `bytes` just written to `set`.
void write_checksum(hid_t set, const void* bytes, size_t size, const std::string& what) {
  const std::uint32_t sum = data_checksum(bytes, size);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle attr(H5Acreate2(set, kChecksumAttribute, H5T_STD_U32LE, space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(attr.id(), H5T_NATIVE_UINT32, &sum), what);
}

/// Refuses data whose checksum differs from the stored one (or that has none).
void verify_checksum(hid_t set, const void* bytes, size_t size, const std::string& what) {
  if (H5Aexists(set, kChecksumAttribute) <= 0)
    throw Refused(what + " has no checksum attribute " + kChecksumAttribute + " (expected a file written by contactrom)");
  const std::uint32_t stored = read_numeric_attribute<std::uint32_t>(set, kChecksumAttribute, H5T_INTEGER, H5T_NATIVE_UINT32,
                                                                     "an unsigned 32-bit integer");
  const bool intact = data_checksum(bytes, size) == stored;
#ifdef CONTACTROM_FUZZING
  // A fuzzing build reads data that fails its checksum: a file made on purpose
  // carries a valid one, and the checks behind it are what the fuzzer must reach.
  (void)intact;
#else
  if (!intact) throw Refused(what + " fails its checksum: the file is damaged");
#endif
}

/// Opens dataset `name`, refusing links to other files (external, or soft links
/// anywhere on the path) and data stored outside the file (external or virtual
/// storage): a file contactrom reads must not read any other file.
hid_t open_local_dataset(hid_t loc, const char* name, const std::string& what) {
  const std::string path = name;
  for (size_t end = path.find('/', 1);; end = path.find('/', end + 1)) {
    const std::string prefix = path.substr(0, end);
    if (H5Lexists(loc, prefix.c_str(), H5P_DEFAULT) > 0) {
      H5L_info_t info{};
      if (H5Lget_info(loc, prefix.c_str(), &info, H5P_DEFAULT) < 0) throw Failure(what);
      if (info.type != H5L_TYPE_HARD)
        throw Refused(what + " is reached through a " + (info.type == H5L_TYPE_EXTERNAL ? "link to another file" : "soft link") +
                      " (/" + prefix + "); expected the data in the file itself");
    }
    if (end == std::string::npos) break;
  }
  const hid_t set = H5Dopen2(loc, name, H5P_DEFAULT);
  if (set < 0) return set;
  const hid_t dcpl = H5Dget_create_plist(set);
  const bool outside = dcpl < 0 || H5Pget_external_count(dcpl) > 0 || H5Pget_layout(dcpl) == H5D_VIRTUAL;
  if (dcpl >= 0) H5Pclose(dcpl);
  if (outside) {
    H5Dclose(set);
    throw Refused(what + " stores its data outside the file (external or virtual storage); expected the data in the file");
  }
  return set;
}

/// Reads a rank-1/2 dataset of class `cls` into `out` after checking its
/// declared size against the file's size.
template <typename T>
void read_numeric_dataset(hid_t file, const char* name, H5T_class_t cls, hid_t mem_type, const char* expected,
                          std::vector<T>& out, hsize_t& rows, hsize_t& cols) {
  const std::string what = dataset_what(name);
  Handle set(open_local_dataset(file, name, what), H5Dclose, what);
  Handle type(H5Dget_type(set.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != cls) throw Refused(what + " does not hold " + expected);
  const size_t element = H5Tget_size(type.id());
  if (element == 0 || element > 16) throw Refused(what + " has elements of " + std::to_string(element) + " bytes");
  const std::vector<hsize_t> dims = dataset_shape(file, name);
  rows = dims[0];
  cols = dims.size() == 2 ? dims[1] : 1;
  // Declared bytes, overflow-checked, must fit in the file (datasets are stored
  // uncompressed), and the elements in memory.
  const std::uint64_t limit = file_size(file);
  const long double declared = static_cast<long double>(rows) * static_cast<long double>(cols) * element;
  if (declared > static_cast<long double>(limit))
  {
    char bytes[32];
    std::snprintf(bytes, sizeof bytes, "%.3Lg", declared);
    throw Refused(what + " declares " + std::to_string(rows) + " x " + std::to_string(cols) + " elements (" + bytes +
                  " bytes), more than the file's " + std::to_string(limit) + " bytes");
  }
  out.assign(static_cast<size_t>(rows * cols), T{});
  if (!out.empty()) check(H5Dread(set.id(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), what);
  verify_checksum(set.id(), out.data(), out.size() * sizeof(T), what);
}

}  // namespace

void silence() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

Handle::Handle(hid_t id, Closer closer, const std::string& what) : m_id(id), m_closer(closer) {
  if (id < 0) throw Failure(what);
}

Handle::~Handle() {
  if (m_id >= 0) m_closer(m_id);
}

void Handle::close(const std::string& what) {
  const herr_t rc = m_closer(m_id);
  m_id = -1;
  if (rc < 0) throw Failure(what);
}

void check(herr_t rc, const std::string& what) {
  if (rc < 0) throw Failure(what);
}

void write_string_attribute(hid_t loc, const char* name, const std::string& value) {
  const std::string what = attribute_what(name);
  if (value.size() > kMaxStringAttribute) throw Refused(what + " is too long");
  // Fixed length, padded with NULs: never a variable-length heap reference.
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, what);
  check(H5Tset_size(type.id(), value.empty() ? 1 : value.size()), what);
  check(H5Tset_strpad(type.id(), H5T_STR_NULLPAD), what);
  check(H5Tset_cset(type.id(), H5T_CSET_UTF8), what);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle attr(H5Acreate2(loc, name, type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  std::string buffer = value.empty() ? std::string(1, '\0') : value;
  check(H5Awrite(attr.id(), type.id(), buffer.data()), what);
}

std::string read_string_attribute(hid_t loc, const char* name) {
  const std::string what = attribute_what(name);
  Handle attr(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose, what);
  Handle type(H5Aget_type(attr.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != H5T_STRING) throw Refused(what + " is not a string");
  if (H5Tis_variable_str(type.id()) != 0)
    throw Refused(what + " is a variable-length string, expected a fixed-length one (not read)");
  const hssize_t n = attribute_elements(attr.id(), what);
  if (n != 1) throw Refused(what + " has " + std::to_string(n) + " elements, expected a single string");
  const size_t size = H5Tget_size(type.id());
  if (size == 0 || size > kMaxStringAttribute)
    throw Refused(what + " has a string size of " + std::to_string(size) + " bytes");
  // Read through a memory type of the same size, so the buffer always matches.
  Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, what);
  check(H5Tset_size(mem.id(), size), what);
  check(H5Tset_strpad(mem.id(), H5T_STR_NULLPAD), what);
  const H5T_cset_t cset = H5Tget_cset(type.id());
  if (cset != H5T_CSET_ASCII && cset != H5T_CSET_UTF8) throw Refused(what + " has an unknown character set");
  check(H5Tset_cset(mem.id(), cset), what);
  std::string buffer(size, '\0');
  check(H5Aread(attr.id(), mem.id(), buffer.data()), what);
  const size_t end = buffer.find('\0');
  return end == std::string::npos ? buffer : buffer.substr(0, end);
}

bool has_attribute(hid_t loc, const char* name) { return H5Aexists(loc, name) > 0; }

void write_scalar_attribute(hid_t loc, const char* name, hid_t file_type, hid_t mem_type, const void* value) {
  const std::string what = attribute_what(name);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle attr(H5Acreate2(loc, name, file_type, space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(attr.id(), mem_type, value), what);
}

int read_int_attribute(hid_t loc, const char* name) {
  return read_numeric_attribute<int>(loc, name, H5T_INTEGER, H5T_NATIVE_INT, "integer");
}

double read_double_attribute(hid_t loc, const char* name) {
  return read_numeric_attribute<double>(loc, name, H5T_FLOAT, H5T_NATIVE_DOUBLE, "floating-point number");
}

namespace {
std::uint32_t rot32(std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }
std::uint32_t word32(const unsigned char* p, size_t n) {
  std::uint32_t w = 0;
  for (size_t i = 0; i < n && i < 4; ++i) w |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return w;
}
}  // namespace

DataChecksum::DataChecksum(std::size_t total)
    : m_a(0xdeadbeef + static_cast<std::uint32_t>(total)), m_b(m_a), m_c(m_a), m_remaining(total) {}

void DataChecksum::add(const void* bytes, std::size_t size) {
  const unsigned char* p = static_cast<const unsigned char*>(bytes);
  for (std::size_t i = 0; i < size; ++i) {
    m_buffer[m_buffered++] = p[i];
    // A full block is mixed only while more than 12 bytes remain (lookup3's loop);
    // the last block, of 1 to 12 bytes, goes to the final step.
    if (m_buffered == 12 && m_remaining > 12) {
      std::uint32_t& a = m_a;
      std::uint32_t& b = m_b;
      std::uint32_t& c = m_c;
      a += word32(m_buffer, 4), b += word32(m_buffer + 4, 4), c += word32(m_buffer + 8, 4);
      a -= c, a ^= rot32(c, 4), c += b, b -= a, b ^= rot32(a, 6), a += c;
      c -= b, c ^= rot32(b, 8), b += a, a -= c, a ^= rot32(c, 16), c += b;
      b -= a, b ^= rot32(a, 19), a += c, c -= b, c ^= rot32(b, 4), b += a;
      m_remaining -= 12, m_buffered = 0;
    }
  }
}

std::uint32_t DataChecksum::value() const {
  std::uint32_t a = m_a, b = m_b, c = m_c;
  const size_t length = m_buffered;
  if (length == 0) return c;
  const unsigned char* k = m_buffer;
  a += word32(k, length), b += length > 4 ? word32(k + 4, length - 4) : 0, c += length > 8 ? word32(k + 8, length - 8) : 0;
  c ^= b, c -= rot32(b, 14), a ^= c, a -= rot32(c, 11), b ^= a, b -= rot32(a, 25);
  c ^= b, c -= rot32(b, 16), a ^= c, a -= rot32(c, 4), b ^= a, b -= rot32(a, 14);
  c ^= b, c -= rot32(b, 24);
  return c;
}

void write_checksum_attribute(hid_t set, std::uint32_t sum, const std::string& what) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, what);
  Handle attr(H5Acreate2(set, kChecksumAttribute, H5T_STD_U32LE, space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  check(H5Awrite(attr.id(), H5T_NATIVE_UINT32, &sum), what);
}

std::uint32_t data_checksum(const void* bytes, std::size_t size) {
  return lookup3(static_cast<const unsigned char*>(bytes), size);
}

std::uint64_t file_size(hid_t file) {
  hsize_t size = 0;
  check(H5Fget_filesize(file, &size), "the file size");
  return size;
}

std::vector<hsize_t> dataset_shape(hid_t file, const char* name) {
  const std::string what = dataset_what(name);
  Handle set(open_local_dataset(file, name, what), H5Dclose, what);
  Handle space(H5Dget_space(set.id()), H5Sclose, what);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 1 || rank > 2) throw Refused(what + " has rank " + std::to_string(rank) + ", expected 1 or 2");
  std::vector<hsize_t> dims(static_cast<size_t>(rank), 0);
  if (H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr) < 0) throw Failure(what);
  return dims;
}

void read_int_dataset(hid_t file, const char* name, std::vector<int>& out, hsize_t& rows, hsize_t& cols) {
  read_numeric_dataset(file, name, H5T_INTEGER, H5T_NATIVE_INT, "integers", out, rows, cols);
}

void read_double_dataset(hid_t file, const char* name, std::vector<double>& out, hsize_t& rows, hsize_t& cols) {
  read_numeric_dataset(file, name, H5T_FLOAT, H5T_NATIVE_DOUBLE, "floating-point numbers", out, rows, cols);
}

void write_dataset(hid_t file, hid_t dcpl, const char* name, hid_t file_type, hid_t mem_type, int rank, hsize_t rows,
                   hsize_t cols, const void* data) {
  const std::string what = dataset_what(name);
  const hsize_t dims[2] = {rows, cols};
  Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose, what);
  Handle set(H5Dcreate2(file, name, file_type, space.id(), H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, what);
  const hsize_t count = rank == 2 ? rows * cols : rows;
  if (count > 0) check(H5Dwrite(set.id(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), what);
  write_checksum(set.id(), data, static_cast<size_t>(count) * H5Tget_size(mem_type), what);
}

hid_t create_memory_file(const std::string& label, hid_t fcpl) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access properties");
  check(H5Pset_fapl_core(fapl.id(), std::size_t{1} << 20, false), "file access properties");
  // The 1.8 file format: superblock version 2 and version-2 object headers, both
  // with checksums, so a damaged header is refused by HDF5's checksum test before
  // libhdf5 parses it (the 1.10 library crashes on some damaged version-1 headers).
  check(H5Pset_libver_bounds(fapl.id(), H5F_LIBVER_V18, H5F_LIBVER_V18), "file access properties");
  return H5Fcreate(label.c_str(), H5F_ACC_TRUNC, fcpl, fapl.id());
}

std::string file_image(hid_t file) {
  check(H5Fflush(file, H5F_SCOPE_GLOBAL), "file flush");
  const ssize_t size = H5Fget_file_image(file, nullptr, 0);
  if (size < 0) throw Failure("file image");
  std::string image(static_cast<size_t>(size), '\0');
  if (H5Fget_file_image(file, image.data(), image.size()) != size) throw Failure("file image");
  // libhdf5 1.10 clears the superblock's "open for writing" flag in the image but
  // keeps the checksum computed with it set; the superblock (version 2 or 3:
  // signature, 4 bytes, 4 addresses, checksum) gets its checksum recomputed.
  const auto* bytes = reinterpret_cast<unsigned char*>(image.data());
  const size_t offsets = image.size() > 9 ? bytes[9] : 0, checked = 12 + 4 * offsets;
  if (image.size() >= checked + 4 && (bytes[8] == 2 || bytes[8] == 3)) {
    const std::uint32_t sum = lookup3(bytes, checked);
    for (int i = 0; i < 4; ++i) image[checked + i] = static_cast<char>((sum >> (8 * i)) & 0xff);
  }
  return image;
}

namespace {

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

}  // namespace

void write_string_list(hid_t loc, hid_t dcpl, const char* name, const std::vector<std::string>& items) {
  const std::string what = dataset_what(name);
  size_t width = 1;
  for (const auto& item : items) width = std::max(width, item.size());
  Handle type(fixed_string_type(width), H5Tclose, what);
  const hsize_t dims[1] = {items.size()};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose, what);
  Handle set(H5Dcreate2(loc, name, type.id(), space.id(), H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose, what);
  std::string buf(width * items.size(), '\0');
  for (size_t i = 0; i < items.size(); ++i) buf.replace(i * width, items[i].size(), items[i]);
  if (!items.empty()) check(H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()), what);
  write_checksum(set.id(), buf.data(), buf.size(), what);
}

std::vector<std::string> read_string_list(hid_t loc, const char* name, std::uint64_t max_bytes) {
  const std::string what = dataset_what(name);
  Handle set(open_local_dataset(loc, name, what), H5Dclose, what);
  Handle type(H5Dget_type(set.id()), H5Tclose, what);
  if (H5Tget_class(type.id()) != H5T_STRING || H5Tis_variable_str(type.id()) != 0)
    throw Refused(what + " is not a list of fixed-length strings");
  Handle space(H5Dget_space(set.id()), H5Sclose, what);
  if (H5Sget_simple_extent_ndims(space.id()) != 1) throw Refused(what + " is not one-dimensional");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.id(), &n, nullptr);
  const size_t width = H5Tget_size(type.id());
  if (width == 0 || n > max_bytes || width > max_bytes / std::max<hsize_t>(n, 1))
    throw Refused(what + " declares more bytes than the file holds");
  std::string buf(width * n, '\0');
  if (n > 0) check(H5Dread(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()), what);
  verify_checksum(set.id(), buf.data(), buf.size(), what);
  std::vector<std::string> out;
  for (hsize_t i = 0; i < n; ++i) {
    std::string item = buf.substr(i * width, width);
    item.resize(std::min(item.find('\0'), item.size()));
    out.push_back(item);
  }
  return out;
}

void write_file(const std::string& path, const std::function<void(hid_t file, hid_t dcpl)>& fill) {
  silence();
  check_output_path(path);
  // Built in memory: HDF5 never writes to the disk, so a full disk is our error to
  // report, not a half-closed file left inside libhdf5.
  std::string image;
  {
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation properties");
    check(H5Pset_obj_track_times(fcpl.id(), false), "file creation properties");
    Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "dataset creation properties");
    check(H5Pset_obj_track_times(dcpl.id(), false), "dataset creation properties");
    Handle file(create_memory_file(path, fcpl.id()), H5Fclose, "file creation");
    fill(file.id(), dcpl.id());
    image = file_image(file.id());
    file.close("file close");
  }
  write_file_atomically(path, [&image](std::ostream& out) { out.write(image.data(), static_cast<std::streamsize>(image.size())); });
}

namespace {

/// Version of the HDF5 superblock of `path`: the byte after the signature, which
/// sits at offset 0, 512, 1024, 2048, ... (after a user block); -1 if there is no
/// signature (not an HDF5 file, or unreadable), as H5Fis_hdf5 would find.
int superblock_version(const std::string& path) {
  static const char signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(path, std::ios::binary);
  char head[9];
  for (std::streamoff offset = 0; in.seekg(offset) && in.read(head, sizeof head); offset = offset ? 2 * offset : 512)
    if (std::equal(signature, signature + 8, head)) return static_cast<unsigned char>(head[8]);
  return -1;
}

}  // namespace

hid_t open_file(const std::string& path, const std::string& label, const std::string& expected_writer) {
  // A regular file that can be read: a pipe or a device would block the signature
  // search below (or never end it), and an unreadable file is not "not HDF5".
  check_input_file(path, label, std::numeric_limits<std::uintmax_t>::max());
  silence();
  const int version = superblock_version(path);
  if (version < 0)
    throw InputError(label + " " + quoted(path, 200) + " is not an HDF5 file (expected one written by " + expected_writer + ")");
  // Without checksums (superblock versions 0 and 1) a damaged file reaches
  // libhdf5's parsers unchecked; contactrom writes version 2.
  if (version < 2)
    throw InputError(label + " " + quoted(path, 200) + " has HDF5 superblock version " + std::to_string(version) +
                     " (no metadata checksums), expected 2 or later as written by " + expected_writer +
                     "; write it again with " + expected_writer);
  // Without HDF5's own file lock (flock): files are published whole by rename, so a
  // reader never sees one being written, and `offline --append` holds its own lock
  // on the database (core/atomic_file.hpp FileLock), which HDF5's would conflict with.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access properties");
  check(H5Pset_file_locking(fapl.id(), false, true), "file access properties");
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.id());
  if (file < 0) throw InputError(label + " " + quoted(path, 200) + " is truncated or corrupt (HDF5 cannot open it)");
  return file;
}

}  // namespace contactrom::rom::hdf5
