#pragma once
/// \file atomic_file.hpp
/// \brief Write files atomically: content goes to a temporary file in the same
/// folder, which is renamed over the target only once it is complete, so a
/// failed or interrupted run never leaves a partial output file.
#include <functional>
#include <ostream>
#include <string>

namespace contactrom {

/// \brief Calls `writer` on a stream to a temporary file next to `path`, then
/// renames it to `path`. Throws InputError naming `path` if the folder is not
/// writable or the stream fails; the temporary file is removed on any failure
/// (including an exception thrown by `writer`).
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& writer);

/// \brief Returns a unique temporary path next to `path` (same folder, so that
/// rename() is atomic); for libraries such as HDF5 that write by file name.
std::string temporary_path_for(const std::string& path);

/// \brief Renames `tmp` to `path`; throws InputError naming both on failure.
void commit_temporary(const std::string& tmp, const std::string& path);

}  // namespace contactrom
