// libFuzzer target: the reduced-model file reader (rom/reduced_model_file.hpp).
// The input is written to a file (HDF5 reads by name) and loaded; it must either
// load into a model that answers a query inside its range, or throw InputError.
// Crashes inside libhdf5 itself on structurally corrupted files are a known limit
// (docs/database_format.md).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <contactrom/core/errors.hpp>
#include "hdf5_open_objects.hpp"
#include <contactrom/rom/reduced_model_file.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/contactrom_fuzz_reduced_model_" + std::to_string(::getpid()) + ".h5";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const contactrom::rom::OnlineModel rom = contactrom::rom::OnlineModel::load(path);
    // A model that loads must answer a query at the middle of its parameter box.
    const auto& space = rom.problem().parameters();
    contactrom::fom::Param mu(space.size());
    for (int k = 0; k < space.size(); ++k) mu(k) = 0.5 * (space.lower(k) + space.upper(k));
    (void)rom.solve(mu);
  } catch (const contactrom::InputError&) {
  }
  contactrom::fuzz::require_no_open_hdf5_objects();
  std::remove(path.c_str());
  return 0;
}
