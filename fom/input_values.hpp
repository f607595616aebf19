#pragma once
/// \file input_values.hpp
/// \brief One validation layer for every number a user types: command-line
/// options, `--param` lists, `--option KEY=VALUE` settings.
///
/// A value is accepted only if the whole text (blanks around it aside) is a
/// finite number in the expected interval; integers must be written as integers.
/// Every refusal throws InputError with one line that quotes the text exactly as
/// given (not a rounded copy) and says what was expected, e.g.
///   `--tau 'nan' is not a finite number; expected a number >= 0`
///   `--train '2.5' is not an integer; expected an integer in [1, 100000]`
///   `parameter d = '0.30000000001' is outside the range of 'hertz'; expected d in (0, 0.3]`.
/// Subnormal numbers such as 5e-324 are numbers; values that underflow to zero
/// or overflow to infinity are refused.
#include <limits>
#include <string>
#include <vector>

#include <contactrom/core/format.hpp>  // quoted()
#include <contactrom/fom/problem.hpp>

namespace contactrom {

/// \brief An interval of accepted real values; bounds may be open or infinite.
struct Interval {
  double lower = -std::numeric_limits<double>::infinity();  ///< lower bound (default: none)
  double upper = std::numeric_limits<double>::infinity();   ///< upper bound (default: none)
  bool lower_open = false;                                   ///< whether the lower bound is excluded
  bool upper_open = false;                                   ///< whether the upper bound is excluded

  /// Whether `value` (finite) lies in the interval.
  bool contains(double value) const;
  /// "a number in [0, 1]", "a number >= 0", "a number > 0", "a number".
  std::string text() const;

  static Interval any() { return {}; }
  static Interval closed(double a, double b) { return {a, b, false, false}; }
  static Interval at_least(double a) { return {a, std::numeric_limits<double>::infinity(), false, false}; }
  static Interval greater_than(double a) { return {a, std::numeric_limits<double>::infinity(), true, false}; }
};

/// \brief Parses `text` as one finite number.
/// \param what how the value is named in messages, e.g. "--tau" or "parameter d".
/// \throws InputError naming `what` and quoting `text` if it is empty, not a number,
///   has trailing characters, is NaN or infinite, or underflows/overflows.
double parse_number(const std::string& text, const std::string& what);

/// \brief parse_number(), then checks `range`; the message quotes `text`.
double parse_number(const std::string& text, const std::string& what, const Interval& range);

/// \brief Parses `text` as an integer (optional sign and decimal digits only) in
/// [lower, upper]; "2.5" is "not an integer", "1e9999" is "not an integer".
long long parse_integer(const std::string& text, const std::string& what, long long lower, long long upper);

/// \brief Splits a comma-separated list; refuses an empty list and empty items
/// ("0.1," or ",0.1" or "0.1,,0.2"), naming `what` and quoting `text`.
std::vector<std::string> split_list(const std::string& text, const std::string& what);

/// \brief `text` without its leading and trailing blanks (space, tab, CR, LF).
std::string trim_blanks(const std::string& text);

/// \brief Parses "V" or "V1,V2,..." into a parameter of `problem`: the number of
/// values and each value's range are checked, and a value outside its range is
/// quoted exactly as written. The same parser as fom::parse_param
/// (fom::ParameterSpace::parse).
fom::Param parse_problem_param(const fom::Problem& problem, const std::string& text);

}  // namespace contactrom
