#pragma once
/// \file hdf5_io.hpp
/// \brief Checked access to HDF5 files for the files contactrom writes and reads
/// (snapshot databases, reduced models).
///
/// HDF5 itself trusts a file's metadata: it reads a string attribute of any
/// shape into a buffer sized for one string, allocates whatever size a dataset
/// declares, and follows variable-length string heaps that a corrupted file can
/// point anywhere (libhdf5 1.10 crashes or hangs on such files). These helpers
/// check before they read:
///  - string attributes are written as scalar fixed-length UTF-8 strings, and read
///    only from a scalar dataspace with a fixed-length string type of bounded
///    size; a variable-length string is refused without being read;
///  - numeric attributes must be scalar (or hold one element) of the expected
///    class (integer or floating point);
///  - datasets must have rank 1 or 2, the expected class, and a declared size
///    that fits in the file (contactrom stores datasets uncompressed), so no
///    allocation is larger than the file that asked for it.
///
/// Failures throw hdf5::Failure whose `what()` names the object and the
/// problem ("attribute problem has 3 elements, expected a single string"); the
/// caller adds the file name.
#include <hdf5.h>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace contactrom::rom::hdf5 {

/// \brief A failed or refused HDF5 operation; `what()` names the object involved.
struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// \brief A file refused by a check (wrong shape, type or size) rather than a
/// failed HDF5 call; `what()` is a whole sentence naming the object.
struct Refused : Failure {
  using Failure::Failure;
};

/// \brief Turns off HDF5's own error printing (the caller reports one line instead).
void silence();

/// \brief Owns one HDF5 identifier and closes it with the matching H5*close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  /// \throws Failure(`what`) if `id` is negative (the call that made it failed).
  Handle(hid_t id, Closer closer, const std::string& what);
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle();
  /// Closes now and reports failure (closing a file flushes it).
  void close(const std::string& what);
  hid_t id() const { return m_id; }

 private:
  hid_t m_id;
  Closer m_closer;
};

/// \brief Throws Failure(`what`) if `rc` is negative.
void check(herr_t rc, const std::string& what);

/// \brief Largest string attribute read or written (bytes); longer is refused.
inline constexpr std::size_t kMaxStringAttribute = std::size_t{1} << 24;

/// \brief Name of the attribute holding the checksum of a dataset's data: every
/// dataset write_dataset() and write_string_list() create carries it, and the
/// readers refuse data that fails it (docs/database_format.md, "Data checksums").
inline constexpr const char* kChecksumAttribute = "checksum_lookup3";

/// \brief The checksum of a dataset's data bytes: Bob Jenkins' lookup3 (hashlittle,
/// initial value 0), the hash HDF5 uses for its metadata.
std::uint32_t data_checksum(const void* bytes, std::size_t size);

/// \brief data_checksum() of data that arrives in pieces (e.g. a dataset read back by
/// blocks of rows): the same value as over the whole, with O(1) memory.
class DataChecksum {
 public:
  /// \param total the number of bytes that will be added in all
  explicit DataChecksum(std::size_t total);
  /// Adds the next `size` bytes.
  void add(const void* bytes, std::size_t size);
  /// The checksum, once `total` bytes were added.
  std::uint32_t value() const;

 private:
  std::uint32_t m_a, m_b, m_c;
  std::size_t m_remaining;  // bytes not yet mixed (buffered ones included)
  unsigned char m_buffer[12];
  std::size_t m_buffered = 0;
};

/// \brief Stores `sum` as the checksum attribute of dataset `set`.
void write_checksum_attribute(hid_t set, std::uint32_t sum, const std::string& what);

/// \brief Writes a scalar fixed-length UTF-8 string attribute (h5py returns it as bytes
/// or str depending on its version; its length is the string's, at least 1).
void write_string_attribute(hid_t loc, const char* name, const std::string& value);

