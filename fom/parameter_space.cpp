#include <contactrom/fom/parameter_space.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/input_values.hpp>

namespace contactrom::fom {

int ParameterSpace::index_of(const std::string& name) const {
  for (int i = 0; i < size(); ++i)
    if (names[i] == name) return i;
  return -1;
}

void ParameterSpace::add(const std::string& name, double lo, double hi, bool open_lower) {
  if (index_of(name) >= 0) throw InputError("parameter " + quoted(name, 200) + " is defined twice; expected distinct names");
  // The width must be finite too: sampling plans and grids step through it.
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi) || !std::isfinite(hi - lo))
    throw InputError("parameter " + quoted(name, 200) + " has range [" + format_number(lo) + ", " + format_number(hi) +
                     "]; expected finite bounds with lo < hi and a finite width hi - lo");
  names.push_back(name);
  lower.conservativeResize(size());
  upper.conservativeResize(size());
  lower(size() - 1) = lo;
  upper(size() - 1) = hi;
  lower_open.push_back(open_lower ? 1 : 0);
}

bool ParameterSpace::contains(const Param& mu) const {
  if (mu.size() != size()) return false;
  for (int i = 0; i < size(); ++i) {
    const bool below = lower_open[i] ? !(mu(i) > lower(i)) : !(mu(i) >= lower(i));
    if (below || !(mu(i) <= upper(i))) return false;
  }
  return true;
}

void ParameterSpace::check(const Param& mu, const std::string& problem_name) const {
  if (mu.size() != size())
    throw InputError("problem " + quoted(problem_name, 200) + " takes " + std::to_string(size()) + " parameter value(s) (" +
                     range_text() + "), got " + std::to_string(mu.size()));
  for (int i = 0; i < size(); ++i) {
    const bool below = lower_open[i] ? !(mu(i) > lower(i)) : !(mu(i) >= lower(i));
    if (below || !(mu(i) <= upper(i)))
      throw InputError("parameter " + names[i] + " = " + format_number(mu(i)) + " is outside the range of '" +
                       problem_name + "'; expected " + range_text());
  }
}

std::string ParameterSpace::range_text() const {
  std::string out;
  for (int i = 0; i < size(); ++i) {
    if (i) out += ", ";
    out += names[i] + " in " + (lower_open[i] ? "(" : "[") + format_number(lower(i)) + ", " +
           format_number(upper(i)) + "]";
  }
  return out;
}

std::string ParameterSpace::text(const Param& mu) const {
  const bool named = mu.size() == size();
  std::string out = named ? "" : "mu = ";
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    if (i) out += ", ";
    if (named) out += names[static_cast<size_t>(i)] + " = ";
    out += format_number(mu(i));
  }
  return out;
}

Param ParameterSpace::parse(const std::string& text, const std::string& problem_name) const {
  const std::string expected = "; expected " + range_text();
  std::vector<std::string> items;
  try {
    items = split_list(text, "--param");
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (" + range_text() + ")");
  }
  if (static_cast<int>(items.size()) != size())
    throw InputError("problem " + quoted(problem_name, 200) + " takes " + std::to_string(size()) +
                     " parameter value(s), but --param " + quoted(text) + " has " + std::to_string(items.size()) +
                     expected);
  Param mu(size());
  for (int i = 0; i < size(); ++i) {
    const std::string what = "parameter " + names[i] + " =";
    try {
      mu(i) = parse_number(items[i], what);
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + expected);
    }
    const Interval range{lower(i), upper(i), lower_open[i] != 0, false};
    // A value outside its range is quoted exactly as written.
    if (!range.contains(mu(i)))
      throw InputError(what + " " + quoted(trim_blanks(items[i])) + " is outside the range of " + quoted(problem_name, 200) +
                       expected);
  }
  return mu;
}

AffineExpression AffineExpression::constant_value(double value, int num_params) {
  AffineExpression e;
  e.constant = value;
  e.coefficients = Eigen::VectorXd::Zero(num_params);
  return e;
}

double AffineExpression::min_over(const ParameterSpace& space) const {
  double v = constant;
  for (int i = 0; i < coefficients.size(); ++i)
    v += coefficients(i) * (coefficients(i) > 0 ? space.lower(i) : space.upper(i));
  return v;
}

