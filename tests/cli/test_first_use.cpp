// What a new user meets first: every command is documented in the README, every
// help text lists its choices instead of pointing into the sources, the bench
// table keeps each name apart from its value, a training size a problem cannot
// honour is refused rather than silently replaced, and one version is reported
// everywhere.
#define BOOST_TEST_MODULE cli_first_use
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/run_command.hpp"
#include <contactrom/core/version.hpp>
#include <contactrom/rom/snapshot_database.hpp>

using contactrom::test::run_command;
using contactrom::test::slurp;

namespace {

const std::string kExe = CONTACTROM_EXE;

/// The subcommands listed by `contactrom --help` (lines "  name   description").
std::vector<std::string> subcommands() {
  const auto r = run_command(kExe + " --help");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  std::vector<std::string> names;
  std::istringstream in(r.out);
  bool listing = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Subcommands:", 0) == 0) {
      listing = true;
      continue;
    }
    std::smatch m;
    if (listing && std::regex_match(line, m, std::regex("  ([a-z][a-z-]*) .*"))) names.push_back(m[1]);
  }
  return names;
}

}  // namespace

BOOST_AUTO_TEST_CASE(every_subcommand_is_listed) {
  const auto names = subcommands();
  // The ones a user of the method needs at least; the README test below covers all.
  for (const char* expected : {"fom", "offline", "online", "reduce", "query", "bench", "hull-report", "sparse"})
    BOOST_TEST((std::find(names.begin(), names.end(), expected) != names.end()), expected);
}

BOOST_AUTO_TEST_CASE(readme_documents_every_subcommand) {
  const std::string readme = slurp(std::string(CONTACTROM_SOURCE_DIR) + "/README.md");
  BOOST_REQUIRE(!readme.empty());
  for (const auto& name : subcommands())
    BOOST_TEST(std::regex_search(readme, std::regex("contactrom +" + name + "( |\n)")),
               "README.md does not show the subcommand " << name);
}

BOOST_AUTO_TEST_CASE(help_texts_list_choices_instead_of_pointing_elsewhere) {
  // A help text that says "see the error text" or names a source file leaves the
  // user without the list of valid values.
  const std::regex pointer("see the error|see (rom|fom|baselines|tools)/|\\.(hpp|cpp)\\b");
  for (const auto& name : subcommands()) {
    const auto r = run_command(kExe + " " + name + " --help");
    BOOST_TEST(r.exit_code == 0, name);
    BOOST_TEST(!std::regex_search(r.out, pointer), name << " --help points elsewhere:\n" << r.out);
  }
}

BOOST_AUTO_TEST_CASE(bench_table_keeps_names_and_values_apart) {
  const auto r = run_command(kExe + " bench --problem rope --repeats 1 --ipopt-queries 1");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  std::istringstream in(r.out);
  int rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("  ", 0) != 0) continue;  // headers ("ratios:") start in column 0
    std::istringstream fields(line);
    std::string name, value, extra;
    fields >> name >> value;
    BOOST_TEST(!(fields >> extra), "more than a name and a value: '" << line << "'");
    char* end = nullptr;
    std::strtod(value.c_str(), &end);
    BOOST_TEST((!value.empty() && *end == '\0'), "no number after the name: '" << line << "'");
    ++rows;
  }
  // Times of the FOM and of several ROMs plus their ratios.
  BOOST_TEST(rows >= 10);
}

BOOST_AUTO_TEST_CASE(a_training_size_the_problem_cannot_honour_is_refused) {
  // rope trains on its listed points: --train 30 must not make 9 snapshots and
  // record 30.
  const std::string out = "/tmp/contactrom_first_use_rope30.h5";
  std::remove(out.c_str());
  const auto r = run_command(kExe + " offline --problem rope --train 30 --out " + out);
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.out.empty());
  BOOST_TEST(r.err.find("--train") != std::string::npos, r.err);
  BOOST_TEST(!std::ifstream(out).good(), "a database was written");
}

BOOST_AUTO_TEST_CASE(one_version_everywhere) {
  // The build's project version, as the library, `--version` and the files the CLI
  // writes report it (Python's contactrom.__version__: tests/python/test_quiet.py).
  const std::string expected = CONTACTROM_PROJECT_VERSION;
  BOOST_TEST(contactrom::version() == expected);
  const auto r = run_command(kExe + " --version");
  BOOST_TEST(r.exit_code == 0);
  BOOST_TEST(r.out == "contactrom " + expected + "\n");
  const std::string db = "/tmp/contactrom_first_use_version.h5";
  const auto offline = run_command(kExe + " offline --problem hertz --train 3 --threads 1 --out " + db);
  BOOST_REQUIRE_MESSAGE(offline.exit_code == 0, offline.err);
  BOOST_TEST(contactrom::rom::read_database(db).created_by == "contactrom " + expected);
  std::remove(db.c_str());
}

BOOST_AUTO_TEST_CASE(the_executable_searches_no_relative_library_folder) {
  // An empty or relative entry in RUNPATH/RPATH makes the loader look for libraries
  // in the current folder: `build/tools/contactrom` run in a folder holding a
  // libmpi.so.40 would load it.
  const auto r = run_command("readelf -d " + kExe);
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, r.err);
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, std::regex(R"(\((RUNPATH|RPATH)\).*\[(.*)\])"))) continue;
    const std::string path = m[2];
    std::string entry;
    std::istringstream entries(path + ":");
    while (std::getline(entries, entry, ':'))
      BOOST_TEST((entry.rfind('/', 0) == 0 || entry.rfind("$ORIGIN", 0) == 0), "entry '" << entry << "' of " << path);
  }
}
