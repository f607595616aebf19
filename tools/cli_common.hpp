#pragma once
/// \file cli_common.hpp
/// \brief Small helpers shared by the subcommands.
#include <CLI/CLI.hpp>
#include <iostream>
#include <nlohmann/json.hpp>

#include "fom/input_values.hpp"
#include "fom/kkt.hpp"
#include "fom/problem.hpp"
#include "rom/reduced_model.hpp"

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

/// Validator of a file or folder option: an empty value ("--out ''") is refused
/// rather than read as "not given".
inline CLI::Validator non_empty_path() {
  return CLI::Validator(
      [](std::string& value) {
        return value.empty() ? std::string("'' is empty; expected a path") : std::string();
      },
      "PATH");
}

/// A parameter as a JSON number (one value) or array (several).
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

/// Warns on stderr when δ left no POD mode: the reduced displacement is then the
/// offset alone and no contact can be enforced, whatever the dual method.
inline void warn_if_no_primal_modes(const rom::ReducedModel& model) {
  if (model.primal_rank() == 0)
    std::cerr << "contactrom: warning: delta " << model.delta()
              << " keeps no POD mode (primal rank 0); the reduced solution is the lifting alone"
                 " and no contact can be enforced; expected a delta well below 1 (paper: 1e-6 to 1e-10)\n";
}

}  // namespace contactrom::cli
