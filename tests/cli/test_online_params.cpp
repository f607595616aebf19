// `online --validation --params FILE.csv`: a database evaluated against the FOM on a
// user-given parameter list gives, row by row, the errors of single queries at the
// same parameters; bad lists are refused with the file and line named. The offset
// option `--offset` and its other name `--lifting` build the same reduced model.
#define BOOST_TEST_MODULE cli_online_params
#include <boost/test/unit_test.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/run_command.hpp"

using contactrom::test::run_command;

namespace {
const std::string kExe = CONTACTROM_EXE;

std::vector<std::vector<std::string>> csv_rows(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) cells.push_back(x);
    rows.push_back(cells);
  }
  return rows;
}
}  // namespace

BOOST_AUTO_TEST_CASE(parameter_list_rows_equal_single_queries) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h12.h5", list = dir + "/points.csv", out = dir + "/rows.csv";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 12 --out " + db).exit_code == 0);
  const std::vector<std::string> points{"0.0625", "0.17", "0.2913"};
  {
    std::ofstream f(list);
    f << "d\n# three points off the training grid\n";
    for (const std::string& p : points) f << p << "\n";
  }
  const auto r = run_command(kExe + " online --db " + db + " --method greedy --validation --params " + list +
                             " --out " + out + " --json --progress");
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, r.err);
  const auto j = nlohmann::json::parse(r.out);
  BOOST_TEST(j["validation_size"].get<int>() == 3);
  // --progress: both stages drawn to the end on stderr, stdout only the JSON.
  BOOST_TEST(r.err.find("online: FOM references") != std::string::npos, r.err);
  BOOST_TEST(r.err.find("online: reduced queries [##############################] 3/3") != std::string::npos, r.err);
  const auto rows = csv_rows(out);
  BOOST_REQUIRE(rows.size() == 4u);
  for (size_t i = 0; i < points.size(); ++i) {
    BOOST_TEST(std::stod(rows[i + 1][0]) == std::stod(points[i]));
    const auto single = run_command(kExe + " online --db " + db + " --method greedy --param " + points[i] + " --json");
    BOOST_REQUIRE(single.exit_code == 0);
    const auto s = nlohmann::json::parse(single.out);
    BOOST_TEST(std::stod(rows[i + 1][1]) == s["primal_error"].get<double>(), boost::test_tools::tolerance(1e-9));
    BOOST_TEST(std::stod(rows[i + 1][2]) == s["dual_error"].get<double>(), boost::test_tools::tolerance(1e-9));
  }
  // The same list with other line ends (CRLF, a lone CR) and a UTF-8 byte-order mark.
  for (const std::string& end : {std::string("\r\n"), std::string("\r")}) {
    const std::string other = dir + "/points_other.csv", other_out = dir + "/rows_other.csv";
    {
      std::ofstream f(other, std::ios::binary);
      f << "\xEF\xBB\xBF" << "d" << end;
      for (const std::string& p : points) f << p << end;
    }
    const auto o = run_command(kExe + " online --db " + db + " --method greedy --validation --params " + other +
                               " --out " + other_out);
    BOOST_REQUIRE_MESSAGE(o.exit_code == 0, o.err);
    const auto other_rows = csv_rows(other_out);
    BOOST_REQUIRE(other_rows.size() == rows.size());
    for (size_t i = 1; i < rows.size(); ++i) BOOST_TEST(other_rows[i][0] == rows[i][0]);
  }
}

BOOST_AUTO_TEST_CASE(offset_and_its_other_name_lifting_build_the_same_model) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h8.h5";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 8 --out " + db).exit_code == 0);
  const auto query = [&](const std::string& flag) {
    const auto r = run_command(kExe + " online --db " + db + " --param 0.17 --json " + flag);
    BOOST_REQUIRE_MESSAGE(r.exit_code == 0, flag + ": " + r.err);
    return nlohmann::json::parse(r.out);
  };
  const auto offset = query("--offset dirichlet"), lifting = query("--lifting dirichlet"), harmonic = query("");
  BOOST_TEST(offset["primal_rank"].get<int>() == lifting["primal_rank"].get<int>());
  BOOST_TEST(offset["primal_error"].get<double>() == lifting["primal_error"].get<double>());
  BOOST_TEST(offset["dual_error"].get<double>() == lifting["dual_error"].get<double>());
  // ... and a model other than the default (harmonic) offset's.
  BOOST_TEST(offset["primal_error"].get<double>() != harmonic["primal_error"].get<double>());
  const auto bad = run_command(kExe + " online --db " + db + " --param 0.17 --offset zero");
  BOOST_TEST(bad.exit_code == 2);
  BOOST_TEST(bad.err.find("zero") != std::string::npos, bad.err);
}

BOOST_AUTO_TEST_CASE(bad_parameter_lists_are_refused) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h12.h5", list = dir + "/bad.csv";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 12 --out " + db).exit_code == 0);
  {
    std::ofstream f(list);
    f << "0.1\n0.7\n";  // 0.7 is outside d in (0, 0.3]
  }
  const auto r = run_command(kExe + " online --db " + db + " --validation --params " + list);
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.err.find("bad.csv") != std::string::npos);
  BOOST_TEST(r.err.find("0.7") != std::string::npos);
  const auto both = run_command(kExe + " online --db " + db + " --param 0.1 --params " + list);
  BOOST_TEST(both.exit_code == 2);
}
