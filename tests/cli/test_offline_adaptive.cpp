// `offline --adaptive`: one progress line per round on stderr, a database that
// `--append` continues to the database of a single run, `online --validation
// --params` on it, and bad settings refused with exit code 2 and one line.
#define BOOST_TEST_MODULE cli_offline_adaptive
#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "common/run_command.hpp"
#include <contactrom/rom/snapshot_database.hpp>

using contactrom::test::run_command;
namespace rom = contactrom::rom;

namespace {
const std::string kExe = CONTACTROM_EXE;
const std::string kSmall = " offline --problem hertz --adaptive --tolerance 0.001 --candidates 40 --batch 2 --threads 1";

int count_lines(const std::string& text, const std::string& word) {
  int n = 0;
  for (size_t p = text.find(word); p != std::string::npos; p = text.find(word, p + 1)) ++n;
  return n;
}
}  // namespace

BOOST_AUTO_TEST_CASE(append_continues_a_stopped_run_to_the_database_of_one_run) {
  const std::string dir = contactrom::test::temp_dir();
  const auto whole = run_command(kExe + kSmall + " --max-snapshots 8 --out " + dir + "/whole.h5 --json");
  BOOST_REQUIRE_MESSAGE(whole.exit_code == 0, whole.err);
  const auto j = nlohmann::json::parse(whole.out);
  BOOST_TEST(j["total_snapshots"].get<int>() == 8);
  BOOST_TEST(j["rounds"].get<int>() == 4);
  BOOST_TEST(count_lines(whole.err, "adaptive round") == 4);  // progress on stderr, one line per round

  const auto first = run_command(kExe + kSmall + " --max-snapshots 4 --out " + dir + "/part.h5");
  BOOST_REQUIRE_MESSAGE(first.exit_code == 0, first.err);
  // The settings are the database's; only N changes. Without --problem, the
  // database's own problem is continued.
  const auto rest = run_command(kExe + " offline --adaptive --max-snapshots 8 --threads 2 --append " + dir + "/part.h5");
  BOOST_REQUIRE_MESSAGE(rest.exit_code == 0, rest.err);
  const rom::SnapshotDatabase a = rom::read_database(dir + "/whole.h5"), b = rom::read_database(dir + "/part.h5");
  // Appending grid snapshots to it is refused, naming the option that continues it.
  const auto grid = run_command(kExe + " offline --problem hertz --train 4 --append " + dir + "/part.h5");
  BOOST_TEST(grid.exit_code == 2);
  BOOST_TEST(grid.err.find("--adaptive") != std::string::npos, grid.err);
  BOOST_REQUIRE_EQUAL(a.num_snapshots(), b.num_snapshots());
  BOOST_TEST((a.parameters == b.parameters));
  BOOST_TEST((a.primal == b.primal));
  BOOST_TEST((a.dual == b.dual));
  BOOST_TEST(a.adaptive.round_snapshots == b.adaptive.round_snapshots, boost::test_tools::per_element());
  BOOST_TEST(a.adaptive.round_max_indicator == b.adaptive.round_max_indicator, boost::test_tools::per_element());

  // Evaluated on a parameter list; it has no validation set of its own.
  {
    std::ofstream f(dir + "/points.csv");
    f << "d\n0.05\n0.12\n0.27\n";
  }
  const auto online = run_command(kExe + " online --db " + dir + "/whole.h5 --validation --params " + dir +
                                  "/points.csv --json");
  BOOST_REQUIRE_MESSAGE(online.exit_code == 0, online.err);
  BOOST_TEST(nlohmann::json::parse(online.out)["validation_size"].get<int>() == 3);
  const auto no_set = run_command(kExe + " online --db " + dir + "/whole.h5 --validation");
  BOOST_TEST(no_set.exit_code == 2);
  BOOST_TEST(no_set.err.find("--params") != std::string::npos, no_set.err);

  // Continuing a run that already holds --max-snapshots says that no round adds any.
  std::filesystem::copy_file(dir + "/whole.h5", dir + "/full.h5");
  const auto full = run_command(kExe + " offline --problem hertz --adaptive --max-snapshots 8 --append " + dir + "/full.h5");
  BOOST_REQUIRE_MESSAGE(full.exit_code == 0, full.err);
  BOOST_TEST(full.err.find("holds 8 snapshots already, at least --max-snapshots 8: no round adds any") != std::string::npos,
             full.err);
}

BOOST_AUTO_TEST_CASE(bad_settings_exit_2_with_one_line) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string base = kExe + " offline --problem hertz --out " + dir + "/x.h5";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 4 --out " + dir + "/grid.h5").exit_code == 0);
  for (const std::string& args :
       {std::string(" --adaptive --tolerance 0"), std::string(" --adaptive --tolerance -1"),
        std::string(" --adaptive --tolerance nan"), std::string(" --adaptive --tolerance 0.1 --batch 0"),
        std::string(" --adaptive --tolerance 0.1 --candidates 0"), std::string(" --adaptive --tolerance 0.1 --max-snapshots 0"),
        std::string(" --adaptive --tolerance 0.1 --candidates 100001"),
        std::string(" --adaptive --tolerance 0.1 --indicator both"), std::string(" --adaptive --tolerance 0.1 --method nope"),
        std::string(" --adaptive --tolerance 0.1 --delta 2"), std::string(" --tolerance 0.1"), std::string(" --adaptive"),
        std::string(" --adaptive --tolerance 0.1 --part 1/2"),
        std::string(" --adaptive --tolerance 0.1 --train 4 --max-snapshots 3")}) {
    const auto r = run_command(base + args);
    BOOST_TEST(r.exit_code == 2, args << ": exit " << r.exit_code);
    BOOST_TEST(count_lines(r.err, "\n") == 1, args << ": " << r.err);
    BOOST_TEST(r.out.empty(), args);
  }
  std::ifstream none(dir + "/x.h5");
  BOOST_TEST(!none.good());  // nothing written
  const auto grid = run_command(kExe + " offline --problem hertz --adaptive --tolerance 0.1 --append " + dir + "/grid.h5");
  BOOST_TEST(grid.exit_code == 2);
  BOOST_TEST(grid.err.find("offline --adaptive") != std::string::npos, grid.err);
}

BOOST_AUTO_TEST_CASE(an_interrupted_run_says_what_its_database_holds) {
  // Ctrl-C (SIGINT) mid-run: the database holds the rounds written, and the last line
  // on stderr says how many snapshots and how to continue.
  const std::string dir = contactrom::test::temp_dir(), db = dir + "/int.h5";
  const auto r = run_command("timeout -s INT 3 " + kExe +
                             " offline --problem hertz --adaptive --tolerance 1e-12 --max-snapshots 100000 --candidates 400"
                             " --threads 1 --out " + db);
  BOOST_TEST(r.exit_code != 0);
  BOOST_REQUIRE_MESSAGE(std::filesystem::exists(db), "no round finished in 3 s: " << r.err);
  const int held = rom::read_database(db).num_snapshots();
  BOOST_TEST(r.err.find("contactrom: interrupted; '" + db + "' holds the " + std::to_string(held) +
                        " snapshots of the rounds done; continue it with contactrom offline --adaptive --append " + db) != std::string::npos,
             r.err);
}
