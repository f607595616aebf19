#pragma once
/// \file format.hpp
/// \brief Text helpers shared by the libraries and the CLI: numbers written so that
/// they read back exactly, comma-separated lists, and quoted input for messages.
#include <cstddef>
#include <string>
#include <vector>

namespace contactrom {

/// \brief Shortest text that reads back as the same double: "%.{6..17}g", the first
/// precision whose strtod() gives `value` again (e.g. 0.1 → "0.1", 1/3 →
/// "0.33333333333333331"); "nan", "inf", "-inf" for non-finite values.
std::string format_number(double value);

/// \brief `items` separated by `separator` (default ", "): {"a", "b"} → "a, b".
std::string join(const std::vector<std::string>& items, const std::string& separator = ", ");

/// \brief The choices of a message: {"a", "b", "c"} → "a, b or c".
std::string join_or(const std::vector<std::string>& items);

/// \brief `text` between single quotes, fit for a one-line message: control
/// bytes are written as `\xNN`, and text beyond `max_length` bytes is cut
/// and marked with "... (N bytes)".
std::string quoted(const std::string& text, std::size_t max_length = 80);


}  // namespace contactrom
