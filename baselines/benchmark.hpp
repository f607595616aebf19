#pragma once
/// \file benchmark.hpp
/// \brief Median per-query times of the FOM solvers and of every online method,
/// all measured in the same run so that their ratios are meaningful on a noisy
/// machine: what `contactrom bench` computes, as one library call.
///
/// The FOM (active set, factorisation reused) and every ROM are timed in
/// interleaved rounds (rom::time_interleaved: one pass of each per round after a
/// warm-up pass), each ROM also through a twin clocking its contact-operator
/// construction (the paper's timing convention, times without it). Ipopt is timed
/// on fewer queries (it is slow).
///
/// \code
///   const auto report = contactrom::baselines::benchmark(model, rom::database_validation_set(db, problem));
///   // report.fom_active_set_s, report.methods[k].timing.median_core_s, report.ratios
/// \endcode
/// Command line: `contactrom bench --problem hertz --json`.
#include <map>
#include <string>
#include <vector>

#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::baselines {

/// \brief One timed configuration of an online method.
struct BenchVariant {
  std::string key;                            ///< report key, e.g. "rom_greedy"
  std::string method;                         ///< registry name
  std::map<std::string, std::string> options;  ///< settings (rom::options_from_map)
};

/// \brief Every registered method with its defaults (key `rom_<method>`, '-' as
/// '_'), then the variants that make the comparison honest: the greedy schedules
/// started as in the paper's Alg. 1 (`rom_greedy_init_empty`,
/// `rom_greedy_nested_init_empty`) and CPG warm-started like the greedy (`rom_cpg_warm`).
/// Every variant is timed without the error estimate of its answers (option
/// `estimate`), except `rom_greedy_with_estimate`, the default greedy with it.
std::vector<BenchVariant> default_bench_variants();

/// \brief Settings of benchmark() (documented defaults).
struct BenchOptions {
  std::vector<BenchVariant> variants = default_bench_variants();  ///< what to time
  int repeats = 3;          ///< interleaved timing rounds. Default 3.
  int queries = 30;         ///< parameters timed (evenly thinned); ≤ 0: all. Default 30.
  int ipopt_queries = 5;    ///< parameters timed for Ipopt; 0: Ipopt not timed. Default 5.
};

/// \brief Timing of one variant.
struct BenchMethod {
  BenchVariant variant;     ///< what was timed
  rom::OnlineTiming timing;  ///< medians (core, with reconstruction, without operators)
};

/// \brief Everything benchmark() measured.
struct BenchReport {
  int queries = 0;                          ///< parameters timed
  double fom_active_set_s = 0.0;            ///< median FOM time per query
  std::vector<double> fom_active_set_rounds;  ///< the FOM median of each round (the machine's noise)
  /// Median time of the same queries at their known pairing (fom::ActiveSetSolver::
  /// solve_at: one QP, one back-substitution, the certificate): the FOM's limit, timed
  /// in rounds interleaved with FOM queries (0 when the stiffness depends on μ).
  double fom_limit_s = 0.0;
  double fom_pairing_iterations = 0.0;      ///< mean pairing iterations of the FOM queries
  double fom_zone_iterations = 0.0;         ///< mean contact-zone solves of the FOM queries
  double fom_ipopt_s = 0.0;                 ///< median Ipopt time per query (0 if not timed)
  int ipopt_queries = 0;                    ///< parameters timed for Ipopt
  std::vector<BenchMethod> methods;         ///< the variants that apply, in order
  /// Variants that do not apply to the problem (key → the InputError's message),
  /// e.g. convex-hull on a non-convex feasible set.
  std::map<std::string, std::string> not_applicable;
  /// Quotients of the medians: "fom_ipopt/fom_active_set", "fom_active_set/fom_limit",
  /// "fom_active_set/<key>",
  /// the greedy without its warm start against with it, and every baseline against
  /// both greedy schedules (also without the operators' construction).
  std::map<std::string, double> ratios;
};

/// \brief Times the FOM, Ipopt and every variant on `model` over `params` (thinned
/// to BenchOptions::queries), on the calling thread.
BenchReport benchmark(const rom::ReducedModel& model, const std::vector<fom::Param>& params,
                      const BenchOptions& options = {});

}  // namespace contactrom::baselines
