#pragma once
/// \file online_methods.hpp
/// \brief The registry of online ROM methods: each method's name, summary, the
/// options it reads (declared once, with type, default and help text) and its
/// factory; validation of option values and conversion between
/// OnlineSolverOptions and key/value text.
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
/// (rom/online_solver.hpp), then register it with register_online_method()
/// (declaring its options) or register_online_solver().
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fom/input_values.hpp"
#include "rom/online_solver.hpp"
#include "rom/reduced_model.hpp"

namespace contactrom::rom {

/// \brief Builds an online solver on a reduced model (which must outlive it).
using OnlineSolverFactory =
    std::function<std::unique_ptr<OnlineSolver>(const ReducedModel& model, const OnlineSolverOptions& options)>;

/// \brief Registers (or replaces) the factory of method `name`.
void register_online_solver(const std::string& name, OnlineSolverFactory factory);

/// \brief Registers a method at static-initialisation time. Beware: in a static
/// library the linker drops an object file that nothing references, together with
/// its registrar; a registrar in a program's own source file is safe.
struct OnlineSolverRegistrar {
  OnlineSolverRegistrar(const std::string& name, OnlineSolverFactory factory) {
    register_online_solver(name, std::move(factory));
  }
};

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

/// \brief Kind of value an option takes.
enum class OptionType {
  Number,   ///< a finite real number, possibly bounded
  Integer,  ///< an integer, possibly bounded
  Choice,   ///< one word out of OptionSpec::choices
  Flag      ///< true/false (also 1/0)
};

/// \brief One option of an online method, declared once.
struct OptionSpec {
  std::string key;            ///< name, as in `--option key=value`
  OptionType type = OptionType::Number;  ///< kind of value
  std::string default_value;  ///< default, as text (may be a word such as "delta" when computed)
  std::string help;           ///< one-line meaning (with unit where there is one)
  std::vector<std::string> choices;  ///< accepted words (OptionType::Choice)
  Interval range;             ///< accepted values (Number); Integer uses its bounds too
};

/// \brief An online method: what the registry knows about it.
struct OnlineMethod {
  std::string name;                  ///< registry name ("greedy", "cpg", ...)
  std::string summary;               ///< one-line description
  std::vector<OptionSpec> options;   ///< every option the method reads
  OnlineSolverFactory factory;       ///< builds the solver
  /// Options not declared (a method added with register_online_solver()): every
  /// key of OnlineSolverOptions::extra is passed to the factory, which checks it.
  bool open_options = false;
  /// Whether the method combines the primal training snapshots themselves
  /// (ReducedModel::primal_snapshots(), n × m): a reduced-model file then stores
  /// them. Methods added with register_online_solver() are assumed to.
  bool needs_primal_snapshots = false;
};

/// \brief Registers (or replaces) a method with its option declarations.
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

/// \brief Declarations of OnlineSolverOptions' named fields (`tau`, `tau_scaling`,
/// `max_iterations`, `step_tolerance`, `time_operators`), read by every active-set
/// method (the greedy and the baselines).
std::vector<OptionSpec> active_set_option_specs();

/// \brief The keys of OnlineSolverOptions' named fields (`tau`, `tau_scaling`,
/// `max_iterations`, `step_tolerance`, `time_operators`); every other key of a
/// method lives in OnlineSolverOptions::extra.
const std::vector<std::string>& shared_option_keys();

/// \brief Checks `value` against `spec`.
/// \throws InputError "online method 'm' option key = 'value' invalid; expected ...".
void validate_option_value(const std::string& method, const OptionSpec& spec, const std::string& value);

/// \brief Checks every setting of `options` that `method` reads: unknown keys in
/// OnlineSolverOptions::extra, values of the wrong type or outside their range.
/// make_online_solver() calls it before building the solver.
/// \throws InputError naming the method, the key, the value and what was expected.
void validate_online_options(const std::string& method, const OnlineSolverOptions& options);

/// \brief The settings of `options` that `method` reads, as key/value text: the
/// named fields the method declares and every entry of
/// OnlineSolverOptions::extra. options_from_map(method, result) gives back
/// equivalent options.
std::map<std::string, std::string> options_to_map(const std::string& method, const OnlineSolverOptions& options);

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

/// \brief What a value of `spec` must be, e.g. "a number in [0, 1]", "an integer >= 1",
/// "empty, primal or cell", "true or false (1 or 0)".
std::string describe_option_type(const OptionSpec& spec);

}  // namespace contactrom::rom
