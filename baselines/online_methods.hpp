#pragma once
/// \file online_methods.hpp
/// \brief The complete table of online methods: those of contactrom::rom
/// (`greedy`, `greedy-nested`, `convex-hull`) and the baselines (`cpg`,
/// `full-dictionary`).
///
/// Linking contactrom::baselines registers the baselines with the registry of
/// rom/online_methods.hpp before main() runs: its CMake target passes the linker
/// `--undefined=contactrom_baselines_online_methods`, which keeps the registering
/// object file of the static library (a shared library registers when loaded).
/// No call is needed; a program linked by other means than CMake can call
/// baseline_online_methods() once to the same effect.
#include <vector>

#include <contactrom/rom/online_methods.hpp>

namespace contactrom::baselines {

/// \brief The methods of contactrom::baselines (`cpg`, `full-dictionary`) with
/// their declared options; also makes sure they are registered.
std::vector<rom::OnlineMethod> baseline_online_methods();

/// \brief Every built-in online method (rom's and the baselines'), sorted by name.
std::vector<rom::OnlineMethod> builtin_online_methods();

}  // namespace contactrom::baselines
