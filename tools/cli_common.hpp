#pragma once
/// \file cli_common.hpp
/// \brief Small helpers shared by the subcommands.
#include <iostream>
#include <nlohmann/json.hpp>

#include "fom/kkt.hpp"
#include "fom/problem.hpp"
#include "rom/reduced_model.hpp"

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

/// Warns on stderr when δ left no POD mode: the reduced displacement is then the
/// offset alone and no contact can be enforced, whatever the dual method.
inline void warn_if_no_primal_modes(const rom::ReducedModel& model) {
  if (model.primal_rank() == 0)
    std::cerr << "contactrom: warning: delta " << model.delta()
              << " keeps no POD mode (primal rank 0); the reduced solution is the lifting alone"
                 " and no contact can be enforced; expected a delta well below 1 (paper: 1e-6 to 1e-10)\n";
}

}  // namespace contactrom::cli
