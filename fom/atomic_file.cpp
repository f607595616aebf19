#include "fom/atomic_file.hpp"

#include <atomic>
#include <cstdio>
#include <fstream>
#include <unistd.h>

#include "fom/errors.hpp"

namespace contactrom {

std::string temporary_path_for(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
}

void commit_temporary(const std::string& tmp, const std::string& path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError("cannot write '" + path + "': rename from temporary file failed");
  }
}

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& writer) {
  const std::string tmp = temporary_path_for(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw InputError("cannot write '" + path + "': folder missing or not writable");
    try {
      writer(out);
    } catch (...) {
      out.close();
      std::remove(tmp.c_str());
      throw;
    }
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw InputError("cannot write '" + path + "': write failed (disk full?)");
    }
  }
  commit_temporary(tmp, path);
}

}  // namespace contactrom
