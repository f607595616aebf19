// libFuzzer target: the snapshot database reader (rom/snapshot_database.hpp).
// The input is written to a file (HDF5 reads by name) and read back; it must
// either be read or throw InputError. Crashes inside libhdf5 itself on
// structurally corrupted files are a known limit (docs/database_format.md).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <contactrom/core/errors.hpp>
#include "hdf5_open_objects.hpp"
#include <contactrom/rom/snapshot_database.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/contactrom_fuzz_database_" + std::to_string(::getpid()) + ".h5";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const contactrom::rom::SnapshotDatabase db = contactrom::rom::read_database(path);
    if (db.num_snapshots() != static_cast<int>(db.status.size())) __builtin_trap();
  } catch (const contactrom::InputError&) {
  }
  contactrom::fuzz::require_no_open_hdf5_objects();
  std::remove(path.c_str());
  return 0;
}
