// `query --fallback fom`: answers come from the ROM or the FOM as the tolerances
// decide, and the output says which and how long each took.
#define BOOST_TEST_MODULE cli_query_fallback
#include <algorithm>
#include <cmath>
#include <boost/test/unit_test.hpp>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/run_command.hpp"

using contactrom::test::run_command;

namespace {
const std::string kExe = CONTACTROM_EXE;

/// The fields of a CSV line; a quoted field may hold commas and doubled quotes.
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') out.back() += '"', ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back() += c;
  }
  return out;
}
}  // namespace

BOOST_AUTO_TEST_CASE(fallback_answers_are_labelled_and_timed) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h12.h5", rom = dir + "/h12_greedy.h5", list = dir + "/q.csv", out = dir + "/a.csv";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 12 --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  {
    std::ofstream f(list);
    f << "0.1\n0.2\n";
  }
  // Tolerances no answer meets: every answer is the FOM's.
  const auto all = run_command(kExe + " query --rom " + rom + " --params " + list +
                               " --fallback fom --primal-tolerance 1e-12 --dual-tolerance 1e-12 --json --out " + out +
                               " --fields " + dir + "/fields");
  BOOST_REQUIRE_MESSAGE(all.exit_code == 0, all.err);
  const auto j = nlohmann::json::parse(all.out);
  BOOST_TEST(j["fallbacks"].get<int>() == 2);
  for (const auto& q : j["queries"]) {
    BOOST_TEST(q["source"].get<std::string>() == "fom");
    // A FOM answer carries the FOM's force, not that of the reduced answer it replaced.
    const auto fom = run_command(kExe + " fom --problem hertz --json --param " + q["param"].dump());
    BOOST_REQUIRE_MESSAGE(fom.exit_code == 0, fom.err);
    const double force = nlohmann::json::parse(fom.out)["contact_force"].get<double>();
    BOOST_TEST(std::abs(q["contact_force"].get<double>() - force) <= 1e-12 * force);
    BOOST_TEST(q["fom_time_s"].get<double>() > 0.0);
    BOOST_TEST(!q["fallback_reason"].get<std::string>().empty());
  }
  // The fields of a FOM answer are named so, and record their parameter.
  for (const char* name : {"/fields/hertz_fom_0.vtu", "/fields/hertz_fom_1.vtu"})
    BOOST_TEST(std::ifstream(dir + name).good(), name);
  BOOST_TEST(!std::ifstream(dir + "/fields/hertz_greedy_0.vtu").good());
  {
    std::ifstream vtu(dir + "/fields/hertz_fom_1.vtu");
    const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
    BOOST_TEST(text.find("<FieldData>\n      <DataArray type=\"Float64\" Name=\"d\" NumberOfTuples=\"1\" "
                         "format=\"ascii\">0.2</DataArray>") != std::string::npos);
  }
  // The CSV carries what the JSON says of each answer: where it came from, why, and
  // the reduced answer's status and estimates.
  std::ifstream csv(out);
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = csv_fields(line);
  const auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  BOOST_TEST_REQUIRE(column("fom_time_s") == header.size() - 1);
  for (const auto& q : j["queries"]) {
    BOOST_REQUIRE(std::getline(csv, line));
    const std::vector<std::string> row = csv_fields(line);
    BOOST_REQUIRE(row.size() == header.size());
    BOOST_TEST(row[column("source")] == "fom");
    BOOST_TEST(row[column("fallback_reason")] == q["fallback_reason"].get<std::string>());
    BOOST_TEST(row[column("rom_status")] == q["rom_status"].get<std::string>());
    BOOST_TEST(std::stod(row[column("rom_dual_estimate")]) == q["rom_dual_estimate"].get<double>(),
               boost::test_tools::tolerance(1e-12));
  }
  // Generous tolerances: the ROM answers (hertz 12 is accurate to a few per cent).
  const auto none = run_command(kExe + " query --rom " + rom + " --params " + list +
                                " --fallback fom --primal-tolerance 1 --dual-tolerance 1 --json");
  BOOST_REQUIRE(none.exit_code == 0);
  const auto k = nlohmann::json::parse(none.out);
  BOOST_TEST(k["fallbacks"].get<int>() == 0);
  for (const auto& q : k["queries"]) BOOST_TEST(q["source"].get<std::string>() == "rom");
  // A bad choice is an input error.
  BOOST_TEST(run_command(kExe + " query --rom " + rom + " --param 0.1 --fallback ipopt").exit_code != 0);
  // Tolerances without --fallback fom would be ignored: refused instead.
  const auto ignored = run_command(kExe + " query --rom " + rom + " --param 0.1 --primal-tolerance 0.01");
  BOOST_TEST(ignored.exit_code == 2);
  BOOST_TEST(ignored.err.find("apply to --fallback fom only") != std::string::npos, ignored.err);
  // --out and --fields on one path: refused by name, and nothing is created there.
  const std::string same = dir + "/same";
  const auto clash = run_command(kExe + " query --rom " + rom + " --param 0.1 --out " + same + " --fields " + same);
  BOOST_TEST(clash.exit_code == 2);
  BOOST_TEST(clash.err.find("--out and --fields name the same path") != std::string::npos, clash.err);
  BOOST_TEST(!std::ifstream(same).good());
}
