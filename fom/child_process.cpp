#include <contactrom/fom/child_process.hpp>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include <contactrom/core/errors.hpp>

// A .geo file is a program, and gmsh can end the process that reads it: `Exit;`
// calls exit(0), some options and inputs crash it (Mesh.Algorithm = 8 segfaults in
// gmsh 4.8.4), a NaN radius makes it loop forever. load_mesh therefore runs gmsh in
// a forked child process that sends the finished answer (or an error message) back
// through a pipe. Whatever the work does to that child, the caller gets an outcome
// with its own state untouched: no exit handler of the caller runs, nothing reaches
// its stdout, and a half-written output file of the caller cannot be closed or
// flushed by the child's exit.

namespace contactrom::fom {
namespace {

/// Exit code of a child in which the work called exit() (a `.geo` `Exit` command).
constexpr int kChildCalledExit = 121;
/// Message tags on the pipe: an answer follows, an InputError's message follows, or
/// another error's message follows.
constexpr char kAnswerFollows = 'A', kInputErrorFollows = 'I', kErrorFollows = 'E';

void write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent went away: nothing left to tell
    done += static_cast<std::size_t>(n);
  }
}

/// The child: default signal handling, no core file, stdout to /dev/null, and an
/// exit handler that turns the work's exit() into a recognisable exit code before
/// any handler inherited from the parent runs. Never returns.
[[noreturn]] void run_child(int fd, const std::function<std::string()>& work, const std::string& where, pid_t parent) {
  // The child ends with its parent, however the parent ends (SIGKILL included): a
  // looping .geo must not keep a CPU busy after contactrom is gone. The parent may
  // have died between fork() and prctl(); then getppid() has changed already.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(1);
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
  const struct rlimit no_core = {0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, STDOUT_FILENO), ::close(null);
  std::atexit([] { ::_exit(kChildCalledExit); });  // registered last, runs first
  std::string message;
  try {
    message = kAnswerFollows + work();
  } catch (const InputError& e) {
    message = std::string(1, kInputErrorFollows) + e.what();
  } catch (const std::exception& e) {
    message = std::string(1, kErrorFollows) + e.what();
  } catch (...) {
    message = std::string(1, kErrorFollows) + where + " failed";
  }
  write_all(fd, message);
  ::_exit(0);
}

/// Longest wait between two calls of the caller's progress callback, in ms.
constexpr int kProgressIntervalMs = 100;

/// Reads the child's bytes until end of file or the deadline; whether it was reached.
/// `progress` (if any) is called between waits of at most kProgressIntervalMs; what it
/// throws propagates.
bool read_until(int fd, double time_limit_s, std::string& bytes, const ProgressCallback& progress) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(time_limit_s);
  const double longest_wait_ms = progress ? kProgressIntervalMs : 60000.0;
  char buffer[1 << 16];
  for (;;) {
    if (progress) progress(0, 1);
    const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return false;
    struct pollfd p = {fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min(left * 1000.0 + 1.0, longest_wait_ms)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;  // end of file: the child is done (or gone)
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
}

/// Waits for the child `pid` to end (retrying on EINTR); its wait status.
int reap(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

ChildOutcome outcome(int status, const std::string& bytes) {
  ChildOutcome out;
  if (WIFSIGNALED(status)) {
    out.end = ChildOutcome::End::Crashed;
    out.signal = WTERMSIG(status);
    return out;
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 0 && !bytes.empty() &&
      (bytes[0] == kAnswerFollows || bytes[0] == kInputErrorFollows || bytes[0] == kErrorFollows)) {
    out.end = bytes[0] == kAnswerFollows       ? ChildOutcome::End::Answered
              : bytes[0] == kInputErrorFollows ? ChildOutcome::End::Failed
                                               : ChildOutcome::End::Error;
    out.text = bytes.substr(1);
  } else if (code == kChildCalledExit || code == 0) {
    out.end = ChildOutcome::End::CalledExit;
  } else {
    out.end = ChildOutcome::End::ExitCode;
    out.exit_code = code;
  }
  return out;
}

}  // namespace

ChildOutcome run_in_child_process(const std::function<std::string()>& work, double time_limit_s,
                                  const std::string& where, const ProgressCallback& progress) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(where + ": cannot create a pipe: " + std::strerror(errno));
  std::fflush(nullptr);  // nothing buffered may be written twice
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw std::runtime_error(where + ": cannot start a process: " + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], work, where, parent);
  }
  ::close(fds[1]);
  std::string bytes;
  bool finished = false;
  try {
    finished = read_until(fds[0], time_limit_s, bytes, progress);
  } catch (...) {  // the caller stops the work (Ctrl-C): no child is left running or unreaped
    ::close(fds[0]);
    ::kill(pid, SIGKILL);
    reap(pid);
    throw;
  }
  ::close(fds[0]);
  if (!finished) ::kill(pid, SIGKILL);
  const int status = reap(pid);
  if (!finished) {
    ChildOutcome out;
    out.end = ChildOutcome::End::TimedOut;
    return out;
  }
  return outcome(status, bytes);
}

std::string signal_name(int sig) {
  switch (sig) {
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGABRT: return "SIGABRT";
    case SIGKILL: return "SIGKILL";
    default: return "signal " + std::to_string(sig);
  }
}

}  // namespace contactrom::fom
