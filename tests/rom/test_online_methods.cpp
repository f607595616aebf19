// The registry of online methods (rom/online_methods.hpp): complete after linking
// (no registration call in this file), each method's declared options agree with
// what its factory accepts, option text round-trips, and refusals name the method,
// the key, the value and what was expected.
#define BOOST_TEST_MODULE online_methods
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include <contactrom/baselines/online_methods.hpp>
#include "common/run_command.hpp"
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/greedy_active_set.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/reduced_model_file.hpp>

using namespace contactrom;

namespace {

/// rope from 9 snapshots: small enough to build every method in well under a second.
struct Rope {
  std::unique_ptr<fom::Problem> problem = fom::make_problem("rope");
  rom::SnapshotDatabase db = rom::generate_snapshots(*problem, 9);
  rom::ReducedModel model{*problem, db, [] {
                            rom::ReducedModelOptions o;
                            o.delta = 1e-7;
                            return o;
                          }()};
};

const Rope& rope() {
  static const Rope r;
  return r;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

BOOST_AUTO_TEST_CASE(every_builtin_method_is_registered_without_a_call) {
  const std::vector<std::string> names = rom::online_solver_names();
  for (const rom::OnlineMethod& m : baselines::builtin_online_methods())
    BOOST_TEST((std::find(names.begin(), names.end(), m.name) != names.end()), m.name);
  for (const char* name : {"greedy", "greedy-nested", "convex-hull", "cpg", "full-dictionary"}) {
    const auto solver = rom::make_online_solver(name, rope().model);
    BOOST_TEST(solver->name() == name);
    const rom::OnlineResult r = solver->solve(fom::Param::Constant(1, 31.0));
    BOOST_TEST(r.u.size() == rope().problem->num_dofs());
  }
}

BOOST_AUTO_TEST_CASE(every_method_checks_mu_and_wraps_its_answer_the_same_way) {
  // OnlineSolver::solve: μ of the wrong size or outside the range is refused with
  // the problem's message before the method runs; every answer carries μ, the full
  // displacement Φû + u_off(μ) (the convex hull: u_off + D_p α), its times and,
  // when not converged, a status that says so.
  const fom::Problem& problem = *rope().problem;
  const fom::Param outside = fom::Param::Constant(1, 1e9), wrong_size = fom::Param::Zero(2);
  std::string expected_outside, expected_size;
  try {
    problem.check_param(outside);
  } catch (const InputError& e) {
    expected_outside = e.what();
  }
  try {
    problem.check_param(wrong_size);
  } catch (const InputError& e) {
    expected_size = e.what();
  }
  BOOST_REQUIRE(!expected_outside.empty());
  BOOST_REQUIRE(!expected_size.empty());
  for (const char* name : {"greedy", "greedy-nested", "convex-hull", "cpg", "full-dictionary"}) {
    BOOST_TEST_CONTEXT(name) {
      const auto solver = rom::make_online_solver(name, rope().model);
      BOOST_TEST(error_of([&] { solver->solve(outside); }) == expected_outside);
      BOOST_TEST(error_of([&] { solver->solve(wrong_size); }) == expected_size);
      const fom::Param mu = fom::Param::Constant(1, 31.0);
      const rom::OnlineResult r = solver->solve(mu);
      BOOST_TEST(r.mu(0) == 31.0);
      BOOST_TEST(r.time_s > 0.0);
      BOOST_TEST(r.time_s >= r.check_time_s);
      BOOST_TEST(r.reconstruction_time_s >= 0.0);
      BOOST_TEST(r.lambda.size() == problem.contact().num_constraints());
      if (std::string(name) != "convex-hull")
        BOOST_TEST((r.u - rope().model.reconstruct_primal(r.u_hat, mu)).norm() == 0.0);
      BOOST_TEST(((r.status == Status::NoConvergence) == (!r.converged && r.status != Status::NumericalIssue)));
      // A capped query that does not converge says so, with the method's reason.
      rom::OnlineSolverOptions capped;
      capped.max_iterations = 1;
      if (std::string(name) == "convex-hull") capped.extra["max_pairing_iterations"] = "1";
      const rom::OnlineResult c = rom::make_online_solver(name, rope().model, capped)->solve(mu);
      if (!c.converged) {
        BOOST_TEST((c.status == Status::NoConvergence));
        BOOST_TEST(!c.message.empty());
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(every_declared_choice_and_bound_is_accepted_by_the_factory) {
  for (const rom::OnlineMethod& m : rom::online_methods()) {
    for (const rom::OptionSpec& s : m.options) {
      std::vector<std::string> values = s.choices;
      if (s.type == rom::OptionType::Flag) values = {"true", "false"};
      if (s.type == rom::OptionType::Integer) values = {std::to_string(static_cast<long long>(s.range.lower))};
      if (s.type == rom::OptionType::Number && std::isfinite(s.range.lower)) values = {"0.5"};
      for (const std::string& v : values) {
        const rom::OnlineSolverOptions o = rom::options_from_map(m.name, {{s.key, v}});
        const std::string error = error_of([&] { rom::make_online_solver(m.name, rope().model, o); });
        BOOST_TEST(error.empty(), m.name << " " << s.key << "=" << v << ": " << error);
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(option_text_round_trips) {
  const std::map<std::string, std::string> cpg{{"cpg_tolerance", "0.05"}, {"init", "cell"}, {"tau", "1e-7"},
                                               {"max_iterations", "30"}, {"time_operators", "true"}};
  const rom::OnlineSolverOptions o = rom::options_from_map("cpg", cpg);
  BOOST_TEST(o.tau == 1e-7);
  BOOST_TEST(o.max_iterations == 30);
  BOOST_TEST(o.time_operators);
  BOOST_TEST(o.extra.at("cpg_tolerance") == "0.05");
  const auto text = rom::options_to_map("cpg", o);
  BOOST_TEST(text.size() == rom::online_method("cpg").options.size());  // every option, defaults filled in
  for (const auto& [k, v] : cpg) BOOST_TEST(rom::options_from_map("cpg", {{k, text.at(k)}}).extra.size() <= 1u);
  const rom::OnlineSolverOptions back = rom::options_from_map("cpg", text);
  BOOST_TEST(back.tau == o.tau);
  BOOST_TEST(back.max_iterations == o.max_iterations);
  BOOST_TEST(back.step_tolerance == o.step_tolerance);
  BOOST_TEST((back.tau_scaling == o.tau_scaling));
  BOOST_TEST(back.time_operators == o.time_operators);
  BOOST_TEST(back.estimate == o.estimate);
  BOOST_TEST((rom::options_to_map("cpg", back) == text));
  // Typed values: numbers as numbers, flags as bools, choices as words.
  const auto values = rom::options_to_values("cpg", o);
  BOOST_TEST(std::get<double>(values.at("cpg_tolerance")) == 0.05);
  BOOST_TEST(std::get<long long>(values.at("max_iterations")) == 30);
  BOOST_TEST(std::get<bool>(values.at("time_operators")));
  BOOST_TEST(std::get<std::string>(values.at("init")) == "cell");
  // A method stores only the options it reads: the convex hull, its own and the
  // contact check's, not the active-set settings.
  const auto hull = rom::options_to_map("convex-hull", rom::OnlineSolverOptions{});
  BOOST_TEST(hull.size() == rom::online_method("convex-hull").options.size());
  BOOST_TEST(hull.count("estimate") == 1u);
  BOOST_TEST(hull.count("penetration_tolerance") == 1u);
  BOOST_TEST(hull.count("tau") == 0u);
  // The alias schedule=paper stores what it sets, which reads back the same.
  const rom::OnlineSolverOptions paper = rom::options_from_map("greedy", {{"schedule", "paper"}});
  const auto stored = rom::options_to_map("greedy", paper);
  BOOST_TEST(stored.at("schedule") == "interleaved");
  BOOST_TEST(stored.at("anderson_depth") == "0");
  BOOST_TEST(stored.at("on_cycle") == "continue");
  const rom::GreedyOptions a = rom::greedy_options(paper), b = rom::greedy_options(rom::options_from_map("greedy", stored));
  BOOST_TEST((a.schedule == b.schedule && a.anderson_depth == b.anderson_depth && a.nested_on_cycle == b.nested_on_cycle));
}

BOOST_AUTO_TEST_CASE(every_documented_default_is_accepted_and_reported_alike) {
  // The default of every option of every method, as --help prints it: accepted when
  // typed, what options_to_values() gives for default settings, and what a
  // reduced-model file stores and gives back.
  const auto help = contactrom::test::run_command(std::string(CONTACTROM_EXE) + " online --help");
  BOOST_REQUIRE_EQUAL(help.exit_code, 0);
  const std::string dir = contactrom::test::temp_dir();
  std::shared_ptr<const fom::Problem> problem(fom::make_problem("rope"));
  for (const rom::OnlineMethod& m : rom::online_methods()) {
    const auto block_start = help.out.find("\n  " + m.name + ": ");
    BOOST_REQUIRE_MESSAGE(block_start != std::string::npos, m.name);
    auto block_end = help.out.find('\n', block_start + 1);  // the method's lines: those indented by 4
    while (block_end != std::string::npos && help.out.compare(block_end, 5, "\n    ") == 0)
      block_end = help.out.find('\n', block_end + 1);
    const std::string block = help.out.substr(block_start, block_end - block_start);
    rom::ReducedModelOptions model_options;
    model_options.delta = 1e-7;
    const rom::OnlineModel built(problem, rope().db, model_options, m.name);
    const std::string path = dir + "/" + m.name + ".h5";
    built.save(path);
    const auto stored = rom::options_to_map(m.name, rom::OnlineModel::load(path).options());
    const auto typed = rom::options_to_values(m.name, rom::OnlineSolverOptions{});
    for (const rom::OptionSpec& s : m.options) {
      const std::string where = m.name + " " + s.key + " = " + s.default_value;
      const std::string error = error_of([&] {
        rom::make_online_solver(m.name, rope().model, rom::options_from_map(m.name, {{s.key, s.default_value}}));
      });
      BOOST_TEST(error.empty(), where << ": " << error);
      BOOST_TEST(contains(block, "    " + s.key + ": "), where);
      const auto line = block.find("    " + s.key + ": ");
      BOOST_TEST(block.substr(line, block.find('\n', line + 1) - line).find("; default " + s.default_value + "]") !=
                     std::string::npos,
                 where << " not the default --help prints");
      BOOST_TEST(stored.at(s.key) == s.default_value, where << " stored as " << stored.at(s.key));
      BOOST_TEST(rom::option_text(typed.at(s.key)) == s.default_value, where);
    }
  }
}

BOOST_AUTO_TEST_CASE(refusals_name_method_key_value_and_expectation) {
  std::string m = error_of([] { rom::options_from_map("cpg", {{"cpg_tolerance", "2"}}); });
  BOOST_TEST(contains(m, "cpg"));
  BOOST_TEST(contains(m, "cpg_tolerance"));
  BOOST_TEST(contains(m, "'2'"));
  BOOST_TEST(contains(m, "a number <= 1"));
  m = error_of([] { rom::options_from_map("greedy", {{"schedule", "sideways"}}); });
  BOOST_TEST(contains(m, "'sideways'"));
  BOOST_TEST(contains(m, "expected fixed-point, interleaved, paper or nested"));
  m = error_of([] { rom::options_from_map("convex-hull", {{"polish", "maybe"}}); });
  BOOST_TEST(contains(m, "true or false"));
  m = error_of([] { rom::options_from_map("full-dictionary", {{"cpg_tolerance", "0.1"}}); });
  BOOST_TEST(contains(m, "has no option 'cpg_tolerance'"));
  m = error_of([] { rom::options_from_map("greedy", {{"max_iterations", "2.5"}}); });
  BOOST_TEST(contains(m, "'2.5'"));
  // make_online_solver checks the same way.
  rom::OnlineSolverOptions o;
  o.max_iterations = 0;
  m = error_of([&] { rom::make_online_solver("greedy", rope().model, o); });
  BOOST_TEST(contains(m, "max_iterations"));
  m = error_of([] { rom::online_method("sideways"); });
  BOOST_TEST(contains(m, "expected one of"));
  BOOST_TEST(contains(m, "cpg"));
}

BOOST_AUTO_TEST_CASE(split_option_needs_a_key_and_an_equals_sign) {
  BOOST_TEST((rom::split_option("a=b=c") == std::pair<std::string, std::string>{"a", "b=c"}));
  BOOST_CHECK_THROW(rom::split_option("=1"), InputError);
  BOOST_CHECK_THROW(rom::split_option("key"), InputError);
}

// The commands that take --option list every setting of every method; bench, which
// times every method with its defaults, names each method and takes no --option.
BOOST_AUTO_TEST_CASE(cli_help_lists_every_option_of_every_method) {
  for (const char* command : {"online", "reduce", "verify"}) {
    const auto r = contactrom::test::run_command(std::string(CONTACTROM_EXE) + " " + command + " --help");
    BOOST_REQUIRE_EQUAL(r.exit_code, 0);
    BOOST_TEST(contains(r.out, "--option"), command);
    for (const rom::OnlineMethod& m : rom::online_methods()) {
      BOOST_TEST(contains(r.out, "  " + m.name + ": "), command << " " << m.name);
      for (const rom::OptionSpec& s : m.options) BOOST_TEST(contains(r.out, "    " + s.key + ": "), m.name << " " << s.key);
    }
  }
  const auto bench = contactrom::test::run_command(std::string(CONTACTROM_EXE) + " bench --help");
  BOOST_REQUIRE_EQUAL(bench.exit_code, 0);
  BOOST_TEST(!contains(bench.out, "--option"));
  for (const rom::OnlineMethod& m : rom::online_methods()) BOOST_TEST(contains(bench.out, m.name), "bench " << m.name);
}
