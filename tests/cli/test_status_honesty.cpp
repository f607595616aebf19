// A status never says success when the residuals it reports are large: the
// convex-hull ROM below the training range, Ipopt at a vanishing load.
#define BOOST_TEST_MODULE cli_status_honesty
#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "common/run_command.hpp"

using contactrom::test::run_command;

namespace {
const std::string kExe = CONTACTROM_EXE;
}

BOOST_AUTO_TEST_CASE(convex_hull_outside_the_training_range_is_not_a_success) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h30.h5";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 30 --out " + db).exit_code == 0);
  const auto below = run_command(kExe + " online --db " + db + " --method convex-hull --param 1e-9 --json");
  BOOST_REQUIRE(below.exit_code == 0);
  const auto j = nlohmann::json::parse(below.out);
  BOOST_TEST(j["kkt"]["stationarity"].get<double>() > 1.0);  // the reported residual is large ...
  BOOST_TEST(j["status"].get<std::string>() != "success");    // ... so the status is not success
  BOOST_TEST(!j["converged"].get<bool>());
  BOOST_TEST(j["message"].get<std::string>().find("projected residual") != std::string::npos);
  // Inside the range the same method still succeeds.
  const auto inside = nlohmann::json::parse(
      run_command(kExe + " online --db " + db + " --method convex-hull --param 0.15 --json").out);
  BOOST_TEST(inside["status"].get<std::string>() == "success");
  std::filesystem::remove_all(dir);
}

BOOST_AUTO_TEST_CASE(ipopt_at_a_vanishing_load_is_not_a_success) {
  const auto r = run_command(kExe + " fom --problem hertz --param 1e-300 --solver ipopt --json");
  BOOST_REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["kkt"]["stationarity"].get<double>() > 1.0);
  BOOST_TEST(j["status"].get<std::string>() != "success");
  const auto normal = nlohmann::json::parse(run_command(kExe + " fom --problem hertz --param 0.1 --solver ipopt --json").out);
  BOOST_TEST(normal["status"].get<std::string>() == "success");
}
