#include "baselines/online_methods.hpp"

#include <algorithm>

#include "baselines/cpg.hpp"
#include "baselines/full_dictionary.hpp"

namespace contactrom::baselines {
namespace {

rom::OptionSpec choice(std::string key, std::string def, std::string help, std::vector<std::string> choices) {
  return {std::move(key), rom::OptionType::Choice, std::move(def), std::move(help), std::move(choices), {}};
}

/// Options of the reduced active sets (cpg and full-dictionary).
std::vector<rom::OptionSpec> reduced_active_set_specs() {
  std::vector<rom::OptionSpec> o = rom::active_set_option_specs();
  o.push_back(choice("init", "empty", "starting point: empty, primal or cell", {"empty", "primal", "cell"}));
  o.push_back(choice("inner_solve", "nonnegative", "saddle-point solve: nonnegative or equality (textbook PDAS)",
                     {"nonnegative", "equality"}));
  o.push_back(choice("rebuild", "partial", "contact operators rebuilt on the changed rows only (partial) or all (full)",
                     {"partial", "full"}));
  o.push_back({"anderson_depth", rom::OptionType::Integer, "5", "Anderson depth of the rebuild point (0: plain)", {},
               Interval::closed(0, 1e6)});
  o.push_back({"surface_step", rom::OptionType::Number, "1e-3",
               "largest move of the contact surface (units of U) between the operators' point and the answer", {},
               Interval::greater_than(0)});
  o.push_back({"max_solves", rom::OptionType::Integer, "1000", "cap on the saddle-point solves of a query", {},
               Interval::closed(1, 1e9)});
  return o;
}

std::vector<rom::OnlineMethod> table() {
  std::vector<rom::OptionSpec> cpg = reduced_active_set_specs();
  cpg.push_back({"cpg_tolerance", rom::OptionType::Number, "problem's [rom] cpg_tolerance, else 1e-2",
                 "cone-projected greedy: worst relative projection error", {}, Interval::closed(0, 1)});
  cpg.push_back({"cpg_max_size", rom::OptionType::Integer, "0", "cap on the CPG basis size (0: none)", {},
                 Interval::closed(0, 1e9)});
  return {{"cpg", "active set on a cone-projected greedy dual basis (Benaceur et al. 2020)", cpg, make_cpg_solver},
          {"full-dictionary", "active set on the whole dual dictionary, without sparsity", reduced_active_set_specs(),
           make_full_dictionary_solver}};
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
