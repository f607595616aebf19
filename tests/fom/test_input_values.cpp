// The shared validation layer of typed values (fom/input_values.hpp): NaN and
// infinities refused, subnormals accepted, integers strict, lists without empty
// items, and every message quoting the value exactly as typed.
#define BOOST_TEST_MODULE fom_input_values
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "common/input_error.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/fom/input_values.hpp>
#include <contactrom/fom/problem.hpp>

using contactrom::Interval;
using contactrom::test::input_error_of;

BOOST_AUTO_TEST_CASE(numbers_are_finite_and_whole) {
  BOOST_TEST(contactrom::parse_number(" 0.25 ", "--x") == 0.25);
  BOOST_TEST(contactrom::parse_number("5e-324", "--x") > 0.0);  // subnormal: a number
  for (const char* bad : {"nan", "NaN", "inf", "-infinity", "1e999", "1e-400", "", " ", "0.1x", "0x", "--1"}) {
    const std::string m = input_error_of([&] { contactrom::parse_number(bad, "--x"); });
    BOOST_TEST_CONTEXT(bad) {
      BOOST_TEST(!m.empty());
      BOOST_TEST(m.find("--x '" + std::string(bad) + "'") == 0u, m);
    }
  }
}

BOOST_AUTO_TEST_CASE(ranges_quote_the_text_as_typed) {
  const std::string m =
      input_error_of([] { contactrom::parse_number("0.30000000001", "--d", Interval{0.0, 0.3, true, false}); });
  BOOST_TEST(m == "--d '0.30000000001' is outside the range; expected a number in (0, 0.3]");
  BOOST_TEST(input_error_of([] { contactrom::parse_number("nan", "--tau", Interval::at_least(0)); }) ==
             "--tau 'nan' is not a finite number; expected a number >= 0");
  BOOST_TEST(contactrom::parse_number("0.3", "--d", Interval{0.0, 0.3, true, false}) == 0.3);
  BOOST_TEST(!input_error_of([] { contactrom::parse_number("0", "--d", Interval::greater_than(0)); }).empty());
}

BOOST_AUTO_TEST_CASE(integers_are_written_as_integers) {
  BOOST_TEST(contactrom::parse_integer("12", "--n", 1, 100) == 12);
  BOOST_TEST(contactrom::parse_integer("+3", "--n", 1, 100) == 3);
  BOOST_TEST(input_error_of([] { contactrom::parse_integer("2.5", "--train", 1, 100000); }) ==
             "--train '2.5' is not an integer; expected an integer in [1, 100000]");
  BOOST_TEST(input_error_of([] { contactrom::parse_integer("1e3", "--n", 1, 10000); }).find("not an integer") !=
             std::string::npos);
  BOOST_TEST(input_error_of([] { contactrom::parse_integer("99999999999999999999", "--n", 1, 10); })
                 .find("outside the range") != std::string::npos);
  BOOST_TEST(input_error_of([] { contactrom::parse_integer("0", "--n", 1, 10); }).find("'0'") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(lists_have_no_empty_items) {
  BOOST_TEST(contactrom::split_list("1,2", "--p").size() == 2u);
  BOOST_TEST(input_error_of([] { contactrom::split_list("0.1,", "--p"); }).find("after its last comma") != std::string::npos);
  BOOST_TEST(input_error_of([] { contactrom::split_list(",0.1", "--p"); }).find("before its first comma") != std::string::npos);
  BOOST_TEST(input_error_of([] { contactrom::split_list("1,,2", "--p"); }).find("between two commas") != std::string::npos);
  BOOST_TEST(input_error_of([] { contactrom::split_list(" ", "--p"); }).find("is empty") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(problem_parameters_are_checked_per_component) {
  const auto rope = contactrom::fom::make_problem("rope");
  BOOST_TEST(contactrom::parse_problem_param(*rope, "12.5")(0) == 12.5);
  BOOST_TEST(input_error_of([&] { contactrom::parse_problem_param(*rope, "50.0000001"); }).find("'50.0000001'") !=
             std::string::npos);
  BOOST_TEST(input_error_of([&] { contactrom::parse_problem_param(*rope, "12,13"); }).find("takes 1 parameter") !=
             std::string::npos);
  BOOST_TEST(input_error_of([&] { contactrom::parse_problem_param(*rope, "nan"); }).find("'nan'") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(both_parameter_entry_points_are_one_parser) {
  // fom::parse_param (the library's) and parse_problem_param (the CLI's and
  // Python's) accept the same texts with the same values and refuse the same texts
  // with the same message, with the stricter rules: blanks only around a value,
  // no empty item, no underflow to 0, the value out of range quoted as written.
  namespace fom = contactrom::fom;
  const std::string source = CONTACTROM_SOURCE_DIR;
  for (const std::string problem_name : {"punch_beam", "ironing2"}) {
    const auto problem = fom::make_problem(source + "/problems/" + problem_name + ".toml");
    const bool two = problem->num_params() == 2;
    const std::vector<std::string> accepted =
        two ? std::vector<std::string>{"0,0.1", " 4 , 0.3 ", "1e-300,0.2", "+2,2e-1"}
            : std::vector<std::string>{"0.2", " 0.1 ", "1e-300", "+2e-1", "5e-324"};
    const std::vector<std::string> refused = {"", " ", "0.1,", ",0.1", "0.1,,0.2", "abc", "nan", "inf", "0.1x",
                                              "1e-400", "1e400", "0.1\v", "-0.1", "0.30000000001", "0x",
                                              "0.1,0.2,0.3"};
    for (const std::string& text : accepted) {
      BOOST_TEST_CONTEXT(problem_name << " '" << text << "'") {
        const fom::Param a = fom::parse_param(*problem, text);
        const fom::Param b = contactrom::parse_problem_param(*problem, text);
        BOOST_TEST(a.size() == problem->num_params());
        BOOST_TEST((a.array() == b.array()).all());
        BOOST_TEST(problem->parameters().contains(a));
      }
    }
    for (const std::string& text : refused) {
      BOOST_TEST_CONTEXT(problem_name << " '" << text << "'") {
        const std::string a = input_error_of([&] { fom::parse_param(*problem, text); });
        const std::string b = input_error_of([&] { contactrom::parse_problem_param(*problem, text); });
        BOOST_TEST(!a.empty());
        BOOST_TEST(a == b);
      }
    }
  }
  // The messages of the stricter rules.
  const auto punch = fom::make_problem(source + "/problems/punch_beam.toml");
  BOOST_TEST(input_error_of([&] { fom::parse_param(*punch, "1e-400"); }).find("underflows to 0") != std::string::npos);
  BOOST_TEST(input_error_of([&] { fom::parse_param(*punch, "0.1,"); }).find("after its last comma") != std::string::npos);
  BOOST_TEST(input_error_of([&] { fom::parse_param(*punch, "0.20000000001"); }).find("'0.20000000001'") !=
             std::string::npos);
  BOOST_TEST(input_error_of([&] { fom::parse_param(*punch, "0.1,0.2"); }).find("takes 1 parameter value(s), but") !=
             std::string::npos);
}
