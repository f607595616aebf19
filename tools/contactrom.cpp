// contactrom — command-line driver. Subcommands (see README):
//   contactrom fom     --problem hertz --param 0.1 --json
//   contactrom offline --problem hertz --train 30 --out hertz30.h5
//   contactrom online  --db hertz30.h5 --method greedy --validation --json
//   contactrom sparse  --method omp --dictionary D.csv --signal x.csv --json
//   contactrom bench   --problem hertz --json
//   contactrom demo
// Bad input ends with one line on stderr ("contactrom: error: ...") and exit code 2;
// numerical non-convergence is reported in the output with a status instead.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/blas_threads.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/version.hpp>
#include <contactrom/fom/input_values.hpp>
#include "tools/cli.hpp"
#ifdef CONTACTROM_HAVE_MPI
#include <contactrom/rom/offline_mpi.hpp>
#endif

namespace contactrom::cli {
std::vector<CommandEntry>& command_table() {
  static std::vector<CommandEntry> table;
  return table;
}
}  // namespace contactrom::cli

namespace {

/// A message as one line of at most about 1.5 kB: control characters (a newline or
/// an escape sequence in a name read from a file) are written as \n, \t or \xHH,
/// and the middle of a longer message is cut.
std::string one_line(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else out += ch;
  }
  // A name of thousands of characters (read from a file) would bury the message.
  constexpr size_t kHead = 1000, kTail = 400;
  if (out.size() > kHead + kTail + 100)
    out = out.substr(0, kHead) + "[... " + std::to_string(out.size() - kHead - kTail) + " characters cut ...]" +
          out.substr(out.size() - kTail);
  return out;
}

/// CLI11's "The following arguments were not expected: 1 --threads" (its words, in
/// reverse order) as our one line: the unknown option named first, else the stray
/// values.
std::string extras_message(const std::string& what, const std::string& command) {
  const size_t colon = what.find(": ");
  std::vector<std::string> extras;
  std::istringstream words(colon == std::string::npos ? "" : what.substr(colon + 2));
  for (std::string w; words >> w;) extras.insert(extras.begin(), w);
  const std::string help = "see contactrom " + command + " --help";
  for (const std::string& w : extras)
    if (w.size() > 1 && w[0] == '-' && !std::isdigit(static_cast<unsigned char>(w[1])) && w[1] != '.')
      return "option " + contactrom::quoted(w) + " unknown to '" + command + "'; " + help;
  std::vector<std::string> quoted_extras;
  for (const std::string& w : extras) quoted_extras.push_back(contactrom::quoted(w));
  if (quoted_extras.empty()) return what;
  return "unexpected argument" + std::string(extras.size() > 1 ? "s " : " ") + contactrom::join(quoted_extras) +
         "; expected options with one value each (a parameter vector is one value, V1,V2); " + help;
}

int fail(const std::string& message, int code) {
  std::cerr << "contactrom: error: " << one_line(message) << "\n";
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace contactrom;
  CLI::App app{"contactrom: sparse dictionary reduced-order models for frictionless contact"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "contactrom " + version());
  // An interrupted run leaves no temporary file behind (core/atomic_file.hpp).
  remove_temporaries_on_signals();
  // Threads (and MPI ranks) run FOMs side by side: one BLAS thread under each.
  use_one_blas_thread_by_default();
  auto& table = cli::command_table();
  std::sort(table.begin(), table.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (auto& entry : table) entry.setup(app);
#ifdef CONTACTROM_HAVE_MPI
  // Under mpirun every rank runs this program (MPI starts before the arguments are
  // parsed and ends after the error message); only rank 0 reports errors, so a bad
  // argument gives one message, and every rank exits with the error code.
  std::unique_ptr<rom::mpi::Session> mpi_session;
  if (rom::mpi::launched_by_mpi()) mpi_session = std::make_unique<rom::mpi::Session>();
  if (rom::mpi::world_rank() != 0) std::cerr.setstate(std::ios::badbit);
#endif
  // CLI11 would only say that a subcommand is required; name the unknown one.
  if (argc > 1 && argv[1][0] != '-') {
    const std::string name = argv[1];
    const bool known = std::any_of(table.begin(), table.end(), [&](const auto& e) { return e.name == name; });
#ifdef CONTACTROM_HAVE_MPI
    // Only offline and reduce share their work over ranks; any other command would run
    // whole on every rank, print its report once per rank and write its files twice.
    if (known && name != "offline" && name != "reduce" && rom::mpi::world_size() > 1)
      return fail("'" + name + "' runs in one process, not under mpirun with " +
                      std::to_string(rom::mpi::world_size()) + " ranks; expected mpirun only for offline and reduce",
                  2);
#endif
    if (!known) {
      std::string names;
      for (const auto& e : table) names += (names.empty() ? "" : ", ") + e.name;
      return fail("unknown command " + quoted(name) + "; expected one of: " + names, 2);
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ExtrasError& e) {
    return fail(extras_message(e.what(), argc > 1 ? argv[1] : ""), 2);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    return fail(e.what(), 2);
  } catch (const InputError& e) {
    return fail(e.what(), 2);
  } catch (const std::bad_alloc&) {
    return fail("out of memory: a size given in the input (mesh, database, dictionary or option) is too large for this"
                " machine", 1);
  } catch (const std::length_error&) {
    return fail("a size given in the input (mesh, database, dictionary or option) is too large to allocate", 1);
  } catch (const std::exception& e) {
    return fail(e.what(), 1);
  }
  // The report went to stdout: a full disk or a closed pipe there is a failure too.
  errno = 0;
  std::cout.flush();
  if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout))
    return fail(std::string("cannot write the report to standard output: ") +
                    (errno ? std::strerror(errno) : "write error"), 1);
  return 0;
}
