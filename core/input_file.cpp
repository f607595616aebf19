#include <contactrom/core/input_file.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>

namespace contactrom {

void check_input_file(const std::string& path, const std::string& label, std::uintmax_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) throw InputError(label + " " + quoted(path, 200) + " not found");
    throw InputError(label + " " + quoted(path, 200) + " cannot be opened: " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode))
    throw InputError(label + " " + quoted(path, 200) + " is not a regular file (a folder, device or pipe); expected a file");
  // Readable, as documented: an unreadable file is not "not HDF5" or "empty".
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(label + " " + quoted(path, 200) + " cannot be read: " + std::strerror(errno));
  ::close(fd);
  if (static_cast<std::uintmax_t>(st.st_size) > max_bytes)
    throw InputError(label + " " + quoted(path, 200) + " has " + std::to_string(st.st_size) + " bytes, more than the " +
                     std::to_string(max_bytes) + " accepted");
}

std::string read_input_file(const std::string& path, const std::string& label, std::uintmax_t max_bytes) {
  check_input_file(path, label, max_bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(label + " " + quoted(path, 200) + " cannot be read: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  std::string content = text.str();
  if (content.compare(0, 3, "\xEF\xBB\xBF") == 0) content.erase(0, 3);
  return content;
}

}  // namespace contactrom
