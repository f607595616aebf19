// Bad input, table-driven, for every command: each case must end with exit code 2,
// exactly one line on stderr that starts with "contactrom: error: " and names the
// bad value, nothing on stdout, and no output file (nor temporary file) left.
// The corrupted databases are the seed corpus of the database fuzzer
// (fuzz/corpus/database/), so every crash found there stays a regression case.
#define BOOST_TEST_MODULE cli_bad_input
#include <sys/stat.h>

#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/run_command.hpp"

namespace fs = std::filesystem;
using contactrom::test::run_command;

namespace {

const std::string kExe = CONTACTROM_EXE;
const std::string kCorpus = std::string(CONTACTROM_SOURCE_DIR) + "/fuzz/corpus/database/";

struct Case {
  std::string args;      ///< arguments after the executable (shell syntax)
  std::string expected;  ///< substring of the one-line message (the bad value)
  std::string output;    ///< path that must not exist afterwards ("" = none)
  std::string prefix;    ///< shell prefix (environment, limits), "" = none
};

std::string quote(const std::string& s) { return "'" + s + "'"; }

int count_lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

/// Files in `dir` whose name contains ".tmp." (left-over temporary files).
int temporaries_in(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) ++n;
  return n;
}

/// The command fails with `exit_code` (2: bad input, 1: a failure outside the
/// input), one line on stderr naming the value, nothing on stdout, no output left.
void check_case(const Case& c, int exit_code = 2) {
  BOOST_TEST_CONTEXT(c.prefix + "contactrom " + c.args) {
    const auto r = run_command(c.prefix + kExe + " " + c.args);
    BOOST_TEST(r.exit_code == exit_code);
    BOOST_TEST(r.out.empty(), "stdout: " << r.out);
    BOOST_TEST(count_lines(r.err) == 1, "stderr: " << r.err);
    BOOST_TEST(r.err.rfind("contactrom: error: ", 0) == 0u, "stderr: " << r.err);
    BOOST_TEST(r.err.find(c.expected) != std::string::npos, "stderr: " << r.err << "expected: " << c.expected);
    BOOST_TEST(r.err.size() < 600u, "stderr is " << r.err.size() << " bytes");
    if (!c.output.empty()) BOOST_TEST(!fs::exists(fs::symlink_status(c.output)), c.output << " was left behind");
  }
}

/// A copy of problems/hertz.toml in `dir` whose mesh is `dir`/hertz.geo; returns its path.
std::string hertz_problem_next_to(const std::string& dir) {
  std::string text = contactrom::test::slurp(std::string(CONTACTROM_SOURCE_DIR) + "/problems/hertz.toml");
  const std::string from = "../meshes/hertz.geo";
  text.replace(text.find(from), from.size(), "hertz.geo");
  std::ofstream(dir + "/hertz.toml") << text;
  return dir + "/hertz.toml";
}

struct Fixture {
  std::string dir = contactrom::test::temp_dir();
  std::string rope_db = kCorpus + "rope.h5";
  std::string file(const std::string& name) const { return dir + "/" + name; }
  ~Fixture() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

}  // namespace

