#include <contactrom/core/atomic_file.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>

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

/// A file that cannot be created or renamed: a fault of the machine (no space or
/// inodes left, quota, I/O error, no descriptors or memory) is a WriteFailure (exit
/// 1), anything else (permissions, a read-only file system, a bad name) bad input.
[[noreturn]] void throw_cannot_create(const std::string& message, int err) {
  const std::string text = message + std::strerror(err);
  switch (err) {
    case ENOSPC: case EDQUOT: case EIO: case EMFILE: case ENFILE: case ENOMEM: throw WriteFailure(text);
    default: throw InputError(text);
  }
}

// --- declared inputs -----------------------------------------------------------
struct DeclaredInput {
  std::string path;
  dev_t dev;
  ino_t ino;
};
std::mutex g_inputs_mutex;
std::vector<DeclaredInput> g_inputs;

/// Throws InputError if the existing file `st` (of `path`) is a declared input.
void check_not_declared_input(const std::string& path, const struct stat& st) {
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  for (const DeclaredInput& in : g_inputs)
    if (in.dev == st.st_dev && in.ino == st.st_ino)
      throw InputError(cannot_write(path) + "it is the input file " + quoted(in.path, 200) +
                       ", which would be replaced; expected another output file");
}

// --- paths removed on signals ------------------------------------------------
//
// A list of nodes that is only ever prepended to, so that the signal handler only
// reads memory that is never freed and calls unlink() or rmdir() (async-signal-safe),
// whatever the number of paths registered at once (a field folder may take
// thousands of files). A node is claimed (0 → 2), filled, then published (→ 1); a
// free node (0) is reused by a path that fits. The handler removes the published ones.
class SignalSafePaths {
 public:
  void add(const std::string& path) {
    for (Node* n = m_head.load(); n; n = n->next) {
      int expected = 0;
      if (n->capacity <= path.size() || !n->state.compare_exchange_strong(expected, 2)) continue;
      std::memcpy(n->path, path.c_str(), path.size() + 1);
      n->state.store(1);
      return;
    }
    Node* n = new Node;
    n->capacity = std::max<size_t>(path.size() + 1, 256);
    n->path = new char[n->capacity];
    std::memcpy(n->path, path.c_str(), path.size() + 1);
    n->state.store(1);
    n->next = m_head.load();
    while (!m_head.compare_exchange_weak(n->next, n)) {
    }
  }
  void remove(const std::string& path) {
    for (Node* n = m_head.load(); n; n = n->next)
      if (n->state.load() == 1 && path == n->path) {
        n->state.store(0);
        return;
      }
  }
  /// Calls `action(path)` on every published path (from a signal handler too).
  template <class Action>
  void for_each(Action action) const {
    for (Node* n = m_head.load(); n; n = n->next)
      if (n->state.load() == 1) action(n->path);
  }

 private:
  struct Node {
    std::atomic<int> state{0};
    size_t capacity = 0;
    char* path = nullptr;
    Node* next = nullptr;
  };
  std::atomic<Node*> m_head{nullptr};
};

SignalSafePaths g_temporaries;  // files being written
SignalSafePaths g_folders;      // folders an output created, removed if still empty
SignalSafePaths g_notes;        // lines printed on stderr when a signal ends the process
std::mutex g_note_mutex;
std::string g_note;             // the line in g_notes (set_interrupt_note)
std::string g_next_note_path, g_next_note;  // set_interrupt_note_on_publish

void register_temporary(const std::string& tmp) { g_temporaries.add(tmp); }
void unregister_temporary(const std::string& tmp) { g_temporaries.remove(tmp); }

// While a set of files is being published (SignalsHeld): a signal handled by another
// thread (one this thread's mask does not cover) is only noted, and acted on when the
// set is out.
std::atomic<int> g_publishing{0};
std::atomic<int> g_pending_signal{0};

extern "C" void remove_temporaries_and_end(int sig) {
  if (g_publishing.load() > 0) {
    g_pending_signal.store(sig);
    return;
  }
  g_temporaries.for_each([](const char* path) { ::unlink(path); });
  g_folders.for_each([](const char* path) { ::rmdir(path); });  // fails, harmlessly, unless empty
  g_notes.for_each([](const char* line) { (void)!::write(STDERR_FILENO, line, std::strlen(line)); });
  std::signal(sig, SIG_DFL);
  ::raise(sig);
}

void remove_all(const std::vector<std::string>& tmps) {
  for (const std::string& t : tmps) discard_temporary(t);
}

/// The signals whose default action ends the process and that a handler can catch:
/// each removes the temporaries first (SIGKILL cannot be caught).
constexpr int kEndingSignals[] = {SIGINT,  SIGTERM, SIGHUP,  SIGQUIT,   SIGPIPE, SIGXCPU,
                                  SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF};

/// Holds the ending signals while alive (the renames that publish a set of
/// files complete before a signal is handled): blocked in this thread, and only
/// noted by the handler when another thread of the process receives one.
class SignalsHeld {
 public:
  SignalsHeld() {
    sigset_t set;
    sigemptyset(&set);
    for (int sig : kEndingSignals) sigaddset(&set, sig);
    pthread_sigmask(SIG_BLOCK, &set, &m_old);
    g_publishing.fetch_add(1);
  }
  ~SignalsHeld() {
    if (g_publishing.fetch_sub(1) == 1) {
      const int sig = g_pending_signal.exchange(0);
      if (sig) remove_temporaries_and_end(sig);
    }
    pthread_sigmask(SIG_SETMASK, &m_old, nullptr);
  }

