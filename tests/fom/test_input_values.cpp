// The shared validation layer of typed values (fom/input_values.hpp): NaN and
// infinities refused, subnormals accepted, integers strict, lists without empty
// items, and every message quoting the value exactly as typed.
#define BOOST_TEST_MODULE fom_input_values
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <string>

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
