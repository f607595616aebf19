#include <contactrom/rom/online_methods.hpp>

#include <algorithm>
#include <mutex>
#include <sstream>

#include <contactrom/core/format.hpp>
#include <contactrom/fom/input_values.hpp>
#include <contactrom/rom/convex_hull.hpp>
#include <contactrom/rom/greedy_active_set.hpp>

namespace contactrom::rom {
namespace {

/// Methods of contactrom::baselines, named in the message a program gets when it
/// asks for one of them without linking that library.
const std::vector<std::string> kBaselineMethods{"cpg", "full-dictionary"};

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

/// Whether `key` is a typed field of OnlineSolverOptions (not an `extra` entry).
bool is_field(const std::string& key) {
  return active_set_settings_table().find(key) || contact_check_table().find(key);
}

}  // namespace

const OptionSpec* OnlineMethod::option(const std::string& key) const {
  for (const OptionSpec& s : options)
    if (s.key == key) return &s;
  return nullptr;
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
  auto hull = make_online_method("convex-hull",
                                 "convex-hull approximation: nnFOCUSS on the monolithic dictionary (paper app. B)",
                                 make_convex_hull_solver, convex_hull_option_table());
  hull.needs_primal_snapshots = true;
  return {make_online_method("greedy", "sparse greedy active set on the dual dictionary (paper Alg. 1)", greedy,
                             greedy_option_table()),
          make_online_method("greedy-nested", "greedy active set, contact operators rebuilt on a nested schedule", nested,
                             greedy_option_table().without({"schedule", "surface_step", "on_cycle"})),
          hull};
}

void register_online_method(OnlineMethod method) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const std::string name = method.name;
  r.methods[name] = std::move(method);
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

void validate_online_options(const std::string& method, const OnlineSolverOptions& options) {
  const OnlineMethod m = online_method(method);
  for (const auto& entry : options.extra) {
    const std::string& key = entry.first;
    if (is_field(key))
      throw InputError("online method " + quoted(method, 200) + " option " + key +
                       " is a field of OnlineSolverOptions; set the field (or use options_from_map)");
    if (!m.option(key)) throw_unknown_option(method, key, m.options);
  }
  (void)m.read(options);
}

std::map<std::string, OptionValue> options_to_values(const std::string& method, const OnlineSolverOptions& options) {
  validate_online_options(method, options);
  return online_method(method).read(options);
}

std::map<std::string, std::string> options_to_map(const std::string& method, const OnlineSolverOptions& options) {
  std::map<std::string, std::string> out;
  for (const auto& [key, value] : options_to_values(method, options)) out[key] = option_text(value);
  return out;
}

OnlineSolverOptions options_from_map(const std::string& method, const std::map<std::string, std::string>& values) {
  const OnlineMethod m = online_method(method);
  OnlineSolverOptions o;
  for (const auto& [key, value] : values) {
    if (!m.option(key)) throw_unknown_option(method, key, m.options);
    const std::string what = "online method " + quoted(method, 200) + " option " + key;
    if (active_set_settings_table().find(key))
      active_set_settings_table().read(o, key, value, what);
    else if (contact_check_table().find(key))
      contact_check_table().read(o, key, value, what);
    else
      o.extra[key] = value;
  }
  validate_online_options(method, o);
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
    for (const OptionSpec& s : m.options)
      out << "    " << s.key << ": " << s.help << " [" << describe_option_type(s) << "; default " << s.default_value
          << "]\n";
  }
  return out.str();
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
  if (options.estimate) solver->set_error_indicator(model.error_indicator(), options.estimate_pairings);
  return solver;
}

}  // namespace contactrom::rom
