#include <contactrom/baselines/online_methods.hpp>

#include <algorithm>

#include <contactrom/baselines/cpg.hpp>
#include <contactrom/baselines/full_dictionary.hpp>
#include <contactrom/baselines/reduced_active_set.hpp>

namespace contactrom::baselines {
namespace {

std::vector<rom::OnlineMethod> table() {
  return {rom::make_online_method("cpg", "active set on a cone-projected greedy dual basis (Benaceur et al. 2020)",
                                  make_cpg_solver, reduced_active_set_option_table(), cpg_option_table()),
          rom::make_online_method("full-dictionary", "active set on the whole dual dictionary, without sparsity",
                                  make_full_dictionary_solver, reduced_active_set_option_table())};
}

/// Registers the baselines once, at static initialisation.
const bool registered = [] {
  for (rom::OnlineMethod& m : table()) rom::register_online_method(std::move(m));
  return true;
}();

}  // namespace

std::vector<rom::OnlineMethod> baseline_online_methods() {
  std::vector<rom::OnlineMethod> methods = table();
  for (const rom::OnlineMethod& m : methods) rom::register_online_method(m);
  return methods;
}

std::vector<rom::OnlineMethod> builtin_online_methods() {
  std::vector<rom::OnlineMethod> all = rom::rom_online_methods();
  for (rom::OnlineMethod& m : baseline_online_methods()) all.push_back(std::move(m));
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  return all;
}

}  // namespace contactrom::baselines

/// Anchor kept by the linker option of the contactrom::baselines target
/// (`--undefined=contactrom_baselines_online_methods`), so that this object file,
/// and with it the registration above, is part of every program linking the
/// library.
extern "C" int contactrom_baselines_online_methods() { return contactrom::baselines::registered ? 1 : 0; }
