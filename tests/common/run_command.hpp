#pragma once
// Runs a shell command for CLI tests, capturing stdout, stderr and exit code.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace contactrom::test {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs `command` with /bin/sh; stdout/stderr go to temporary files.
inline CommandResult run_command(const std::string& command) {
  char out_name[] = "/tmp/contactrom_out_XXXXXX", err_name[] = "/tmp/contactrom_err_XXXXXX";
  const int fo = mkstemp(out_name), fe = mkstemp(err_name);
  close(fo);
  close(fe);
  const int status = std::system((command + " >" + out_name + " 2>" + err_name).c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out_name);
  r.err = slurp(err_name);
  std::remove(out_name);
  std::remove(err_name);
  return r;
}

/// A fresh empty temporary folder.
inline std::string temp_dir() {
  char name[] = "/tmp/contactrom_test_XXXXXX";
  return mkdtemp(name);
}

}  // namespace contactrom::test