BOOST_FIXTURE_TEST_CASE(options_and_parameters, Fixture) {
  const std::string out = file("out.h5");
  const std::vector<Case> cases = {
      {"frobnicate", "unknown command 'frobnicate'", "", ""},
      {"fom --problem nosuch --param 1", "'nosuch'", "", ""},
      {"fom --problem hertz --param nan", "'nan'", "", ""},
      {"fom --problem hertz --param ' '", "' '", "", ""},
      {"fom --problem hertz --param 0.1,", "'0.1,'", "", ""},
      {"fom --problem hertz --param ,0.1", "',0.1'", "", ""},
      {"fom --problem hertz --param 0.30000000001", "'0.30000000001'", "", ""},
      {"fom --problem hertz --param 1e-400", "'1e-400'", "", ""},
      {"fom --problem hertz --param 0x", "'0x'", "", ""},
      {"fom --problem hertz --param 0x1p-3", "'0x1p-3' is not a number", "", ""},
      {"fom --problem ironing2 --param 1", "takes 2 parameter", "", ""},
      {"fom --problem hertz --param 0.1 --threads 1", "option '--threads' unknown to 'fom'; see contactrom fom --help", "", ""},
      {"fom --problem ironing2 --param 1 0.1", "unexpected argument '0.1'; expected options with one value each", "", ""},
      {"fom --problem hertz --param 0.1 --solver IPOPT", "--solver 'IPOPT' unknown; expected active-set or ipopt", "", ""},
      {"fom --problem hertz --param 0.1 --refine 7", "--refine '7' is outside the range; expected an integer in [0, 6]", "", ""},
      {"fom --problem hertz --param 0.5 --out " + file("fields"), "'0.5'", file("fields"), ""},
      {"offline --problem hertz --train 2.5 --out " + out, "'2.5'", out, ""},
      {"offline --problem hertz --train 0 --out " + out, "'0'", out, ""},
      {"offline --train 4 --out " + out, "offline needs --problem P", out, ""},
      {"offline --problem ironing --level 0 --out " + out, "--level '0' is outside the range; expected an integer in [1, 20]", out, ""},
      {"offline --problem ironing --level 0 --adaptive --tolerance 0.1 --out " + out, "--level '0'", out, ""},
      {"offline --problem hertz --train 4 --threads nan --out " + out, "'nan'", out, ""},
      {"online --db " + rope_db + " --tau nan", "--tau 'nan'", "", ""},
      {"online --db " + rope_db + " --tau inf", "--tau 'inf'", "", ""},
      {"online --db " + rope_db + " --delta -1", "--delta '-1'", "", ""},
      {"online --db " + rope_db + " --max-iterations 2.5", "'2.5'", "", ""},
      // With --param, --out names a folder: a .csv name is refused, not made a folder.
      {"online --db " + rope_db + " --param 20 --out " + file("res.csv"), "res.csv", file("res.csv"), ""},
      {"online --db " + rope_db + " --method cpg --option cpg_tolerance=nan", "'nan'", "", ""},
      {"online --db " + rope_db + " --param 60", "'60'", "", ""},
      {"online --db " + rope_db + " --method nosuch", "'nosuch'", "", ""},
      {"chls --db " + file("missing.h5"), "missing.h5", "", ""},
      {"hull-report --db " + rope_db + " --basis-delta 2", "--basis-delta '2'", "", ""},
      {"hull-report --db " + rope_db + " --basis-delta nan", "--basis-delta 'nan'", "", ""},
      {"hull-report --db " + rope_db + " --seed -3", "--seed '-3'", "", ""},
      {"verify --db " + rope_db + " --method greedy --cpg-tolerance nan", "'nan'", "", ""},
      {"verify --db " + rope_db + " --method greedy --option cpg_tolerance=0.1", "'cpg_tolerance'", "", ""},
      {"verify --db " + rope_db + " --method greedy,cpg --option estimate=maybe", "'maybe'", "", ""},
      {"verify --db " + rope_db + " --method greedy --option estimate", "'estimate'", "", ""},
      {"bench --problem hertz --delta nan", "--delta 'nan'", "", ""},
      {"bench --problem hertz --threads -1", "--threads '-1'", "", ""},
      {"bench --problem hertz --threads 1025", "--threads '1025'", "", ""},
      {"bench --problem hertz --ipopt-queries -1", "--ipopt-queries '-1'", "", ""},
      {"bench-sparse --noise nan", "--noise 'nan'", "", ""},
      {"demo --train 2.5", "--train '2.5'", "", ""},
      {"sparse --method omp --dictionary a.csv --signal b.csv --tol nan", "--tol 'nan'", "", ""},
  };
  for (const Case& c : cases) check_case(c);
}

