// libFuzzer target: the TOML problem-file reader (fom/problem_file.hpp). Any text
// must either give a definition or throw InputError naming the file, line and key.
// Only the text is read: the mesh it names is not loaded (a .geo is trusted code).
#include <cstddef>
#include <cstdint>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/problem_file.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    contactrom::fom::parse_problem_text(text, "/nonexistent/fuzz.toml");
  } catch (const contactrom::InputError&) {
  }
  return 0;
}
