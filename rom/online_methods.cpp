#include "rom/online_methods.hpp"

#include <algorithm>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/format.hpp"
#include "fom/input_values.hpp"
#include "fom/parameter_space.hpp"
#include "rom/convex_hull.hpp"
#include "rom/greedy_active_set.hpp"

namespace contactrom::rom {
namespace {

/// Methods of contactrom::baselines, named in the message a program gets when it
/// asks for one of them without linking that library.
const std::vector<std::string> kBaselineMethods{"cpg", "full-dictionary"};

OptionSpec number(std::string key, std::string def, std::string help, Interval range = Interval::any()) {
  return {std::move(key), OptionType::Number, std::move(def), std::move(help), {}, range};
}

OptionSpec integer(std::string key, std::string def, std::string help, double lower, double upper) {
  return {std::move(key), OptionType::Integer, std::move(def), std::move(help), {}, Interval::closed(lower, upper)};
}

OptionSpec choice(std::string key, std::string def, std::string help, std::vector<std::string> choices) {
  return {std::move(key), OptionType::Choice, std::move(def), std::move(help), std::move(choices), {}};
}

OptionSpec flag(std::string key, std::string def, std::string help) {
  return {std::move(key), OptionType::Flag, std::move(def), std::move(help), {}, {}};
}

/// The tolerances of the full-order contact check that every online method runs.
OptionSpec penetration_tolerance_spec() {
  return number("penetration_tolerance", "-1",
                "largest penetration (units of U) of an answer reported success; < 0: the problem's [rom] value, else 5e-2");
}
OptionSpec complementarity_tolerance_spec() {
  return number("complementarity_tolerance", "-1",
                "largest separation under pressure (units of U) of an answer reported success; < 0: the problem's "
                "[rom] value, else 5e-2");
}

/// The error estimate that every online method makes of its answers.
OptionSpec estimate_spec() {
  return flag("estimate", "true",
              "estimate the primal and dual errors of every answer at the full order on the contact surface");
}

}  // namespace

std::vector<OptionSpec> active_set_option_specs() {
  return {number("tau", "-1", "penetration threshold of the reduced constraint; < 0: delta of the model"),
          choice("tau_scaling", "absolute", "absolute (paper) or relative to the dictionary's force scale",
                 {"absolute", "relative"}),
          integer("max_iterations", "50", "iteration cap k_max", 1, 1e6),
          number("step_tolerance", "1e-5", "relative change of u_hat under which the iteration may stop",
                 Interval::at_least(0)),
          flag("time_operators", "false", "measure the time spent building the contact operators"),
          penetration_tolerance_spec(), complementarity_tolerance_spec(), estimate_spec()};
}

namespace {

std::vector<OptionSpec> greedy_specs(bool with_schedule) {
  std::vector<OptionSpec> o = active_set_option_specs();
  o.push_back(choice("init", "cell", "starting point: empty (paper Alg. 1), cell, nearest or primal",
                     {"empty", "cell", "nearest", "primal"}));
  if (with_schedule)
    o.push_back(choice("schedule", "fixed-point",
                       "fixed-point (exact reduced solves, Anderson on the rebuild point), interleaved (one change "
                       "per rebuild, Alg. 1 with safeguards), paper (Alg. 1 exactly) or nested",
                       {"fixed-point", "interleaved", "paper", "nested"}));
  o.push_back(integer("anderson_depth", "5", "nested schedule: Anderson depth of the rebuild point (0: plain)", 0, 1e6));
  if (with_schedule)
    o.push_back(number("surface_step", "1e-3",
                     "fixed-point schedule: largest move of the contact surface (units of U) between the operators' "
                     "point and the answer",
                     Interval::greater_than(0)));
  o.push_back(integer("max_solves", "1000", "nested schedule: cap on the one-change solves of a query", 1, 1e9));
  o.push_back(choice("rebuild", "partial", "contact operators rebuilt on the changed rows only (partial) or all (full)",
                     {"partial", "full"}));
  if (with_schedule)
    o.push_back(choice("on_cycle", "nested", "interleaved schedule: on a revisited selection switch to nested, or continue",
                       {"nested", "continue"}));
  return o;
}

std::vector<OptionSpec> convex_hull_specs() {
  return {choice("basis", "svd", "projection basis: truncated SVD or random combinations", {"svd", "random"}),
          number("basis_delta", "-1", "energy tolerance of the SVD basis; < 0: delta of the model"),
          integer("rank_l", "0", "random basis: number of combinations (0: rank of the SVD basis)", 1, 100000),
          integer("seed", "42", "random basis: seed of the generator", 0, 9e15),
          number("sum_weight", "0.1", "weight of the convexity row relative to the largest column norm"),
          flag("polish", "true", "re-solve the simplex-constrained least squares on the support"),
          integer("max_pairing_iterations", "20", "cap of the pairing fixed point", 1, 1e6),
          integer("selection_iterations", "3", "pairing loop: full nnFOCUSS solves before the support is frozen", 1,
                  1e6),
          integer("anderson_depth", "3", "Anderson depth of the pairing fixed point (on the surface displacement)", 0,
                  100),
          number("pairing_tolerance", "1e-8",
                 "pairing fixed point: largest relative change of contact forces and gaps on re-pairing"),
          number("residual_tolerance", "0.1", "largest relative projected residual reported as success",
                 Interval::at_least(0)),
          integer("focuss_max_iterations", "100", "nnFOCUSS iteration cap", 1, 1e6),
          number("focuss_tolerance", "1e-10", "nnFOCUSS stopping tolerance"),
          number("prune_tolerance", "1e-8", "nnFOCUSS pruning threshold"),
          penetration_tolerance_spec(),
          complementarity_tolerance_spec(),
          estimate_spec()};
}

struct Registry {
  std::mutex mutex;
  std::map<std::string, OnlineMethod> methods;
};

/// The registry, holding the methods of contactrom::rom from the start. A
/// function-local static, so that registrars running during static
/// initialisation (contactrom::baselines) find it constructed.
Registry& registry() {
  static Registry* r = [] {
    auto* reg = new Registry;  // never destroyed: registrars may outlive static destruction order
    for (OnlineMethod& m : rom_online_methods()) reg->methods[m.name] = std::move(m);
    return reg;
  }();
  return *r;
}

const OptionSpec* find_spec(const OnlineMethod& m, const std::string& key) {
  for (const OptionSpec& s : m.options)
    if (s.key == key) return &s;
  return nullptr;
}

bool is_shared(const std::string& key) {
  const auto& keys = shared_option_keys();
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

/// Text of a named field of OnlineSolverOptions.
std::string shared_value(const OnlineSolverOptions& o, const std::string& key) {
  if (key == "tau") return fom::format_number(o.tau);
  if (key == "tau_scaling") return o.tau_scaling;
  if (key == "max_iterations") return std::to_string(o.max_iterations);
  if (key == "step_tolerance") return fom::format_number(o.step_tolerance);
  if (key == "penetration_tolerance") return fom::format_number(o.penetration_tolerance);
  if (key == "complementarity_tolerance") return fom::format_number(o.complementarity_tolerance);
  if (key == "estimate") return o.estimate ? "true" : "false";
  return o.time_operators ? "true" : "false";  // time_operators
}

bool flag_value(const std::string& text) { return text == "true" || text == "1"; }

/// Sets a named field from its (validated) text.
void set_shared(OnlineSolverOptions& o, const std::string& key, const std::string& value) {
  if (key == "tau")
    o.tau = parse_number(value, key);
  else if (key == "tau_scaling")
    o.tau_scaling = value;
  else if (key == "max_iterations")
    o.max_iterations = static_cast<int>(parse_integer(value, key, 1, std::numeric_limits<int>::max()));
  else if (key == "step_tolerance")
    o.step_tolerance = parse_number(value, key);
  else if (key == "penetration_tolerance")
    o.penetration_tolerance = parse_number(value, key);
  else if (key == "complementarity_tolerance")
    o.complementarity_tolerance = parse_number(value, key);
  else if (key == "estimate")
    o.estimate = flag_value(value);
  else
    o.time_operators = flag_value(value);
}

std::string known_keys(const OnlineMethod& m) {
  std::string list;
  for (const OptionSpec& s : m.options) list += (list.empty() ? "" : ", ") + s.key;
  return list.empty() ? "none" : list;
}

void check_key(const OnlineMethod& m, const std::string& key) {
  if (!find_spec(m, key))
    throw InputError("online method " + quoted(m.name, 200) + " has no option " + quoted(key) + "; it knows: " + known_keys(m));
}

}  // namespace

const std::vector<std::string>& shared_option_keys() {
  static const std::vector<std::string> keys{"tau",           "tau_scaling",           "max_iterations",
                                             "step_tolerance", "time_operators",        "penetration_tolerance",
                                             "complementarity_tolerance", "estimate"};
  return keys;
}

std::vector<OnlineMethod> rom_online_methods() {
  auto greedy = [](const ReducedModel& model, const OnlineSolverOptions& options) {
    return std::unique_ptr<OnlineSolver>(std::make_unique<GreedyActiveSet>(model, greedy_options(options)));
  };
  // The same solver with the nested operator-rebuild schedule (GreedySchedule::Nested).
  auto nested = [](const ReducedModel& model, const OnlineSolverOptions& options) {
    GreedyOptions g = greedy_options(options);
    g.schedule = GreedySchedule::Nested;
    return std::unique_ptr<OnlineSolver>(std::make_unique<GreedyActiveSet>(model, g));
  };
  return {{"greedy", "sparse greedy active set on the dual dictionary (paper Alg. 1)", greedy_specs(true), greedy},
          {"greedy-nested", "greedy active set, contact operators rebuilt on a nested schedule", greedy_specs(false),
           nested},
          {"convex-hull", "convex-hull approximation: nnFOCUSS on the monolithic dictionary (paper app. B)",
           convex_hull_specs(), make_convex_hull_solver, false, /*needs_primal_snapshots=*/true}};
}

void register_online_method(OnlineMethod method) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const std::string name = method.name;
  r.methods[name] = std::move(method);
}

void register_online_solver(const std::string& name, OnlineSolverFactory factory) {
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    // Replacing the factory of a declared method keeps its option declarations.
    if (auto it = r.methods.find(name); it != r.methods.end()) {
      it->second.factory = std::move(factory);
      return;
    }
  }
  OnlineMethod m;
  m.name = name;
  m.summary = "registered at run time";
  m.open_options = true;
  m.needs_primal_snapshots = true;  // unknown: keep everything the method could read
  m.factory = std::move(factory);
  register_online_method(std::move(m));
}