/// \brief Reads a string attribute written by write_string_attribute.
/// \throws Failure if it is missing, not a string, not scalar, a variable-length
///   string (refused without reading: corrupted ones crash libhdf5), or longer
///   than kMaxStringAttribute.
std::string read_string_attribute(hid_t loc, const char* name);

/// \brief Whether `loc` has an attribute `name`.
bool has_attribute(hid_t loc, const char* name);

/// \brief Writes a scalar numeric attribute.
void write_scalar_attribute(hid_t loc, const char* name, hid_t file_type, hid_t mem_type, const void* value);

/// \brief Reads a scalar 32-bit integer attribute (class integer, one element).
int read_int_attribute(hid_t loc, const char* name);

/// \brief Reads a scalar double attribute (class floating point, one element).
double read_double_attribute(hid_t loc, const char* name);

/// \brief Size of the open file `file` in bytes.
std::uint64_t file_size(hid_t file);

/// \brief Dimensions of a dataset of rank 1 ({rows}) or rank 2 ({rows, cols}).
/// \throws Failure if it is missing or of another rank.
std::vector<hsize_t> dataset_shape(hid_t file, const char* name);

/// \brief Reads a rank-1 or rank-2 dataset of integers into `out` (row-major);
/// returns its dimensions as (rows, cols), cols = 1 for rank 1.
/// \throws Failure if it is missing, of another rank or class, or declares more
///   bytes than the file holds.
void read_int_dataset(hid_t file, const char* name, std::vector<int>& out, hsize_t& rows, hsize_t& cols);

/// \brief As read_int_dataset for floating-point data read as double.
void read_double_dataset(hid_t file, const char* name, std::vector<double>& out, hsize_t& rows, hsize_t& cols);

/// \brief Writes a dataset of rank 1 (length rows) or rank 2 (rows × cols, row-major).
void write_dataset(hid_t file, hid_t dcpl, const char* name, hid_t file_type, hid_t mem_type, int rank, hsize_t rows,
                   hsize_t cols, const void* data);

/// \brief Creates an HDF5 file in memory (core driver, no backing store) with the
/// file-creation properties `fcpl`: HDF5 never touches the disk, so a full disk
/// or a failing device cannot leave a half-closed file inside the library. The
/// file has HDF5's 1.8 format (superblock version 2, checksummed object headers).
/// Write it out with file_image() and core/atomic_file.
/// \param label name of the file in HDF5's error messages
hid_t create_memory_file(const std::string& label, hid_t fcpl);

/// \brief The bytes of an open file (flushed first), as they would be on disk.
std::string file_image(hid_t file);

/// \brief Writes a 1-D dataset of fixed-length UTF-8 strings (one element per item).
void write_string_list(hid_t loc, hid_t dcpl, const char* name, const std::vector<std::string>& items);

/// \brief Reads a dataset written by write_string_list; refuses variable-length
/// strings without reading them and lists declaring more than `max_bytes`.
std::vector<std::string> read_string_list(hid_t loc, const char* name, std::uint64_t max_bytes);

/// \brief Builds an HDF5 file in memory with `fill(file, dcpl)` and writes it to
/// `path` atomically (core/atomic_file.hpp). Object modification times are not
/// stored, so the same content gives the same bytes.
/// \throws Failure from `fill` or HDF5; InputError (from the atomic write) naming
///   `path` if the target is refused or the disk is full. No partial file is left.
void write_file(const std::string& path, const std::function<void(hid_t file, hid_t dcpl)>& fill);

/// \brief Opens an existing HDF5 file read-only after checking that it exists, is
/// not a folder, is HDF5 and has a superblock of version 2 or later (the format
/// create_memory_file() writes: metadata with checksums, so libhdf5 refuses a
/// damaged object header instead of parsing it). \param label what the file is ("database",
/// "reduced model"), for the messages, e.g. "reduced model 'x.h5' not found".
/// \throws InputError (one line naming `path`).
hid_t open_file(const std::string& path, const std::string& label, const std::string& expected_writer);

}  // namespace contactrom::rom::hdf5
