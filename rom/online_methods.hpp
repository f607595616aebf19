#pragma once
/// \file online_methods.hpp
/// \brief The registry of online ROM methods: each method's name, summary, the
/// options it reads and its factory; validation of option values and conversion
/// between OnlineSolverOptions and key/value text or typed values.
///
/// A method's options are declared once, in the binding table of its options
/// struct (rom/option_table.hpp: greedy_option_table(), convex_hull_option_table(),
/// the baselines' reduced_active_set_option_table() and cpg_option_table()), plus
/// contact_check_table() that every method reads; the declarations below, `--help`,
/// the parser and the reduced-model file's option maps are generated from them.
///
/// The built-in methods are registered without any call from the user:
/// - `greedy`, `greedy-nested` (rom/greedy_active_set.hpp) and `convex-hull`
///   (rom/convex_hull.hpp) live in contactrom::rom and are always available;
/// - `cpg` and `full-dictionary` live in contactrom::baselines and are registered
///   as soon as a program links that library (its CMake target makes the linker
///   keep the registering object file, static or shared). A program linking
///   contactrom::rom alone gets an InputError naming the library to link when it
///   asks for one of them.
///
/// \code
///   contactrom::rom::OnlineSolverOptions o = contactrom::rom::options_from_map("cpg", {{"cpg_tolerance", "0.05"}});
///   auto solver = contactrom::rom::make_online_solver("cpg", model, o);
/// \endcode
/// The CLI's `--option KEY=VALUE` goes through the same validation
/// (validate_online_options) and `contactrom online --help` prints
/// describe_online_methods(). Adding a method: implement OnlineSolver
/// (rom/online_solver.hpp), declare its options struct's OptionTable, then
/// register_online_method(make_online_method(name, summary, factory, table)).
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <contactrom/fom/input_values.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace contactrom::rom {

/// \brief Builds an online solver on a reduced model (which must outlive it).
using OnlineSolverFactory =
    std::function<std::unique_ptr<OnlineSolver>(const ReducedModel& model, const OnlineSolverOptions& options)>;

/// \brief Registered method names, sorted.
std::vector<std::string> online_solver_names();

/// \brief Refuses a method name that is not registered (before costly work).
/// \throws InputError "unknown online method 'x'; expected one of: ...".
void check_online_method(const std::string& name);

/// \brief Builds the solver registered as `name`, after checking `options` against
/// the method's declared options (validate_online_options below).
/// \throws InputError "unknown online method 'x'; expected one of: ..." for an unknown
/// name, or naming the method, option, value and what was expected.
std::unique_ptr<OnlineSolver> make_online_solver(const std::string& name, const ReducedModel& model,
                                                 const OnlineSolverOptions& options = {});
/// A solver keeps a reference to its model: a temporary model would be gone before
/// the first solve.
std::unique_ptr<OnlineSolver> make_online_solver(const std::string& name, const ReducedModel&& model,
                                                 const OnlineSolverOptions& options = {}) = delete;

/// \brief An online method: what the registry knows about it.
struct OnlineMethod {
  std::string name;                  ///< registry name ("greedy", "cpg", ...)
  std::string summary;               ///< one-line description
  std::vector<OptionSpec> options;   ///< every option the method reads (from its tables)
  /// The value of every option of `options` once the settings are read into the
  /// method's options structs (read_options(): values checked, defaults filled in).
  std::function<std::map<std::string, OptionValue>(const OnlineSolverOptions&)> read;
  OnlineSolverFactory factory;       ///< builds the solver
  /// Whether the method combines the primal training snapshots themselves
  /// (ReducedModel::primal_snapshots(), n × m): a reduced-model file then stores them.
  bool needs_primal_snapshots = false;
  /// The declared option `key`, or nullptr when the method has no such option.
  const OptionSpec* option(const std::string& key) const;
};

/// \brief A method whose options are those of `tables` (one per options struct it
/// reads) and of contact_check_table(). Every key must be declared once.
template <class... S>
OnlineMethod make_online_method(std::string name, std::string summary, OnlineSolverFactory factory,
                                const OptionTable<S>&... tables) {
  OnlineMethod m;
  m.name = std::move(name);
  m.summary = std::move(summary);
  m.factory = std::move(factory);
  auto append = [&m](const auto& table) {
    for (const OptionSpec& spec : table.specs()) m.options.push_back(spec);
  };
  (append(tables), ...);
  append(contact_check_table());
  m.read = [method = m.name, tables...](const OnlineSolverOptions& o) {
    std::map<std::string, OptionValue> values;
    auto add = [&](const auto& table) {
      for (auto& [key, value] : table.to_values(read_options(table, o, method, /*strict=*/false)))
        values[key] = std::move(value);
    };
    (add(tables), ...);
    add(contact_check_table());
    return values;
  };
  return m;
}

/// \brief Registers (or replaces) a method (make_online_method()).
void register_online_method(OnlineMethod method);

/// \brief Every registered method, sorted by name.
std::vector<OnlineMethod> online_methods();

/// \brief The method registered as `name`.
/// \throws InputError naming the known methods (or the library that provides a
/// built-in method this program does not link).
OnlineMethod online_method(const std::string& name);

/// \brief Whether method `name` needs the primal training snapshots
/// (OnlineMethod::needs_primal_snapshots). \throws InputError as online_method().
bool online_method_needs_primal_snapshots(const std::string& name);

/// \brief The methods built into contactrom::rom (`greedy`, `greedy-nested`,
/// `convex-hull`); the registry starts with them.
std::vector<OnlineMethod> rom_online_methods();

/// \brief Checks every setting of `options` that `method` reads: unknown keys in
/// OnlineSolverOptions::extra, values of the wrong type or outside their range.
/// make_online_solver() calls it before building the solver.
/// \throws InputError naming the method, the key, the value and what was expected.
void validate_online_options(const std::string& method, const OnlineSolverOptions& options);

/// \brief Every option of `method` with its value in `options` (defaults filled
/// in), as key/value text: what a reduced-model file stores.
/// options_from_map(method, result) gives back equivalent options.
/// \throws InputError as validate_online_options().
std::map<std::string, std::string> options_to_map(const std::string& method, const OnlineSolverOptions& options);

/// \brief Every option of `method` with its typed value in `options` (numbers as
/// numbers, flags as bools, choices as words).
/// \throws InputError as validate_online_options().
std::map<std::string, OptionValue> options_to_values(const std::string& method, const OnlineSolverOptions& options);

/// \brief Options of `method` from key/value text (e.g. `--option` pairs or a
/// reduced-model file); keys absent keep their defaults.
/// \throws InputError as validate_online_options().
OnlineSolverOptions options_from_map(const std::string& method, const std::map<std::string, std::string>& values);

/// \brief Splits "KEY=VALUE" (the CLI's `--option`).
/// \throws InputError if there is no '=' or the key is empty.
std::pair<std::string, std::string> split_option(const std::string& key_value);

/// \brief Human-readable list of the registered methods and their options (for
/// `--help`): one paragraph per method, one line per option with its type,
/// default and help.
std::string describe_online_methods();

}  // namespace contactrom::rom