BOOST_FIXTURE_TEST_CASE(messages_name_the_right_key_and_file, Fixture) {
  const std::string hertz = hertz_problem_next_to(dir);
  fs::copy_file(std::string(CONTACTROM_SOURCE_DIR) + "/meshes/hertz.geo", file("hertz.geo"));
  const std::string text = contactrom::test::slurp(hertz);
  const auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string t = text;
    const size_t at = t.find(from);
    BOOST_REQUIRE_MESSAGE(at != std::string::npos, from);
    t.replace(at, from.size(), to);
    std::ofstream(file(name)) << t;
    return file(name);
  };
  // An unknown master names the master key and its line.
  const std::string master = variant("master.toml", "master = \"", "master = \"nothing_");
  check_case({"fom --problem " + master + " --param 0.1", "key 'contact[0].master': the mesh has no physical curve", "", ""});
  // A wrong type of lower_open is named once, at its own key.
  const std::string open = variant("open.toml", "lower_open = true", "lower_open = \"true\"");
  check_case({"fom --problem " + open + " --param 0.1", "key 'parameters[0].lower_open': expected true or false", "", ""});
  // A missing mesh names the problem file's key.
  const std::string mesh = variant("mesh.toml", "mesh = \"hertz.geo\"", "mesh = \"nothere.geo\"");
  check_case({"fom --problem " + mesh + " --param 0.1", "key 'problem.mesh': mesh file", "", ""});
  // A size or level of 0 would read as "not given".
  const std::string of = variant("of.toml", "of = 120", "of = 0");
  check_case({"fom --problem " + of + " --param 0.1", "key 'validation.of': is 0; expected 1..", "", ""});
  // A reduced-model file given as a database, and a parameter header out of order.
  const std::string db = file("r.h5"), rom = file("r_rom.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  check_case({"online --db " + rom, "is a reduced-model file (contactrom reduce), not a snapshot database", "", ""});
  std::ofstream(file("p.csv")) << "g\n20\n";
  check_case({"query --rom " + rom + " --params " + file("p.csv"), "header 'g' does not name the parameters of 'rope' in order; expected 'gamma'", "", ""});
}

BOOST_FIXTURE_TEST_CASE(subnormal_parameter_is_a_number, Fixture) {
  const auto r = run_command(kExe + " fom --problem hertz --param 5e-324 --json");
  BOOST_TEST(r.exit_code == 0, r.err);
}

BOOST_FIXTURE_TEST_CASE(corrupted_databases, Fixture) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"string_attribute_array.h5", "attribute created_by has 3 elements, expected a single string"},
      {"variable_length_string.h5", "attribute problem is a variable-length string"},
      {"declared_2e32_elements.h5", "dataset /time_s has shape (4294967296)"},
      {"declared_2e62_columns.h5", "dataset /primal declares 9 x 4611686018427387904 elements"},
      {"negative_pressure.h5", "dataset /dual row 1, column 3 holds -1"},
      {"training_size_0.h5", "attribute training_size is 0"},
  };
  for (const auto& [name, expected] : files) {
    check_case({"online --db " + kCorpus + name + " --json", expected, "", ""});
    check_case({"chls --db " + kCorpus + name + " --out " + file("c.csv"), expected, file("c.csv"), ""});
  }
  // A database relabelled with another training size holds the wrong snapshots.
  const std::string relabelled = file("relabelled.h5");
  fs::copy_file(rope_db, relabelled);
  // rope's training set does not depend on n; hertz's does: build a hertz one.
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 2 --out " + file("h2.h5")).exit_code == 0);
  const int patched = std::system(("/usr/bin/python3 -c \"import h5py, numpy; f = h5py.File('" + file("h2.h5") +
                                   "', 'a'); f.attrs['training_size'] = numpy.int32(7)\" 2>/dev/null")
                                      .c_str());
  // h5py and numpy are installed by tools/setup.sh: without them the case fails.
  BOOST_REQUIRE_MESSAGE(patched == 0, "the relabelled-database case needs /usr/bin/python3 with h5py and numpy");
  check_case({"online --db " + file("h2.h5"), "claims training size 7 of hertz, but it holds 2 of its 7 snapshots", "", ""});
  // A part of a training set says how to complete it.
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 4 --part 1/2 --out " + file("part.h5")).exit_code == 0);
  check_case({"online --db " + file("part.h5"), "complete it with contactrom offline --append, or join the parts with contactrom merge", "", ""});
}

