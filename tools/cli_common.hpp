#pragma once
/// \file cli_common.hpp
/// \brief Small JSON helpers shared by the subcommands.
#include <nlohmann/json.hpp>

#include "fom/kkt.hpp"
#include "fom/problem.hpp"

namespace contactrom::cli {

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

}  // namespace contactrom::cli