std::vector<OnlineMethod> online_methods() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<OnlineMethod> out;
  for (const auto& entry : r.methods) out.push_back(entry.second);
  return out;
}

std::vector<std::string> online_solver_names() {
  std::vector<std::string> names;
  for (const OnlineMethod& m : online_methods()) names.push_back(m.name);
  return names;
}

OnlineMethod online_method(const std::string& name) {
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    if (const auto it = r.methods.find(name); it != r.methods.end()) return it->second;
  }
  if (std::find(kBaselineMethods.begin(), kBaselineMethods.end(), name) != kBaselineMethods.end())
    throw InputError("online method " + quoted(name) +
                     " is in the library contactrom::baselines, which this program does not link; link it "
                     "(CMake: target_link_libraries(app PRIVATE contactrom::baselines))");
  throw InputError("unknown online method " + quoted(name) + "; expected one of: " + join(online_solver_names(), ", "));
}

bool online_method_needs_primal_snapshots(const std::string& name) {
  return online_method(name).needs_primal_snapshots;
}

std::string describe_option_type(const OptionSpec& spec) {
  switch (spec.type) {
    case OptionType::Number: return spec.range.text();
    case OptionType::Integer: {
      const Interval& r = spec.range;
      auto whole = [](double v) { return std::to_string(static_cast<long long>(v)); };
      if (r.upper >= 1e9) return "an integer >= " + whole(r.lower);
      return "an integer in [" + whole(r.lower) + ", " + whole(r.upper) + "]";
    }
    case OptionType::Choice: {  // "a, b or c", as the methods' own messages say
      std::vector<std::string> head(spec.choices.begin(), spec.choices.end() - (spec.choices.empty() ? 0 : 1));
      return head.empty() ? join(spec.choices, "") : join(head, ", ") + " or " + spec.choices.back();
    }
    case OptionType::Flag: return "true or false (1 or 0)";
  }
  return "";
}