BOOST_FIXTURE_TEST_CASE(output_targets, Fixture) {
  fs::create_directories(file("folder"));
  std::ofstream(file("target.h5")) << "keep";
  fs::create_symlink(file("target.h5"), file("link.h5"));
  // A pipe of our own stands in for a device node: the test never risks a system
  // device (a broken check would replace it).
  BOOST_REQUIRE(::mkfifo(file("fifo").c_str(), 0600) == 0);
  const std::string offline = "offline --problem rope --out ";
  const std::vector<Case> cases = {
      {offline + "''", "--out: '' is empty; expected a path", "", ""},
      {"fom --problem rope --param 20 --out ''", "--out: '' is empty; expected a path", "", ""},
      {"online --db ''", "--db: '' is empty; expected a path", "", ""},
      {offline + file("folder"), "is a folder", "", ""},
      {offline + file("link.h5"), "is a symbolic link", "", ""},
      {offline + file("fifo"), "it is a device, pipe or socket", "", ""},
      {offline + file("nofolder/x.h5"), "nofolder", file("nofolder"), ""},
      {"online --db " + rope_db + " --out " + file("folder"), "is a folder", "", ""},
      {"fom --problem rope --param 20 --out " + file("target.h5"), "a file of that name exists", "", ""},
  };
  for (const Case& c : cases) check_case(c);
  // Nothing was replaced: the link is still a link to the untouched file, the pipe a pipe.
  BOOST_TEST(fs::is_symlink(file("link.h5")));
  std::ifstream in(file("target.h5"));
  std::string text;
  in >> text;
  BOOST_TEST(text == "keep");
  struct stat st {};
  BOOST_TEST((::lstat(file("fifo").c_str(), &st) == 0 && S_ISFIFO(st.st_mode)));
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(long_output_name_is_written, Fixture) {
  // 250 bytes: the temporary name must not exceed the 255-byte file-name limit.
  const std::string name = file(std::string(247, 'a') + ".h5");
  const auto r = run_command(kExe + " offline --problem rope --out " + quote(name));
  BOOST_TEST(r.exit_code == 0, r.err);
  BOOST_TEST(fs::exists(name));
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(full_disk_leaves_nothing_and_does_not_crash, Fixture) {
  // A 20 KB file-size limit stands in for a full disk (writes fail with EFBIG): a
  // failure outside the input, exit code 1.
  const std::string limit = "trap '' XFSZ; ulimit -f 40; ";
  const std::string db = file("full.h5");
  check_case({"offline --problem hertz --train 30 --out " + db, "File too large", db, limit}, 1);
  // fom --out: the folder it created and the VTU are removed when the set fails.
  const std::string fields = file("fields");
  check_case({"fom --problem hertz --param 0.1 --out " + fields, "File too large", fields, limit}, 1);
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(field_set_is_published_together, Fixture) {
  // The CSV target is a folder: refused before the VTU is published.
  fs::create_directories(file("fields/rope_surface.csv"));
  check_case({"fom --problem rope --param 20 --out " + file("fields"), "rope_surface.csv", file("fields/rope.vtu"), ""});
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(csv_messages_are_cut_and_escaped, Fixture) {
  std::ofstream(file("d.csv")) << "1,2\n3,\x01\x1b[31m" << std::string(5000000, 'x') << "\n";
  std::ofstream(file("x.csv")) << "1\n2\n";
  check_case({"sparse --method nnls --dictionary " + file("d.csv") + " --signal " + file("x.csv"),
              "line 2, column 2: '\\x01\\x1b[31mxxx", "", ""});
  // A dictionary whose Gram matrix cannot fit in memory is refused by size.
  {
    std::ofstream wide(file("wide.csv"));
    for (int j = 0; j < 200000; ++j) wide << (j ? ",1" : "1");
    wide << "\n";
  }
  std::ofstream(file("one.csv")) << "1\n";
  check_case({"sparse --method nnls --dictionary " + file("wide.csv") + " --signal " + file("one.csv"),
              "has 200000 columns", "", ""});
}

BOOST_FIXTURE_TEST_CASE(unheld_body_is_named_and_stdout_stays_clean, Fixture) {
  // hertz.toml without the Dirichlet condition of the top body's load face:
  // nothing holds the top body, the stiffness is singular.
  const std::string meshes = file("meshes");
  fs::create_directories(meshes);
  fs::copy_file(std::string(CONTACTROM_SOURCE_DIR) + "/meshes/hertz.geo", meshes + "/hertz.geo");
  const std::string problem = hertz_problem_next_to(meshes);
  std::string text = contactrom::test::slurp(problem);
  const std::string held = "[[dirichlet]]\ngroup = \"top_load\"\ndisplacement = [0.0, \"-d\"]\n";
  BOOST_REQUIRE(text.find(held) != std::string::npos);
  text.replace(text.find(held), held.size(), "");
  std::ofstream(problem) << text;
  check_case({"fom --problem " + problem + " --param 0.1 --json", "body 'top' is held by no Dirichlet condition", "", ""});
  check_case({"offline --problem " + problem + " --train 3 --out " + file("s.h5"), "body 'top'", file("s.h5"), ""});
}

BOOST_FIXTURE_TEST_CASE(geo_that_exits_is_an_error_not_a_silent_success, Fixture) {
  // A .geo file is a gmsh program; `Exit;` ends the process from inside gmsh.
  const std::string meshes = file("meshes");
  fs::create_directories(meshes);
  std::ifstream in(std::string(CONTACTROM_SOURCE_DIR) + "/meshes/hertz.geo");
  std::ofstream geo(meshes + "/hertz.geo");
  geo << "Exit;\n" << in.rdbuf();
  geo.close();
  check_case({"fom --problem " + hertz_problem_next_to(meshes) + " --param 0.1 --json",
              "/hertz.geo' ended the program while gmsh read it", "", ""});
}

BOOST_FIXTURE_TEST_CASE(gmsh_crash_or_oversized_mesh_writes_nothing, Fixture) {
  // Mesh.Algorithm = 8 segfaults inside gmsh 4.8.4: gmsh runs in a child process,
  // and meshing precedes every output file, so the command fails cleanly.
  const std::string meshes = file("meshes");
  fs::create_directories(meshes);
  {
    std::ifstream in(std::string(CONTACTROM_SOURCE_DIR) + "/meshes/hertz.geo");
    std::ofstream geo(meshes + "/hertz.geo");
    geo << in.rdbuf() << "\nMesh.Algorithm = 8;\n";
  }
  const std::string problem = hertz_problem_next_to(meshes);
  check_case({"fom --problem " + problem + " --param 0.1 --json --out " + file("fields"), "gmsh crashed (SIGSEGV)",
              file("fields"), ""});
  check_case({"offline --problem " + problem + " --train 3 --out " + file("s.h5"), "gmsh crashed", file("s.h5"), ""});
  BOOST_TEST(temporaries_in(dir) == 0);

  // The shipped mesh above a node limit of 100: the count and the limit are named.
  std::string text = contactrom::test::slurp(std::string(CONTACTROM_SOURCE_DIR) + "/problems/hertz.toml");
  const std::string from = "../meshes/hertz.geo\"";
  text.replace(text.find(from), from.size(), std::string(CONTACTROM_SOURCE_DIR) + "/meshes/hertz.geo\"\nmax_mesh_nodes = 100");
  std::ofstream(file("small.toml")) << text;
  check_case({"offline --problem " + file("small.toml") + " --train 3 --out " + file("t.h5"), "above the limit of 100",
              file("t.h5"), ""});
  // The limits themselves are checked.
  std::string bad = text;
  bad.replace(bad.find("max_mesh_nodes = 100"), 20, "mesh_time_limit = -1");
  std::ofstream(file("bad.toml")) << bad;
  check_case({"fom --problem " + file("bad.toml") + " --param 0.1", "mesh_time_limit", "", ""});
}
