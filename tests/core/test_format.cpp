// core/format.hpp: format_number writes the shortest text that reads back as the same
// double (checked by reading it back, and on decimals that need few digits); join puts
// the separator between items only; quoted escapes control bytes and cuts long text.
#define BOOST_TEST_MODULE core_format
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include <contactrom/core/format.hpp>

using contactrom::format_number;
using contactrom::join;

BOOST_AUTO_TEST_CASE(format_number_reads_back_exactly) {
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> exponent(-300.0, 300.0);
  for (int i = 0; i < 2000; ++i) {
    const double v = (i % 2 ? -1.0 : 1.0) * std::pow(10.0, exponent(gen));
    const std::string text = format_number(v);
    BOOST_TEST(std::strtod(text.c_str(), nullptr) == v, text);
  }
  const double extremes[] = {0.0, std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::denorm_min(), 1.0 / 3.0};
  for (const double v : extremes) BOOST_TEST(std::strtod(format_number(v).c_str(), nullptr) == v);
}

BOOST_AUTO_TEST_CASE(format_number_uses_few_digits_for_short_decimals) {
  BOOST_TEST(format_number(0.1) == "0.1");
  BOOST_TEST(format_number(-2.5e-7) == "-2.5e-07");
  BOOST_TEST(format_number(30.0) == "30");
  BOOST_TEST(format_number(std::numeric_limits<double>::infinity()) == "inf");
}

BOOST_AUTO_TEST_CASE(join_separates_items_only) {
  BOOST_TEST(join({}) == "");
  BOOST_TEST(join({"a"}) == "a");
  BOOST_TEST(join({"a", "b", "c"}) == "a, b, c");
  BOOST_TEST(join({"d", "", "e"}, ",") == "d,,e");
}

BOOST_AUTO_TEST_CASE(quoted_cuts_and_escapes) {
  BOOST_TEST(contactrom::quoted("a\x01\x1b" "b") == "'a\\x01\\x1bb'");
  const std::string q = contactrom::quoted(std::string(5000000, 'x'));
  BOOST_TEST(q.size() < 120u);
  BOOST_TEST(q.find("(5000000 bytes)") != std::string::npos);
}
