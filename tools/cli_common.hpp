#pragma once
/// \file cli_common.hpp
/// \brief Small helpers shared by the subcommands.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <variant>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/parallel_for.hpp>
#include <contactrom/fom/input_values.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/online_evaluation.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::cli {

/// Adds a real-valued option checked by the shared validation layer
/// (fom/input_values.hpp): NaN, infinities, trailing text and values outside
/// `range` end the run with one line quoting the value as typed.
inline CLI::Option* add_number(CLI::App* sub, const std::string& name, double& target, const std::string& help,
                               const Interval& range) {
  return sub->add_option_function<std::string>(
                name, [&target, name, range](const std::string& text) { target = parse_number(text, name, range); },
                help)
      ->type_name("NUMBER");
}

/// Adds an integer option in [lower, upper]; "2.5" is refused as not an integer.
template <typename Int>
CLI::Option* add_integer(CLI::App* sub, const std::string& name, Int& target, const std::string& help,
                         long long lower, long long upper) {
  return sub->add_option_function<std::string>(
                name,
                [&target, name, lower, upper](const std::string& text) {
                  target = static_cast<Int>(parse_integer(text, name, lower, upper));
                },
                help)
      ->type_name("INT");
}

/// Adds an option that takes one of `choices` (`names`: "--name" or "--name,--alias");
/// another word ends the run with one line naming the option and the choices.
inline CLI::Option* add_word(CLI::App* sub, const std::string& names, std::string& target, const std::string& help,
                             const std::vector<std::string>& choices) {
  const std::string name = names.substr(0, names.find(','));
  return sub->add_option_function<std::string>(
                names,
                [&target, name, choices](const std::string& text) {
                  if (std::find(choices.begin(), choices.end(), text) == choices.end())
                    throw InputError(name + " " + quoted(text, 200) + " unknown; expected " + join_or(choices));
                  target = text;
                },
                help)
      ->type_name("WORD");
}

/// Adds `--threads`: 0 (the default: all cores) or 1..kMaxThreads, as Python's
/// `threads=`; `help` says what runs on them.
template <typename Int>
CLI::Option* add_threads(CLI::App* sub, Int& target, const std::string& help) {
  return add_integer(sub, "--threads", target, help + " (default 0: all cores)", 0, kMaxThreads);
}

/// Adds flag `name` for the option `key` of an options table (rom/option_table.hpp):
/// its help, default and range or words are the declaration's. `target` (a double, an
/// integer or the word) starts at the struct's default (setting_default()).
template <class S, class T>
CLI::Option* add_setting(CLI::App* sub, const std::string& name, T& target, const rom::OptionTable<S>& table,
                         const std::string& key) {
  const rom::OptionSpec& spec = table.find(key)->spec;
  const std::string help = spec.help + " (default " + spec.default_value + "; as --option " + key + ")";
  if constexpr (std::is_same_v<T, double>)
    return add_number(sub, name, target, help, spec.range);
  else if constexpr (std::is_same_v<T, std::string>)
    return add_word(sub, name, target, help, spec.choices);
  else
    return add_integer(sub, name, target, help, static_cast<long long>(spec.range.lower),
                       static_cast<long long>(std::min(spec.range.upper, 9e18)));
}

/// Adds flag `name` that turns off the flag option `key` of an options table (e.g.
/// --no-polish for polish): `target` starts at the struct's default; help and
/// default are the declaration's.
template <class S>
CLI::Option* add_setting_negation(CLI::App* sub, const std::string& name, bool& target, const rom::OptionTable<S>& table,
                                  const std::string& key) {
  const rom::OptionSpec& spec = table.find(key)->spec;
  return sub->add_flag_callback(name, [&target] { target = false; },
                                "off: " + spec.help + " (default " + spec.default_value + "; as --option " + key + "=false)");
}

/// Help of a setting that several online methods declare (e.g. init): the methods
/// that take it, grouped by what they accept and their default, as declared.
inline std::string shared_setting_help(const std::string& key) {
  std::vector<std::pair<std::string, std::string>> groups;  // (methods, accepted values and default)
  for (const rom::OnlineMethod& m : rom::online_methods())
    for (const rom::OptionSpec& s : m.options) {
      if (s.key != key) continue;
      const std::string values = rom::describe_option_type(s) + "; default " + s.default_value;
      auto g = std::find_if(groups.begin(), groups.end(), [&](const auto& x) { return x.second == values; });
      if (g == groups.end())
        groups.emplace_back(m.name, values);
      else
        g->first += "/" + m.name;
    }
  std::string out;
  for (const auto& [methods, values] : groups) out += (out.empty() ? "" : "; ") + methods + ": " + values;
  return out;
}

/// The default of the option `key` of the active-set settings, typed as T.
template <class T>
T setting_default(const std::string& key) {
  const rom::OptionValue v = rom::active_set_settings_table().to_values(rom::ActiveSetSettings{}).at(key);
  if constexpr (std::is_same_v<T, std::string>)
    return std::get<std::string>(v);
  else if constexpr (std::is_same_v<T, double>)
    return std::get<double>(v);
  else
    return static_cast<T>(std::get<long long>(v));
}

