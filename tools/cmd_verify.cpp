// contactrom verify --db DB.h5 --method M[,M2,...] [--delta D] [--tau T] [--tau-scaling S]
//                   [--cpg-tolerance E] [--inner-solve nonnegative|equality]
//                   [--reference ipopt|fom] [--threads T] [--limit N] [--bench] [--repeats R] [--out FILE.csv] [--progress] [--json]
//                   [--option KEY=VALUE]...
// KKT verification of reduced solutions against the Ipopt reference (or the FOM,
// --reference fom): baselines::verify (baselines/verification.hpp) computes it, this
// file parses the arguments and prints. --bench adds the median online time per
// query and the FOM time, timed in interleaved rounds.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>

#include <contactrom/baselines/cpg.hpp>
#include <contactrom/baselines/full_dictionary.hpp>
#include <contactrom/baselines/ipopt_qp.hpp>
#include <contactrom/baselines/kkt_verifier.hpp>
#include <contactrom/baselines/reduced_active_set.hpp>
#include <contactrom/baselines/verification.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/parameter_space.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_timing.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace contactrom::cli {
namespace {


struct VerifyArgs {
  std::string db, methods, reference = "ipopt", out, inner_solve, init;
  std::string tau_scaling = setting_default<std::string>("tau_scaling");
  double delta = 1e-8, tau = setting_default<double>("tau"), cpg_tolerance = baselines::CpgOptions{}.tolerance;
  int threads = 0, max_iterations = setting_default<int>("max_iterations"), limit = 0, repeats = 3;
  bool json = false, progress = false, bench = false;
  std::vector<std::string> options;  // --option KEY=VALUE, for every listed method that declares KEY
};

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

/// The methods of --method with the settings of the flags each knows: --cpg-tolerance
/// concerns cpg, --inner-solve the reduced active sets (cpg, full-dictionary), --init
/// the methods with a warm start (each checks the value itself); an --option goes to
/// every listed method that declares its key and overrides the flag of that key.
std::vector<baselines::VerifyMethod> methods_of(const VerifyArgs& a) {
  std::map<std::string, std::string> extra;
  for (const std::string& kv : a.options) {
    auto [key, value] = rom::split_option(kv);
    extra[key] = value;
  }
  std::set<std::string> used;
  std::vector<baselines::VerifyMethod> out;
  for (const std::string& m : split_list(a.methods, "--method")) {
    const rom::OnlineMethod method = rom::online_method(m);  // unknown names are refused before the database is read
    std::map<std::string, std::string> values;
    if (m == "cpg" && a.cpg_tolerance >= 0.0) values["cpg_tolerance"] = format_number(a.cpg_tolerance);
    if ((m == "cpg" || m == "full-dictionary") && !a.inner_solve.empty()) values["inner_solve"] = a.inner_solve;
    if ((m == "greedy" || m == "greedy-nested" || m == "cpg" || m == "full-dictionary") && !a.init.empty())
      values["init"] = a.init;
    for (const auto& [key, value] : extra)
      if (method.option(key)) values[key] = value, used.insert(key);
    rom::OnlineSolverOptions o = rom::options_from_map(m, values);
    if (!values.count("tau")) o.tau = a.tau;
    if (!values.count("tau_scaling")) rom::active_set_settings_table().read(o, "tau_scaling", a.tau_scaling, "--tau-scaling");
    if (!values.count("max_iterations")) o.max_iterations = a.max_iterations;
    out.push_back({m, o});
  }
  for (const auto& [key, value] : extra)
    if (!used.count(key))
      throw InputError("--option " + key + "=" + value + ": none of the methods '" + a.methods +
                       "' has a setting '" + key + "' (each method's settings are listed by verify --help)");
  return out;
}

nlohmann::json method_json(const baselines::MethodVerification& r, const rom::ReducedModel& model, bool bench,
                           double fom_time) {
  nlohmann::json j;
  j["method"] = r.name;
  j["primal_rank"] = model.primal_rank();
  j["dictionary_size"] = model.dictionary_size();
  j["dual_basis_size"] = r.dual_columns.size();
  j["tau"] = r.tau;
  j["reduced_constraint"] = r.reduced_constraint;
  j["max_kkt"] = kkt_json(r.summary.max_kkt);
  rom::SummaryValues errors;
  rom::append_error_values(errors, r.errors);
  append_summary_json(j, errors);
  j["max_active_set_differences"] = r.summary.max_active_set_differences;
  j["invalid"] = r.summary.invalid;
  j["max_reduced_penetration"] = r.max_reduced_penetration;
  j["reduced_penetration_violations"] = r.reduced_violations;
  j["reduced_penetration_ok"] = r.reduced_violations == 0;
  j["nonconverged"] = r.nonconverged;
  j["inaccurate"] = r.inaccurate;
  j["mean_iterations"] = r.mean_iterations;
  j["mean_sparsity"] = r.mean_sparsity;
  j["mean_time_s"] = r.mean_time_s;
  if (r.name == "cpg") j["basis_time_s"] = r.basis_time_s;
  if (bench) {
    j["median_time_s"] = r.timing.median_core_s;
    j["median_total_time_s"] = r.timing.median_total_s;
    j["speedup_vs_fom"] = r.timing.median_core_s > 0.0 ? fom_time / r.timing.median_core_s : 0.0;
    // −1 for methods that do not clock their operator construction (convex-hull).
    j["median_time_without_operators_s"] = r.timing.median_without_operators_s;
  }
  return j;
}

void print_table(const VerifyArgs& a, const baselines::VerifyReport& report) {
  const fom::KktResiduals& ref_max = report.reference_summary.max_kkt;
  auto cell = [](const std::string& s, int w) {
    std::ostringstream o;
    o << std::left << std::setw(w) << s;
    return o.str();
  };
  std::cout << cell("", 18) << cell("dual", 6) << cell("stationar.", 11) << cell("penetr.", 10) << cell("neg.press.", 11)
            << cell("complem.", 10) << cell("primal err", 11) << cell("dual err", 10) << cell("red. pen.", 11)
            << cell("tau", 10) << "not conv.\n";
  std::cout << cell(a.reference + " reference", 18) << cell("-", 6) << cell(sci(ref_max.stationarity), 11)
            << cell(sci(ref_max.penetration), 10) << cell(sci(ref_max.negative_pressure), 11)
            << cell(sci(ref_max.complementarity), 10) << cell("-", 11) << cell("-", 10) << cell("-", 11)
            << cell("-", 10) << report.reference_failures << "\n";
  for (const baselines::MethodVerification& r : report.methods)
    std::cout << cell(r.name, 18) << cell(std::to_string(r.dual_columns.size()), 6)
              << cell(sci(r.summary.max_kkt.stationarity), 11) << cell(sci(r.summary.max_kkt.penetration), 10)
              << cell(sci(r.summary.max_kkt.negative_pressure), 11) << cell(sci(r.summary.max_kkt.complementarity), 10)
              << cell(sci(r.errors.max_primal_error), 11) << cell(sci(r.errors.max_dual_error), 10) << cell(sci(r.max_reduced_penetration), 11)
              << cell(sci(r.tau), 10) << r.nonconverged << "\n";
}

baselines::VerifyOptions verify_options(const VerifyArgs& a) {
  baselines::VerifyOptions options;
  options.methods = methods_of(a);
  if (a.reference != "ipopt" && a.reference != "fom")
    throw InputError("--reference " + quoted(a.reference, 200) + " unknown; expected ipopt or fom");
  options.reference = a.reference;
  options.threads = a.threads;
  options.bench = a.bench;
  options.repeats = a.repeats;
  return options;
}

/// Progress bars on stderr, one per stage (label); finish() ends the last one.
struct StageProgress {
  bool show;
  std::unique_ptr<ProgressBar> bar;
  std::string stage;
  void update(const std::string& label, int done, int total) {
    if (label != stage) {
      finish();
      bar = std::make_unique<ProgressBar>(std::cerr, "verify: " + label, show);
      stage = label;
    }
    bar->update(done, total);
  }
  void finish() {
    if (bar) bar->finish();
  }
};

void print_json(const VerifyArgs& a, const rom::SnapshotDatabase& db, const rom::ReducedModel& model,
                const baselines::VerifyReport& report) {
  nlohmann::json j;
  j["problem"] = model.problem().name();
  j[db.training_kind] = db.training_size;
  j["delta"] = model.delta();
  j["validation_size"] = report.params.size();
  j["reference"] = {{"solver", a.reference},
                    {"failures", report.reference_failures},
                    {"max_kkt", kkt_json(report.reference_summary.max_kkt)},
                    {"wall_time_s", report.reference_wall_s}};
  j["reduced_penetration_slack"] = report.reduced_penetration_slack;
  j["methods"] = nlohmann::json::object();
  for (const auto& r : report.methods) j["methods"][r.name] = method_json(r, model, a.bench, report.fom_median_time_s);
  if (a.bench) j["fom_median_time_s"] = report.fom_median_time_s;
  std::cout << json_text(j) << std::endl;
}

void print_text(const VerifyArgs& a, const rom::SnapshotDatabase& db, const rom::ReducedModel& model,
                const baselines::VerifyReport& report) {
  const double fom_time = report.fom_median_time_s;
  std::cout << "verify " << model.problem().name() << " (" << db.training_kind << " " << db.training_size
            << "): " << report.params.size() << " validation parameters, primal rank " << model.primal_rank()
            << " (delta " << model.delta() << "), dictionary " << model.dictionary_size() << "\n"
            << "reference " << a.reference << ": " << report.reference_failures << " failures, " << std::setprecision(3)
            << report.reference_wall_s << " s\n"
            << "maximum over the validation set (KKT residuals are full-order and relative, see fom/kkt.hpp):\n";
  print_table(a, report);
  for (const baselines::MethodVerification& r : report.methods) {
    std::cout << r.name << ": mean primal error " << sci(r.errors.mean_primal_error) << ", mean dual error "
              << sci(r.errors.mean_dual_error)
              << ", mean |I| " << std::setprecision(3) << r.mean_sparsity << ", mean iterations " << r.mean_iterations
              << ", mean time " << r.mean_time_s * 1e6 << " us";
    if (r.errors.absolute_error_rows)
      std::cout << "; " << r.errors.absolute_error_rows << " parameters with a near-zero reference displacement "
                << "left out of the errors (absolute: max primal " << sci(r.errors.max_absolute_primal_error)
                << ", max dual " << sci(r.errors.max_absolute_dual_error) << ")";
    if (r.reduced_constraint)
      std::cout << "; reduced penetration <= tau + " << report.reduced_penetration_slack << ": "
                << (r.reduced_violations ? "VIOLATED at " + std::to_string(r.reduced_violations) + " parameters"
                                         : std::string("yes"));
    if (a.bench)
      std::cout << "; median " << r.timing.median_core_s * 1e6 << " us, "
                << (r.timing.median_core_s > 0.0 ? fom_time / r.timing.median_core_s : 0.0) << "x faster than the FOM";
    if (a.bench && r.timing.median_without_operators_s >= 0.0)
      std::cout << " (" << r.timing.median_without_operators_s * 1e6 << " us without building the contact operators)";
    std::cout << "\n";
  }
  if (a.bench) std::cout << "FOM (factorisation reused): median " << fom_time * 1e3 << " ms per query\n";
  if (!a.out.empty()) std::cout << "per-parameter results written to " << a.out << "\n";
}

void run_verify(const VerifyArgs& a) {
  declare_input_files({a.db});
  if (!a.out.empty()) check_output_path(a.out);
  baselines::VerifyOptions options = verify_options(a);
  const rom::SnapshotDatabase db = rom::read_database(a.db);
  auto problem = rom::problem_from_database(db, a.db);
  declare_problem_inputs(*problem, {a.out});
  rom::ReducedModelOptions model_options;
  model_options.delta = a.delta;
  const rom::ReducedModel model(*problem, db, model_options);
  warn_if_no_primal_modes(model);
  const std::vector<fom::Param> params = baselines::subsample(rom::database_validation_set(db, *problem), a.limit);
  StageProgress progress{a.progress || ::isatty(STDERR_FILENO), nullptr, ""};
  options.progress = [&](const std::string& label, int done, int total) { progress.update(label, done, total); };
  const baselines::VerifyReport report = baselines::verify(model, params, options);
  progress.finish();
  if (!a.out.empty()) baselines::write_verify_csv(a.out, *problem, report);
  if (a.json)
    print_json(a, db, model, report);
  else
    print_text(a, db, model, report);
}

CommandRegistrar reg("verify", [](CLI::App& app) {
  auto args = std::make_shared<VerifyArgs>();
  auto* sub = app.add_subcommand("verify", "KKT verification of reduced solutions against the Ipopt reference");
  sub->add_option("--db", args->db, "snapshot database written by contactrom offline")
      ->check(non_empty_path())->required();
  sub->add_option("--method", args->methods, "online method(s), comma-separated (e.g. greedy,cpg,full-dictionary)")
      ->required();
  add_number(sub, "--delta", args->delta, "POD energy tolerance of the primal basis (default 1e-8)", Interval::closed(0, 1));
  add_setting(sub, "--tau", args->tau, rom::active_set_settings_table(), "tau");
  add_setting(sub, "--tau-scaling", args->tau_scaling, rom::active_set_settings_table(), "tau_scaling");
  add_setting(sub, "--max-iterations", args->max_iterations, rom::active_set_settings_table(), "max_iterations");
  add_setting(sub, "--cpg-tolerance", args->cpg_tolerance, baselines::cpg_option_table(), "cpg_tolerance");
  add_setting(sub, "--inner-solve", args->inner_solve, baselines::reduced_active_set_option_table(), "inner_solve");
  sub->add_option("--init", args->init, "starting point of the methods that take one (as --option init): " +
                                             shared_setting_help("init"));
  sub->add_option("--reference", args->reference, "reference solver: ipopt (default) | fom (custom active set)");
  add_threads(sub, args->threads, "threads for the reference solves");
  add_integer(sub, "--limit", args->limit, "use N evenly spaced validation parameters (default: all)", 1, 1000000);
  sub->add_flag("--bench", args->bench, "also time each method and the FOM, in interleaved rounds (rom::time_interleaved)");
  add_integer(sub, "--repeats", args->repeats, "timing passes over the parameters with --bench (default 3)", 1, 1000);
  sub->add_option("--out", args->out, "CSV file with one row per method and parameter")
      ->check(non_empty_path());
  sub->add_flag("--progress", args->progress, "draw progress bars even when stderr is not a terminal");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->add_option("--option", args->options,
                  "method setting KEY=VALUE, repeatable; given to every listed method that has the setting (each "
                  "method's keys are listed below)");
  sub->footer(rom::describe_online_methods());
  sub->callback([args] { run_verify(*args); });
});

}  // namespace
}  // namespace contactrom::cli
