#include "core/atomic_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "core/errors.hpp"
#include "core/format.hpp"

namespace contactrom {
namespace {

std::string folder_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string base_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string cannot_write(const std::string& path) { return "cannot write " + quoted(path, 200) + ": "; }

void remove_all(const std::vector<std::string>& tmps) {
  for (const std::string& t : tmps) std::remove(t.c_str());
}

}  // namespace

void check_output_path(const std::string& path) {
  if (path.empty()) throw InputError("output file name is empty; expected a file name");
  if (path.back() == '/') throw InputError(cannot_write(path) + "it names a folder; expected a file name");
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (S_ISLNK(st.st_mode))
      throw InputError(cannot_write(path) +
                       "it is a symbolic link, which would be replaced, not written through; give the path of its target");
    if (S_ISDIR(st.st_mode)) throw InputError(cannot_write(path) + "it is a folder; expected a file name");
    if (!S_ISREG(st.st_mode))
      throw InputError(cannot_write(path) + "it is a device, pipe or socket, not a regular file; refusing to replace it");
  } else if (errno != ENOENT) {
    throw InputError(cannot_write(path) + std::strerror(errno));
  }
  const std::string folder = folder_of(path);
  struct stat dir {};
  if (::stat(folder.c_str(), &dir) != 0)
    throw InputError(cannot_write(path) + "folder " + quoted(folder, 200) + ": " + std::strerror(errno));
  if (!S_ISDIR(dir.st_mode)) throw InputError(cannot_write(path) + quoted(folder, 200) + " is not a folder");
}

std::string temporary_path_for(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  // A hidden name built from at most 40 bytes of the target's name: a target
  // near the file-name limit still gets a valid temporary name.
  const std::string folder = folder_of(path);
  return (folder == "/" ? "" : folder) + "/." + base_of(path).substr(0, 40) + ".tmp." + std::to_string(::getpid()) +
         "." + std::to_string(counter++);
}

void commit_temporary(const std::string& tmp, const std::string& path) {
  try {
    check_output_path(path);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw InputError(cannot_write(path) + "renaming the completed temporary file failed: " + std::strerror(err));
  }
}

void write_files_atomically(const std::vector<std::pair<std::string, FileWriter>>& files) {
  for (const auto& [path, writer] : files) check_output_path(path);
  std::vector<std::string> tmps;
  for (const auto& [path, writer] : files) {
    const std::string tmp = temporary_path_for(path);
    std::ofstream out(tmp, std::ios::binary);
    if (!out) {
      const int err = errno;
      remove_all(tmps);
      throw InputError(cannot_write(path) + std::strerror(err));
    }
    tmps.push_back(tmp);
    try {
      writer(out);
    } catch (...) {
      out.close();
      remove_all(tmps);
      throw;
    }
    out.flush();
    out.close();
    if (!out) {
      const int err = errno;
      remove_all(tmps);
      throw InputError(cannot_write(path) + "write failed" + (err ? std::string(": ") + std::strerror(err) : "") +
                       " (disk full?)");
    }
  }
  for (size_t i = 0; i < files.size(); ++i) {
    try {
      commit_temporary(tmps[i], files[i].first);
    } catch (...) {
      remove_all(std::vector<std::string>(tmps.begin() + static_cast<std::ptrdiff_t>(i) + 1, tmps.end()));
      throw;
    }
  }
}

void write_file_atomically(const std::string& path, const FileWriter& writer) {
  write_files_atomically({{path, writer}});
}

}  // namespace contactrom