/// Validator of a file or folder option: an empty value ("--out ''") is refused
/// rather than read as "not given".
inline CLI::Validator non_empty_path() {
  return CLI::Validator(
      [](std::string& value) {
        return value.empty() ? std::string("'' is empty; expected a path") : std::string();
      },
      "PATH");
}

/// Declares the problem's file and mesh as inputs of the command (declare_input_files():
/// no output may replace them), then checks `outputs` again against them.
inline void declare_problem_inputs(const fom::Problem& problem, const std::vector<std::string>& outputs = {}) {
  declare_input_files({problem.definition().path, problem.definition().mesh});
  for (const std::string& out : outputs)
    if (!out.empty()) check_output_path(out);
}

/// A parameter as a JSON number (one value) or array (several).
/// The text of a JSON report: file names are bytes, not always UTF-8, so an invalid
/// sequence is printed as U+FFFD instead of failing after the work is done.
inline std::string json_text(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

inline nlohmann::json param_json(const fom::Param& mu) {
  if (mu.size() == 1) return mu(0);
  return std::vector<double>(mu.data(), mu.data() + mu.size());
}

/// The four KKT residuals as a JSON object.
inline nlohmann::json kkt_json(const fom::KktResiduals& k) {
  return {{"stationarity", k.stationarity},
          {"penetration", k.penetration},
          {"negative_pressure", k.negative_pressure},
          {"complementarity", k.complementarity}};
}

/// Adds a library summary (rom::summary_values and its kin) to the JSON object `j`.
inline void append_summary_json(nlohmann::json& j, const rom::SummaryValues& values) {
  for (const auto& [key, value] : values) std::visit([&j, &k = key](const auto& v) { j[k] = v; }, value);
}

/// Warns on stderr when δ left no POD mode: the reduced displacement is then the
/// offset alone and no contact can be enforced, whatever the dual method.
inline void warn_if_no_primal_modes(const rom::ReducedModel& model) {
  if (model.primal_rank() == 0)
    std::cerr << "contactrom: warning: delta " << model.delta()
              << " keeps no POD mode (primal rank 0); the reduced solution is the offset alone"
                 " and no contact can be enforced; expected a delta well below 1 (paper: 1e-6 to 1e-10)\n";
}

/// The options that choose a reduced model and its online method (`online`, `reduce`).
struct MethodArgs {
  std::string method = "greedy", offset = "harmonic";
  std::string tau_scaling = setting_default<std::string>("tau_scaling");
  double delta = 1e-8, tau = setting_default<double>("tau");
  int max_iterations = setting_default<int>("max_iterations");
  std::vector<std::string> options;  // KEY=VALUE method settings

  /// The reduced-model settings (δ, offset).
  rom::ReducedModelOptions model_options() const {
    rom::ReducedModelOptions o;
    o.delta = delta;
    o.offset = offset == "dirichlet" ? rom::OffsetKind::Dirichlet : rom::OffsetKind::Harmonic;
    return o;
  }
  /// The online settings; \throws InputError for an --option without '='.
  rom::OnlineSolverOptions solver_options() const {
    // --option KEY=VALUE pairs and the named flags, checked against the method's
    // declared options (rom/online_methods.hpp).
    std::map<std::string, std::string> values;
    for (const std::string& kv : options) {
      auto [key, value] = rom::split_option(kv);
      values[key] = value;
    }
    rom::OnlineSolverOptions o = rom::options_from_map(method, values);
    if (!values.count("tau")) o.tau = tau;
    if (!values.count("tau_scaling")) rom::active_set_settings_table().read(o, "tau_scaling", tau_scaling, "--tau-scaling");
    if (!values.count("max_iterations")) o.max_iterations = max_iterations;
    return o;
  }
};

/// Adds --method, --delta, --tau, --tau-scaling, --offset (alias --lifting), --max-iterations, --option.
inline void add_method_options(CLI::App* sub, MethodArgs& a) {
  sub->add_option("--method", a.method, "online method (default greedy; listed below)");
  sub->footer(rom::describe_online_methods());
  add_number(sub, "--delta", a.delta, "POD energy tolerance of the primal basis (default 1e-8)", Interval::closed(0, 1));
  add_setting(sub, "--tau", a.tau, rom::active_set_settings_table(), "tau");
  add_setting(sub, "--tau-scaling", a.tau_scaling, rom::active_set_settings_table(), "tau_scaling");
  add_word(sub, "--offset,--lifting", a.offset,
           "offset of the reduced displacement: harmonic (default; unconstrained FOM response) | dirichlet"
           " (--lifting: the same option)",
           {"harmonic", "dirichlet"});
  add_setting(sub, "--max-iterations", a.max_iterations, rom::active_set_settings_table(), "max_iterations");
  sub->add_option("--option", a.options, "method setting KEY=VALUE, repeatable; each method's keys are listed below");
}

}  // namespace contactrom::cli
