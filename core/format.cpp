#include <contactrom/core/format.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace contactrom {

std::string format_number(double value) {
  // printf's %.<digits>g with the fewest digits (6 to 17) that read back as `value`;
  // to_chars/from_chars give the same text without the locale and formatting
  // machinery (a query CSV of 20,000 rows spent a third of its time here).
  if (!std::isfinite(value)) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%g", value);
    return buf;
  }
  char buf[64];
  std::to_chars_result end{};
  for (int digits = 6; digits <= 17; ++digits) {
    end = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, digits);
    double back = 0.0;
    std::from_chars(buf, end.ptr, back);
    if (back == value) break;
  }
  return std::string(buf, end.ptr);
}

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += separator;
    out += items[i];
  }
  return out;
}

std::string join_or(const std::vector<std::string>& items) {
  if (items.size() < 2) return join(items);
  return join(std::vector<std::string>(items.begin(), items.end() - 1)) + " or " + items.back();
}

std::string quoted(const std::string& text, std::size_t max_length) {
  std::string out = "'";
  const size_t shown = std::min(text.size(), max_length);
  for (size_t i = 0; i < shown; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  out += "'";
  if (shown < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

}  // namespace contactrom
