#pragma once
/// \file full_dictionary.hpp
/// \brief The full-dictionary baseline: the standard (non-sparse) primal–dual
/// active-set method of baselines/reduced_active_set.hpp with the whole dual
/// dictionary as dual basis, W = D_d — every column is available at every
/// iteration and any number may enter or leave the active set at once (no sparsity
/// control). It isolates what the greedy's one-change-per-iteration rule buys.
///
/// Exact command lines (see docs/baselines.md):
/// \code
///   contactrom offline --problem hertz --train 30 --out hertz30.h5
///   contactrom online  --db hertz30.h5 --method full-dictionary --validation --json
///   contactrom verify  --db hertz30.h5 --method full-dictionary --json
/// \endcode
#include <memory>

#include <contactrom/baselines/reduced_active_set.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::baselines {

/// \brief ReducedActiveSet with W = D_d (all dictionary columns, in order).
class FullDictionaryActiveSet final : public ReducedActiveSet {
 public:
  explicit FullDictionaryActiveSet(const rom::ReducedModel& model, const ReducedActiveSetOptions& options = {});
};

/// \brief Registry factory of "full-dictionary" (reads tau, tau_scaling,
/// max_iterations, step_tolerance).
std::unique_ptr<rom::OnlineSolver> make_full_dictionary_solver(const rom::ReducedModel& model,
                                                               const rom::OnlineSolverOptions& options);

}  // namespace contactrom::baselines