 private:
  sigset_t m_old;
};

}  // namespace

void remove_temporaries_on_signals() {
  struct sigaction sa {};
  sa.sa_handler = remove_temporaries_and_end;
  sigemptyset(&sa.sa_mask);
  for (int sig : kEndingSignals) sigaction(sig, &sa, nullptr);
  // Past a file-size limit (ulimit -f) a write fails with EFBIG instead of ending
  // the process: reported like a full disk, temporaries removed.
  std::signal(SIGXFSZ, SIG_IGN);
}

void set_interrupt_note(const std::string& line) {
  const std::lock_guard<std::mutex> lock(g_note_mutex);
  if (!g_note.empty()) g_notes.remove(g_note);
  g_note = line.empty() || line.back() == '\n' ? line : line + "\n";
  if (!g_note.empty()) g_notes.add(g_note);
}

void set_interrupt_note_on_publish(const std::string& path, const std::string& line) {
  const std::lock_guard<std::mutex> lock(g_note_mutex);
  g_next_note_path = path;
  g_next_note = line;
}

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
    check_not_declared_input(path, st);
  } else if (errno != ENOENT) {
    throw InputError(cannot_write(path) + std::strerror(errno));
  }
  const std::string folder = folder_of(path);
  struct stat dir {};
  if (::stat(folder.c_str(), &dir) != 0)
    throw InputError(cannot_write(path) + "folder " + quoted(folder, 200) + ": " + std::strerror(errno));
  if (!S_ISDIR(dir.st_mode)) throw InputError(cannot_write(path) + quoted(folder, 200) + " is not a folder");
  // A read-only or permission-less folder is found now, not after the work.
  const std::string probe = temporary_path_for(path);
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int err = errno;
    unregister_temporary(probe);
    throw_cannot_create(cannot_write(path) + "cannot create a file in folder " + quoted(folder, 200) + ": ", err);
  }
  ::close(fd);
  discard_temporary(probe);
}

void register_scratch_file(const std::string& path) { g_temporaries.add(path); }
void forget_scratch_file(const std::string& path) { g_temporaries.remove(path); }

void register_created_folder(const std::string& dir) { g_folders.add(dir); }

void forget_created_folder(const std::string& dir) { g_folders.remove(dir); }

void declare_input_files(const std::vector<std::string>& paths) {
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  for (const std::string& path : paths) {
    struct stat st {};
    if (!path.empty() && ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode))
      g_inputs.push_back({path, st.st_dev, st.st_ino});
  }
}

FileLock::FileLock(const std::string& path, const std::function<void()>& on_wait) {
  bool told = false;
  for (;;) {
    m_fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (m_fd < 0) throw InputError("cannot open " + quoted(path, 200) + " to lock it: " + std::strerror(errno));
    if (::flock(m_fd, LOCK_EX | LOCK_NB) != 0) {
      if (!told && on_wait) on_wait();
      told = true;
      while (::flock(m_fd, LOCK_EX) != 0 && errno == EINTR) {
      }
    }
    // The holder before us may have replaced the file (rename): lock the new one.
    struct stat locked {}, named {};
    if (::fstat(m_fd, &locked) == 0 && ::stat(path.c_str(), &named) == 0 && locked.st_dev == named.st_dev &&
        locked.st_ino == named.st_ino)
      return;
    ::close(m_fd);
  }
}

FileLock::~FileLock() {
  if (m_fd >= 0) ::close(m_fd);  // releases the lock
}

std::string temporary_path_for(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  // A hidden name built from at most 40 bytes of the target's name: a target
  // near the file-name limit still gets a valid temporary name.
  const std::string folder = folder_of(path);
  const std::string tmp = (folder == "/" ? "" : folder) + "/." + base_of(path).substr(0, 40) + ".tmp." +
                          std::to_string(::getpid()) + "." + std::to_string(counter++);
  register_temporary(tmp);
  return tmp;
}

void discard_temporary(const std::string& tmp) {
  std::remove(tmp.c_str());
  unregister_temporary(tmp);
}

void commit_temporary(const std::string& tmp, const std::string& path) {
  try {
    check_output_path(path);
  } catch (...) {
    discard_temporary(tmp);
    throw;
  }
  {
    // The file and the note that describes it change together for a signal handler.
    SignalsHeld held;
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
      const int err = errno;
      discard_temporary(tmp);
      throw_cannot_create(cannot_write(path) + "renaming the completed temporary file failed: ", err);
    }
    std::string note;
    {
      const std::lock_guard<std::mutex> lock(g_note_mutex);
      if (!g_next_note_path.empty() && g_next_note_path == path) note = g_next_note, g_next_note_path.clear();
    }
    if (!note.empty()) set_interrupt_note(note);
  }
  unregister_temporary(tmp);
}

void write_files_atomically(const std::vector<std::pair<std::string, FileWriter>>& files) {
  for (const auto& [path, writer] : files) check_output_path(path);
  std::vector<std::string> tmps;
  for (const auto& [path, writer] : files) {
    const std::string tmp = temporary_path_for(path);
    tmps.push_back(tmp);
    std::ofstream out(tmp, std::ios::binary);
    if (!out) {
      const int err = errno;
      remove_all(tmps);
      throw_cannot_create(cannot_write(path), err);
    }
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
      throw WriteFailure(cannot_write(path) + "write failed" + (err ? std::string(": ") + std::strerror(err) : "") +
                         " (disk full?)");
    }
  }
  // Every file is complete: publish them all, with the signals held so that an
  // interrupt cannot leave part of the set published.
  SignalsHeld held;
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
