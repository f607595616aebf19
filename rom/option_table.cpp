#include <contactrom/rom/option_table.hpp>

#include <cmath>

#include <contactrom/core/format.hpp>

namespace contactrom::rom {

std::string option_text(const OptionValue& value) {
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const long long* i = std::get_if<long long>(&value)) return std::to_string(*i);
  if (const double* d = std::get_if<double>(&value)) return format_number(*d);
  return std::get<std::string>(value);
}

std::string describe_option_type(const OptionSpec& spec) {
  switch (spec.type) {
    case OptionType::Number: return spec.range.text();
    case OptionType::Integer: {
      const Interval& r = spec.range;
      auto whole = [](double v) { return std::to_string(static_cast<long long>(v)); };
      if (r.upper >= 1e9) return "an integer >= " + whole(r.lower);
      return "an integer in [" + whole(r.lower) + ", " + whole(r.upper) + "]";
    }
    case OptionType::Choice: return join_or(spec.choices);  // "a, b or c", as the methods' own messages say
    case OptionType::Flag: return "true or false (1 or 0)";
    case OptionType::Text: return "a non-empty word";
  }
  return "";
}

namespace {

[[noreturn]] void refuse(const OptionSpec& spec, const std::string& text, const std::string& what) {
  throw InputError(what + " = " + quoted(text) + " invalid; expected " + describe_option_type(spec));
}

long long integer_bound(double bound) { return static_cast<long long>(std::clamp(bound, -9e18, 9e18)); }

}  // namespace

OptionValue parse_option_value(const OptionSpec& spec, const std::string& text, const std::string& what) {
  switch (spec.type) {
    case OptionType::Number: return parse_number(text, what, spec.range);
    case OptionType::Integer:
      return parse_integer(text, what, integer_bound(spec.range.lower), integer_bound(spec.range.upper));
    case OptionType::Choice:
      if (std::find(spec.choices.begin(), spec.choices.end(), text) == spec.choices.end()) break;
      return text;
    case OptionType::Flag:
      if (text == "true" || text == "1") return true;
      if (text == "false" || text == "0") return false;
      break;
    case OptionType::Text:
      if (text.empty()) break;
      return text;
  }
  refuse(spec, text, what);
}

void check_option_value(const OptionSpec& spec, const OptionValue& value, const std::string& what) {
  bool ok = true;
  switch (spec.type) {
    case OptionType::Number: {
      const double v = std::get<double>(value);
      ok = std::isfinite(v) && spec.range.contains(v);
      break;
    }
    case OptionType::Integer: {
      const long long v = std::get<long long>(value);
      ok = v >= integer_bound(spec.range.lower) && v <= integer_bound(spec.range.upper);
      break;
    }
    case OptionType::Choice: {
      const std::string& w = std::get<std::string>(value);
      ok = std::find(spec.choices.begin(), spec.choices.end(), w) != spec.choices.end();
      break;
    }
    case OptionType::Flag: break;
    case OptionType::Text: ok = !std::get<std::string>(value).empty(); break;
  }
  if (!ok) refuse(spec, option_text(value), what);
}

}  // namespace contactrom::rom