void validate_option_value(const std::string& method, const OptionSpec& spec, const std::string& value) {
  const std::string what = "online method " + quoted(method, 200) + " option " + spec.key;
  switch (spec.type) {
    case OptionType::Number:
      (void)parse_number(value, what, spec.range);
      return;
    case OptionType::Integer: {
      const Interval& r = spec.range;
      (void)parse_integer(value, what, static_cast<long long>(std::max(r.lower, -9e18)),
                          static_cast<long long>(std::min(r.upper, 9e18)));
      return;
    }
    case OptionType::Choice:
      if (std::find(spec.choices.begin(), spec.choices.end(), value) == spec.choices.end()) break;
      return;
    case OptionType::Flag:
      if (value != "true" && value != "false" && value != "1" && value != "0") break;
      return;
  }
  throw InputError(what + " = " + quoted(value) + " invalid; expected " + describe_option_type(spec));
}

void validate_online_options(const std::string& method, const OnlineSolverOptions& options) {
  const OnlineMethod m = online_method(method);
  if (m.open_options) return;  // the factory checks its own settings
  for (const auto& [key, value] : options.extra) {
    if (is_shared(key))
      throw InputError("online method " + quoted(method, 200) + " option " + key +
                       " is a field of OnlineSolverOptions; set the field (or use options_from_map)");
    check_key(m, key);
    validate_option_value(method, *find_spec(m, key), value);
  }
  for (const std::string& key : shared_option_keys())
    if (const OptionSpec* spec = find_spec(m, key)) validate_option_value(method, *spec, shared_value(options, key));
}

