#include <contactrom/fom/input_values.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>

namespace contactrom {
namespace {

std::string format_bound(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  // Shortest text that reads back to v (0.3, not 0.29999999999999999).
  for (int digits = 1; digits <= 17; ++digits) {
    char shorter[64];
    std::snprintf(shorter, sizeof shorter, "%.*g", digits, v);
    if (std::strtod(shorter, nullptr) == v) return shorter;
  }
  return buf;
}

std::string integer_range_text(long long lower, long long upper) {
  return "an integer in [" + std::to_string(lower) + ", " + std::to_string(upper) + "]";
}

}  // namespace

std::string trim_blanks(const std::string& text) {
  const char* blanks = " \t\r\n";
  const size_t begin = text.find_first_not_of(blanks);
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(blanks);
  return text.substr(begin, end - begin + 1);
}

bool Interval::contains(double value) const {
  const bool above = lower_open ? value > lower : value >= lower;
  const bool below = upper_open ? value < upper : value <= upper;
  return above && below;
}

std::string Interval::text() const {
  const bool has_lower = std::isfinite(lower), has_upper = std::isfinite(upper);
  if (has_lower && has_upper)
    return std::string("a number in ") + (lower_open ? "(" : "[") + format_bound(lower) + ", " + format_bound(upper) +
           (upper_open ? ")" : "]");
  if (has_lower) return std::string("a number ") + (lower_open ? "> " : ">= ") + format_bound(lower);
  if (has_upper) return std::string("a number ") + (upper_open ? "< " : "<= ") + format_bound(upper);
  return "a finite number";
}

double parse_number(const std::string& text, const std::string& what) {
  const std::string t = trim_blanks(text);
  if (t.empty()) throw InputError(what + " " + quoted(text) + " is empty; expected a number");
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(t.c_str(), &end);
  const int err = errno;
  // strtod also reads C's hexadecimal floats (0x1p-3), which Python, TOML and CSV
  // readers elsewhere do not: decimal numbers only, the same everywhere.
  if (end == t.c_str() || end != t.c_str() + t.size() || t.find_first_of("xX") != std::string::npos)
    throw InputError(what + " " + quoted(text) + " is not a number");
  if (!std::isfinite(value)) {
    if (err == ERANGE) throw InputError(what + " " + quoted(text) + " is too large for a double");
    throw InputError(what + " " + quoted(text) + " is not a finite number");
  }
  // ERANGE with a subnormal result is a number; with zero it underflowed.
  if (err == ERANGE && value == 0.0) throw InputError(what + " " + quoted(text) + " underflows to 0");
  return value;
}

double parse_number(const std::string& text, const std::string& what, const Interval& range) {
  double value = 0.0;
  try {
    value = parse_number(text, what);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + "; expected " + range.text());
  }
  if (!range.contains(value)) throw InputError(what + " " + quoted(text) + " is outside the range; expected " + range.text());
  return value;
}

long long parse_integer(const std::string& text, const std::string& what, long long lower, long long upper) {
  const std::string t = trim_blanks(text);
  const std::string expected = "; expected " + integer_range_text(lower, upper);
  if (t.empty()) throw InputError(what + " " + quoted(text) + " is empty" + expected);
  size_t i = (t[0] == '+' || t[0] == '-') ? 1 : 0;
  const bool digits = i < t.size() && t.find_first_not_of("0123456789", i) == std::string::npos;
  if (!digits) throw InputError(what + " " + quoted(text) + " is not an integer" + expected);
  errno = 0;
  const long long value = std::strtoll(t.c_str(), nullptr, 10);
  if (errno == ERANGE || value < lower || value > upper)
    throw InputError(what + " " + quoted(text) + " is outside the range" + expected);
  return value;
}

std::vector<std::string> split_list(const std::string& text, const std::string& what) {
  std::vector<std::string> items;
  size_t start = 0;
  for (;;) {
    const size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (trim_blanks(item).empty()) {
      const std::string where = text.find(',') == std::string::npos ? "is empty"
                                : comma == std::string::npos      ? "has an empty value after its last comma"
                                : start == 0                      ? "has an empty value before its first comma"
                                                                  : "has an empty value between two commas";
      throw InputError(what + " " + quoted(text) + " " + where + "; expected values separated by single commas");
    }
    items.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

fom::Param parse_problem_param(const fom::Problem& problem, const std::string& text) {
  return problem.parameters().parse(text, problem.name());
}

}  // namespace contactrom
