#include <contactrom/baselines/full_dictionary.hpp>

#include <numeric>

namespace contactrom::baselines {
namespace {
std::vector<int> all_columns(const rom::ReducedModel& model) {
  std::vector<int> columns(static_cast<size_t>(model.dictionary_size()));
  std::iota(columns.begin(), columns.end(), 0);
  return columns;
}
}  // namespace

FullDictionaryActiveSet::FullDictionaryActiveSet(const rom::ReducedModel& model, const ReducedActiveSetOptions& options)
    : ReducedActiveSet("full-dictionary", model, all_columns(model), options) {}

std::unique_ptr<rom::OnlineSolver> make_full_dictionary_solver(const rom::ReducedModel& model,
                                                               const rom::OnlineSolverOptions& options) {
  return std::make_unique<FullDictionaryActiveSet>(model, reduced_active_set_options(options, "full-dictionary"));
}

}  // namespace contactrom::baselines
