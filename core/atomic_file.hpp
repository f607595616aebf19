#pragma once
/// \file atomic_file.hpp
/// \brief Write files atomically: content goes to a temporary file in the same
/// folder, which is renamed over the target only once it is complete, so a
/// failed or interrupted run never leaves a partial output file. A set of files
/// (e.g. a VTU and its CSV) is written completely before any of them is
/// published.
///
/// Output targets are checked first: an existing target must be a regular file.
/// A symbolic link, a folder, a device, a pipe or a socket given as output is
/// refused (replacing it would destroy the link or the device node, not write
/// into it), as is an empty name, a folder that does not exist or one in which no
/// file can be created. A target that is one of the command's input files (same
/// device and inode, whatever the names) is refused as well.
///
/// Failures of the machine while writing (disk full, I/O error) throw WriteFailure,
/// not InputError: the CLI reports them with exit code 1. The temporary files being
/// written are removed when the process is ended by a signal it can catch (SIGINT,
/// SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXCPU, SIGUSR1/2, SIGALRM, SIGVTALRM, SIGPROF;
/// remove_temporaries_on_signals(), which also makes a file-size limit a write
/// failure rather than SIGXFSZ), and a set of files is published only after
/// all of it was written.
#include <functional>
#include <stdexcept>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace contactrom {

/// \brief The machine could not write a complete output file (disk full, I/O
/// error): not bad input. The temporary file is removed before it is thrown.
class WriteFailure : public std::runtime_error {
 public:
  explicit WriteFailure(const std::string& message) : std::runtime_error(message) {}
};

/// \brief Writes the content of one file to a stream.
using FileWriter = std::function<void(std::ostream&)>;

/// \brief Throws InputError (one line, naming `path` and why) unless `path` can
/// be written as an output file: non-empty, its folder exists and a file can be
/// created in it (a temporary file is created and removed), and it is either
/// absent or a regular file (not a symbolic link, folder, device, pipe or socket)
/// that is not a declared input (declare_input_files()). Commands call it before
/// any long computation.
void check_output_path(const std::string& path);

/// \brief Declares files the running program reads (a command's problem file, mesh,
/// database, parameter list): from then on check_output_path() — and so every write
/// of this file's functions — refuses a target that is one of them (same device and
/// inode: another name, a hard link or a relative path of the file count as the
/// same). Paths that do not name an existing file are ignored. The declarations last
/// for the life of the process; the command-line tool makes them, a program
/// embedding the library may.
void declare_input_files(const std::vector<std::string>& paths);

/// \brief Registers a folder just created to hold outputs: the signal handlers of
/// remove_temporaries_on_signals() remove it if it is still empty, until
/// forget_created_folder().
void register_created_folder(const std::string& dir);
/// \brief Ends register_created_folder(dir) (the outputs in it are published).
void forget_created_folder(const std::string& dir);

/// \brief Registers a published file that is scratch (e.g. in a temporary folder of
/// register_created_folder()): the signal handlers of remove_temporaries_on_signals()
/// remove it, until forget_scratch_file().
void register_scratch_file(const std::string& path);
/// \brief Ends register_scratch_file(path).
void forget_scratch_file(const std::string& path);

/// \brief Installs handlers of the catchable signals that end a process (SIGINT,
/// SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXCPU, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM,
/// SIGPROF) that remove the temporary files being written (write_file_atomically(),
/// temporary_path_for()) and then end the process by the same signal (its default
/// action), and ignores SIGXFSZ (a write past `ulimit -f` then fails with EFBIG and
/// is reported like a full disk). A process ended by SIGKILL (or the kernel's
/// out-of-memory killer) leaves its temporaries, named `.NAME.tmp.PID.K` beside the
/// output. Called by the command-line tool; a program embedding the library may
/// call it (it replaces the program's handlers of those signals).
void remove_temporaries_on_signals();

/// \brief A line the handlers of remove_temporaries_on_signals() print on stderr
/// before the process ends, e.g. what an interrupted run has kept; it replaces the
/// previous one ("": none).
void set_interrupt_note(const std::string& line);

/// \brief set_interrupt_note(line) at the moment `path` is next published (renamed
/// into place), with the signals held: a handler never sees the file and the note
/// disagree.
void set_interrupt_note_on_publish(const std::string& path, const std::string& line);

/// \brief An exclusive lock on an existing file that is updated by read, modify
/// and rename (`offline --append`): held from construction to destruction, so a
/// second updater waits until the first has published its file, then reads that.
/// The lock is taken on the file the path names *after* any rename by the holder
/// before it (the path is opened again until the locked file is still the one the
/// path names).
class FileLock {
 public:
  /// \param on_wait called once if another process holds the lock (before waiting)
  /// \throws InputError naming `path` if it cannot be opened.
  explicit FileLock(const std::string& path, const std::function<void()>& on_wait = {});
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int m_fd = -1;
};

/// \brief Calls `writer` on a stream to a temporary file next to `path`, then
/// renames it to `path`. Throws InputError naming `path` and the system's reason
/// if the target is refused by check_output_path, the folder is not writable or
/// the stream fails; the temporary file is removed on any failure (including an
/// exception thrown by `writer`).
void write_file_atomically(const std::string& path, const FileWriter& writer);

/// \brief Writes every (path, writer) to its temporary file first and renames
/// them into place only once all were written: a failure leaves none of them.
void write_files_atomically(const std::vector<std::pair<std::string, FileWriter>>& files);

/// \brief Returns a unique temporary path next to `path` (same folder, so that
/// rename() is atomic; a short hidden name, so that a long `path` does not
/// exceed the file-name limit); for libraries such as HDF5 that write by name.
/// The path is registered for removal on signals until commit_temporary() or
/// discard_temporary().
std::string temporary_path_for(const std::string& path);

/// \brief Renames `tmp` to `path` after check_output_path(path); removes `tmp`
/// and throws InputError naming `path` and the system's reason on failure.
void commit_temporary(const std::string& tmp, const std::string& path);

/// \brief Removes `tmp` (from the disk and from the files removed on signals).
void discard_temporary(const std::string& tmp);

}  // namespace contactrom