double AffineExpression::max_over(const ParameterSpace& space) const {
  double v = constant;
  for (int i = 0; i < coefficients.size(); ++i)
    v += coefficients(i) * (coefficients(i) > 0 ? space.upper(i) : space.lower(i));
  return v;
}

namespace {

/// Recursive-descent reader of `[+|-] term {(+|-) term}`, term = number | name | number*name.
class AffineReader {
 public:
  AffineReader(const std::string& text, const ParameterSpace& space) : m_text(text), m_space(space) {}

  AffineExpression read() {
    AffineExpression e = AffineExpression::constant_value(0.0, m_space.size());
    skip_space();
    if (at_end()) fail("is empty");
    double sign = 1.0;
    if (peek() == '+' || peek() == '-') sign = take() == '-' ? -1.0 : 1.0;
    term(sign, e);
    for (skip_space(); !at_end(); skip_space()) {
      const char op = take();
      if (op != '+' && op != '-') fail(std::string("has '") + op + "' where '+' or '-' was expected");
      term(op == '-' ? -1.0 : 1.0, e);
    }
    return e;
  }

 private:
  void term(double sign, AffineExpression& e) {
    skip_space();
    if (at_end()) fail("ends with an operator");
    if (is_name_start(peek())) {
      add_name(sign, e);
      check_no_product();
      return;
    }
    const double value = sign * number();
    skip_space();
    if (!at_end() && peek() == '*') {
      take();
      skip_space();
      if (at_end() || !is_name_start(peek())) fail("has a product that is not number*name");
      add_name(value, e);
      check_no_product();
      return;
    }
    e.constant += value;
  }
  void check_no_product() {
    skip_space();
    if (!at_end() && (peek() == '*' || peek() == '/'))
      fail("multiplies or divides a parameter (an affine expression has terms number, name or number*name)");
  }
  void add_name(double factor, AffineExpression& e) {
    const size_t start = m_pos;
    while (!at_end() && (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_')) ++m_pos;
    const std::string name = m_text.substr(start, m_pos - start);
    const int i = m_space.index_of(name);
    if (i < 0) fail("names the unknown parameter " + quoted(name, 200));
    e.coefficients(i) += factor;
  }
  double number() {
    const char* begin = m_text.c_str() + m_pos;
    char* stop = nullptr;
    const double v = std::strtod(begin, &stop);
    if (stop == begin || !std::isfinite(v)) fail("has '" + std::string(1, peek()) + "' where a number or a parameter name was expected");
    // strtod also reads "inf", "nan" and hex; accept plain decimal numbers only.
    for (const char* c = begin; c < stop; ++c)
      if (!std::isdigit(static_cast<unsigned char>(*c)) && *c != '.' && *c != 'e' && *c != 'E' && *c != '+' &&
          *c != '-')
        fail("has the number '" + std::string(begin, static_cast<size_t>(stop - begin)) + "'; expected a decimal number");
    m_pos += static_cast<size_t>(stop - begin);
    return v;
  }
  static bool is_name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
  bool at_end() const { return m_pos >= m_text.size(); }
  char peek() const { return m_text[m_pos]; }
  char take() { return m_text[m_pos++]; }
  void skip_space() {
    while (!at_end() && std::isspace(static_cast<unsigned char>(peek()))) ++m_pos;
  }
  [[noreturn]] void fail(const std::string& what) const {
    std::string names;
    for (int i = 0; i < m_space.size(); ++i) names += (i ? ", " : "") + m_space.names[i];
    throw InputError("expression " + quoted(m_text, 200) + " " + what + "; expected a number or an affine expression of the parameters (" +
                     (names.empty() ? "none defined" : names) + "), e.g. \"-d\" or \"0.5*d + 0.1\"");
  }

  const std::string& m_text;
  const ParameterSpace& m_space;
  size_t m_pos = 0;
};

}  // namespace

AffineExpression parse_affine_expression(const std::string& text, const ParameterSpace& space) {
  return AffineReader(text, space).read();
}

}  // namespace contactrom::fom
