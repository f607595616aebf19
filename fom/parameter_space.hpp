#pragma once
/// \file parameter_space.hpp
/// \brief The parameters of a problem (names, ranges, checks, parsing) and the
/// affine expressions of them that problem files use for material and boundary data.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include <contactrom/core/format.hpp>

namespace contactrom::fom {

using Param = Eigen::VectorXd;

/// \brief A box of named parameters; each range is [lo, hi], or (lo, hi] when
/// its lower bound is open.
struct ParameterSpace {
  std::vector<std::string> names;  ///< in order: `--param V1,V2` follows it
  Eigen::VectorXd lower, upper;    ///< bounds, lower < upper
  std::vector<char> lower_open;    ///< per parameter: whether lo is excluded

  int size() const { return static_cast<int>(names.size()); }
  /// Index of a parameter, −1 if there is none of that name.
  int index_of(const std::string& name) const;
  /// Appends a parameter. \throws InputError if lo ≥ hi, a bound is not finite or the name is taken.
  void add(const std::string& name, double lo, double hi, bool open_lower = false);
  /// Whether μ lies in the box (and has the right size).
  bool contains(const Param& mu) const;
  /// \throws InputError naming the first value outside its range and the range, e.g.
  /// "parameter d = 0.30000000001 is outside the range of 'hertz'; expected d in (0, 0.3]".
  void check(const Param& mu, const std::string& problem_name) const;
  /// Human-readable ranges, e.g. "d in (0, 0.3]" or "d_x in [0, 4], d_y in [0.1, 0.3]".
  std::string range_text() const;
  /// A parameter in messages, e.g. "d = 0.15" or "d_x = 2, d_y = 0.1" (mu of another
  /// size: its values alone, "mu = 2, 0.1").
  std::string text(const Param& mu) const;
  /// \brief Parses "V" or "V1,V2,..." (one value per parameter, in order) and checks the range:
  /// the one parser of parameter text (fom::parse_param, parse_problem_param).
  /// \throws InputError for an empty item, a non-number (trailing characters, NaN,
  ///   infinite, overflowing or underflowing to 0), a wrong count, or a value out of
  ///   range (quoted exactly as written).
  Param parse(const std::string& text, const std::string& problem_name) const;
};

/// \brief An affine function of the parameters, \f$ a_0 + \sum_i a_i \mu_i \f$.
struct AffineExpression {
  double constant = 0.0;
  Eigen::VectorXd coefficients;  ///< one per parameter

  static AffineExpression constant_value(double value, int num_params);
  double operator()(const Param& mu) const { return constant + coefficients.dot(mu); }
  bool is_constant() const { return coefficients.size() == 0 || coefficients.cwiseAbs().maxCoeff() == 0.0; }
  /// Minimum and maximum over the parameter box (attained at corners).
  double min_over(const ParameterSpace& space) const;
  double max_over(const ParameterSpace& space) const;
};

/// \brief Parses an affine expression: a sum of terms joined by `+`/`-`, each a
/// number, a parameter name, or `number*name` (e.g. "-d", "0.5*dx + 0.1").
/// \throws InputError whose message says what is wrong (unknown name, product of
/// two parameters, stray characters) and lists the parameter names; the caller
/// prefixes it with the file, line and key.
AffineExpression parse_affine_expression(const std::string& text, const ParameterSpace& space);

}  // namespace contactrom::fom
