#pragma once
/// \file child_process.hpp
/// \brief Runs untrusted work (gmsh reading a `.geo` program) in a forked child
/// process, so that whatever it does — exit, crash, hang, print — the caller's
/// process, its exit handlers and its stdout are untouched. POSIX only.
#include <functional>
#include <string>

#include <contactrom/core/parallel_for.hpp>

namespace contactrom::fom {

/// \brief How the child of run_in_child_process() ended.
struct ChildOutcome {
  enum class End {
    Answered,    ///< the work returned: `text` is its answer
    Failed,      ///< the work threw an InputError: `text` is its message
    Error,       ///< the work threw anything else: `text` is its message
    TimedOut,    ///< still running at the time limit: killed (SIGKILL)
    Crashed,     ///< ended by `signal`
    CalledExit,  ///< the work called exit() (or ended with code 0 without an answer)
    ExitCode     ///< ended with another `exit_code`
  };
  End end = End::Answered;
  std::string text;
  int signal = 0;
  int exit_code = 0;
};

/// \brief Runs `work` in a forked child process and returns how it ended.
///
/// The child has default handlers for the crash signals, no core file, stdout on
/// /dev/null, and dies with its parent (a looping child never outlives the
/// caller); an exit() inside `work` ends it with a recognisable code before any exit
/// handler inherited from the caller runs. Its answer comes back through a pipe,
/// read within `time_limit_s` seconds.
/// \param where names the work in the messages of a failed pipe or fork
/// \param progress called with (0, 1) from the calling thread about every 0.1 s while
///   the parent waits (optional); an exception it throws kills the child (SIGKILL),
///   reaps it and propagates
/// \throws std::runtime_error if no pipe or process can be created.
ChildOutcome run_in_child_process(const std::function<std::string()>& work, double time_limit_s,
                                  const std::string& where, const ProgressCallback& progress = {});

/// \brief Name of a signal number for messages ("SIGSEGV", "signal 40").
std::string signal_name(int sig);

}  // namespace contactrom::fom
