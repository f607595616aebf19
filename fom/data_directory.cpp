#include <contactrom/fom/data_directory.hpp>

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>

namespace contactrom::fom {
namespace {

namespace fs = std::filesystem;

/// How many folders above the binary's own are searched: enough for
/// `lib/python3/dist-packages/contactrom/` under an install prefix.
constexpr int kAncestors = 5;

/// The file of the binary (program or shared library) that holds this function.
fs::path own_binary() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&own_binary), &info) != 0 && info.dli_fname && *info.dli_fname) {
    std::error_code ec;
    fs::path p = fs::canonical(info.dli_fname, ec);
    if (!ec) return p;
  }
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe;
}

}  // namespace

std::string data_directory(const std::string& sub, const char* env) {
  if (const char* dir = std::getenv(env); dir && *dir) return dir;
  const fs::path binary = own_binary();
  if (!binary.empty()) {
    fs::path dir = binary.parent_path();
    for (int up = 0; up <= kAncestors && !dir.empty(); ++up, dir = dir.parent_path()) {
      std::error_code ec;
      const fs::path candidate = dir / "share" / "contactrom" / sub;
      if (fs::is_directory(candidate, ec)) return candidate.string();
      if (dir == dir.root_path()) break;
    }
  }
  return std::string(CONTACTROM_INSTALL_DATA_DIR) + "/" + sub;
}

}  // namespace contactrom::fom