std::map<std::string, std::string> options_to_map(const std::string& method, const OnlineSolverOptions& options) {
  const OnlineMethod m = online_method(method);
  std::map<std::string, std::string> out(options.extra.begin(), options.extra.end());
  for (const std::string& key : shared_option_keys())
    if (m.open_options || find_spec(m, key)) out[key] = shared_value(options, key);
  return out;
}

OnlineSolverOptions options_from_map(const std::string& method, const std::map<std::string, std::string>& values) {
  const OnlineMethod m = online_method(method);
  OnlineSolverOptions o;
  for (const auto& [key, value] : values) {
    if (!m.open_options) {
      check_key(m, key);
      validate_option_value(method, *find_spec(m, key), value);
    }
    if (is_shared(key))
      set_shared(o, key, value);
    else
      o.extra[key] = value;
  }
  return o;
}

std::pair<std::string, std::string> split_option(const std::string& key_value) {
  const size_t eq = key_value.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--option " + quoted(key_value) + " invalid; expected KEY=VALUE (e.g. cpg_tolerance=1e-2)");
  return {key_value.substr(0, eq), key_value.substr(eq + 1)};
}

std::string describe_online_methods() {
  std::ostringstream out;
  out << "Online methods and their options (--option KEY=VALUE):\n";
  for (const OnlineMethod& m : online_methods()) {
    out << "  " << m.name << ": " << m.summary << "\n";
    if (m.open_options) out << "    (options checked by the method itself)\n";
    for (const OptionSpec& s : m.options)
      out << "    " << s.key << ": " << s.help << " [" << describe_option_type(s) << "; default " << s.default_value
          << "]\n";
  }
  return out.str();
}

void check_extra_options(const OnlineSolverOptions& options, const std::string& method,
                         const std::vector<std::string>& known) {
  for (const auto& entry : options.extra) {
    if (std::find(known.begin(), known.end(), entry.first) != known.end()) continue;
    throw InputError("online method " + quoted(method, 200) + " has no option " + quoted(entry.first, 200) + "; it knows: " +
                     (known.empty() ? "none" : join(known, ", ")));
  }
}

double parse_option_number(const std::string& method, const std::string& key, const std::string& text) {
  return parse_number(text, method + " option " + key);
}

long long parse_option_integer(const std::string& method, const std::string& key, const std::string& text) {
  return parse_integer(text, method + " option " + key, std::numeric_limits<long long>::min(),
                       std::numeric_limits<long long>::max());
}

void check_online_method(const std::string& name) { (void)online_method(name); }

std::unique_ptr<OnlineSolver> make_online_solver(const std::string& name, const ReducedModel& model,
                                                 const OnlineSolverOptions& options) {
  const OnlineMethod m = online_method(name);
  validate_online_options(name, options);
  std::unique_ptr<OnlineSolver> solver = m.factory(model, options);
  fom::ContactTolerances tolerances = fom::default_contact_tolerances(model.problem());
  if (options.penetration_tolerance >= 0) tolerances.penetration = options.penetration_tolerance;
  if (options.complementarity_tolerance >= 0) tolerances.complementarity = options.complementarity_tolerance;
  solver->set_contact_tolerances(tolerances);
  if (options.estimate) solver->set_error_indicator(model.error_indicator());
  return solver;
}

}  // namespace contactrom::rom
