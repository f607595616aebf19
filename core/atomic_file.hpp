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
/// into it), as is an empty name or a folder that does not exist.
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace contactrom {

/// \brief Writes the content of one file to a stream.
using FileWriter = std::function<void(std::ostream&)>;

/// \brief Throws InputError (one line, naming `path` and why) unless `path` can
/// be written as an output file: non-empty, its folder exists, and it is either
/// absent or a regular file (not a symbolic link, folder, device, pipe or socket).
/// Commands call it before any long computation.
void check_output_path(const std::string& path);

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
std::string temporary_path_for(const std::string& path);

/// \brief Renames `tmp` to `path` after check_output_path(path); removes `tmp`
/// and throws InputError naming `path` and the system's reason on failure.
void commit_temporary(const std::string& tmp, const std::string& path);

}  // namespace contactrom
