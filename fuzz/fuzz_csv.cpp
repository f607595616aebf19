// libFuzzer target: the CSV reader of `contactrom sparse` (rom/dense_csv.hpp).
// Any input must either parse or throw InputError; anything else is a bug.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/rom/dense_csv.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const Eigen::MatrixXd m = contactrom::rom::read_dense_csv(in, "fuzz.csv");
    if (m.rows() < 1 || m.cols() < 1 || !m.allFinite()) __builtin_trap();
  } catch (const contactrom::InputError&) {
  }
  return 0;
}
