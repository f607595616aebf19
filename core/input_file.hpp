#pragma once
/// \file input_file.hpp
/// \brief Input files read whole into memory (CSV, problem files) are regular files
/// of bounded size: a device (`/dev/zero`), a pipe or a folder given as input, or a
/// file beyond the stated size, is refused before anything is read, so that no
/// input can make a command read until memory runs out.
#include <cstdint>
#include <string>

namespace contactrom {

/// \brief Throws InputError (one line, naming `label` and the quoted `path`) unless
/// `path` is a readable regular file of at most `max_bytes` bytes.
void check_input_file(const std::string& path, const std::string& label, std::uintmax_t max_bytes);

/// \brief The content of `path` after check_input_file(), without a leading UTF-8
/// byte-order mark (which some editors write, and which no one can see in a message).
std::string read_input_file(const std::string& path, const std::string& label, std::uintmax_t max_bytes);

}  // namespace contactrom
