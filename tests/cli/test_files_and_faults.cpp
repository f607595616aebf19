// No lost work and no leftover files: an output that is an input is refused (by
// device and inode), a folder where nothing can be created is refused before the
// work, two runs appending to one database both keep their snapshots, merge takes
// parts in any order, a set of outputs is published whole or not at all, inputs are
// regular files, and a signal during a write leaves the old file or the complete
// new one and no temporary file.
#define BOOST_TEST_MODULE cli_files_and_faults
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cstdlib>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common/run_command.hpp"

using contactrom::test::run_command;
using contactrom::test::slurp;
namespace fs = std::filesystem;

namespace {

const std::string kExe = CONTACTROM_EXE;

struct Fixture {
  std::string dir = contactrom::test::temp_dir();
  std::string file(const std::string& name) const { return dir + "/" + name; }
  ~Fixture() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

/// Files in `dir` whose name contains ".tmp." (left-over temporary files).
int temporaries_in(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) ++n;
  return n;
}

/// Exit code 2, one line naming `expected`, nothing on stdout.
void check_refused(const std::string& args, const std::string& expected) {
  BOOST_TEST_CONTEXT("contactrom " + args) {
    const auto r = run_command(kExe + " " + args);
    BOOST_TEST(r.exit_code == 2);
    BOOST_TEST(r.out.empty(), r.out);
    BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1, r.err);
    BOOST_TEST(r.err.find(expected) != std::string::npos, r.err);
  }
}

}  // namespace

BOOST_FIXTURE_TEST_CASE(an_output_that_is_an_input_is_refused, Fixture) {
  const std::string db = file("rope.h5"), rom = file("rope_rom.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  const std::string db_bytes = slurp(db), rom_bytes = slurp(rom);
  // Another name of the same file: a hard link, and a path through "..".
  fs::create_hard_link(db, file("hard.h5"));
  fs::create_directories(file("sub"));
  const std::string dotted = file("sub/../rope.h5");
  for (const std::string& out : {db, file("hard.h5"), dotted}) {
    check_refused("reduce --db " + db + " --method greedy --out " + out, "is the input file");
    check_refused("online --db " + db + " --method greedy --validation --out " + out, "is the input file");
    check_refused("chls --db " + db + " --out " + out, "is the input file");
    check_refused("merge " + db + " --out " + out, "is the input file");
  }
  check_refused("query --rom " + rom + " --param 20 --out " + rom, "is the input file");
  std::ofstream(file("p.csv")) << "20\n";
  check_refused("query --rom " + rom + " --params " + file("p.csv") + " --out " + file("p.csv"), "is the input file");
  BOOST_TEST(slurp(db) == db_bytes);
  BOOST_TEST(slurp(rom) == rom_bytes);
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(an_output_over_a_problem_file_its_mesh_or_a_parameter_list_is_refused, Fixture) {
  // A copy of hertz (problem file and mesh) in the test's folder.
  fs::copy_file(fs::path(CONTACTROM_SOURCE_DIR) / "meshes/hertz.geo", file("hertz.geo"));
  std::string toml = slurp(std::string(CONTACTROM_SOURCE_DIR) + "/problems/hertz.toml");
  const size_t at = toml.find("mesh = ");
  BOOST_REQUIRE(at != std::string::npos);
  toml.replace(at, toml.find('\n', at) - at, "mesh = \"hertz.geo\"");
  std::ofstream(file("hertz.toml")) << toml;
  const std::string geo_bytes = slurp(file("hertz.geo"));
  const std::string problem = " --problem " + file("hertz.toml");
  check_refused("offline" + problem + " --train 2 --out " + file("hertz.geo"), "is the input file");
  check_refused("offline" + problem + " --adaptive --tolerance 0.1 --out " + file("hertz.geo"), "is the input file");
  BOOST_TEST(slurp(file("hertz.geo")) == geo_bytes);
  // query --fields writes <problem>_<method>_surface.csv: a parameter list of that
  // name in the field folder is an input and stays.
  const std::string db = file("h.h5"), rom = file("h_rom.h5");
  BOOST_REQUIRE(run_command(kExe + " offline" + problem + " --train 4 --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  fs::create_directories(file("fields"));
  const std::string params = file("fields/hertz_greedy_surface.csv");
  std::ofstream(params) << "0.1\n";
  check_refused("query --rom " + rom + " --params " + params + " --fields " + file("fields"), "is the input file");
  BOOST_TEST(slurp(params) == "0.1\n");
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(an_output_folder_without_write_access_is_refused_before_the_work, Fixture) {
  // /proc admits no new file, even for root: the refusal names the folder and comes
  // from the check before the snapshots (the message of that check).
  check_refused("offline --problem hertz --train 120 --out /proc/contactrom_test.h5", "cannot create a file in folder");
  const std::string db = file("rope.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  check_refused("reduce --db " + db + " --method greedy --out /proc/r.h5", "cannot create a file in folder");
}

BOOST_FIXTURE_TEST_CASE(concurrent_appends_keep_every_snapshot, Fixture) {
  const std::string db = file("h.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 60 --part 1/3 --out " + db).exit_code == 0);
  // Two runs appending the other two parts at the same moment.
  std::vector<contactrom::test::CommandResult> results(2);
  std::thread a([&] { results[0] = run_command(kExe + " offline --problem hertz --train 60 --part 2/3 --append " + db); });
  std::thread b([&] { results[1] = run_command(kExe + " offline --problem hertz --train 60 --part 3/3 --append " + db); });
  a.join();
  b.join();
  for (const auto& r : results) BOOST_TEST(r.exit_code == 0, r.err);
  // The database is complete (a reader refuses anything else) and equals one run's.
  const auto chls = run_command(kExe + " chls --db " + db + " --json");
  BOOST_TEST(chls.exit_code == 0, chls.err);
  const std::string whole = file("whole.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 60 --out " + whole).exit_code == 0);
  const auto n = run_command("/usr/bin/python3 -c \"import h5py, numpy; a = h5py.File('" + db + "'); b = h5py.File('" +
                             whole + "'); print(int(numpy.array_equal(a['primal'][()], b['primal'][()])))\"");
  BOOST_TEST(n.out == "1\n", n.out << n.err);
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(merge_takes_parts_in_any_order, Fixture) {
  for (int k = 1; k <= 3; ++k)
    BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 12 --part " + std::to_string(k) + "/3 --out " +
                              file("p" + std::to_string(k) + ".h5"))
                      .exit_code == 0);
  const auto r = run_command(kExe + " merge " + file("p3.h5") + " " + file("p1.h5") + " " + file("p2.h5") + " --out " +
                             file("m.h5"));
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, r.err);
  // Readable by every reader, and the same arrays as the parts in order.
  BOOST_TEST(run_command(kExe + " chls --db " + file("m.h5") + " --json").exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " merge " + file("p1.h5") + " " + file("p2.h5") + " " + file("p3.h5") + " --out " +
                            file("ordered.h5"))
                    .exit_code == 0);
  // (The summed timings differ in their last bits: the arrays are compared.)
  const auto same = run_command("/usr/bin/python3 -c \"import h5py, numpy; a = h5py.File('" + file("m.h5") +
                                "'); b = h5py.File('" + file("ordered.h5") + "'); print(int(all(numpy.array_equal("
                                "a[k][()], b[k][()]) for k in ('parameters', 'primal', 'dual', 'status'))))\"");
  BOOST_TEST(same.out == "1\n", same.out << same.err);
}

BOOST_FIXTURE_TEST_CASE(a_failed_set_of_outputs_leaves_none_of_them, Fixture) {
  const std::string db = file("rope.h5"), rom = file("rom.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  std::ofstream(file("p.csv")) << "15\n20\n25\n30\n";
  // The third query's VTU target is a folder: nothing may be published.
  fs::create_directories(file("fields/rope_greedy_2.vtu"));
  const auto r = run_command(kExe + " query --rom " + rom + " --params " + file("p.csv") + " --out " + file("q.csv") +
                             " --fields " + file("fields"));
  BOOST_TEST(r.exit_code == 2, r.err);
  BOOST_TEST(!fs::exists(file("q.csv")));
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(file("fields"))) files += e.is_regular_file() ? 1 : 0;
  BOOST_TEST(files == 0);
  BOOST_TEST(temporaries_in(dir) == 0);
  // Without the obstacle, all of them are written.
  fs::remove_all(file("fields"));
  const auto ok = run_command(kExe + " query --rom " + rom + " --params " + file("p.csv") + " --out " + file("q.csv") +
                              " --fields " + file("fields"));
  BOOST_TEST(ok.exit_code == 0, ok.err);
  BOOST_TEST(fs::exists(file("q.csv")));
  BOOST_TEST(fs::exists(file("fields/rope_greedy_3_surface.csv")));
}

BOOST_FIXTURE_TEST_CASE(inputs_are_regular_files_of_bounded_size, Fixture) {
  const std::string db = file("rope.h5"), rom = file("rom.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  check_refused("query --rom " + rom + " --params /dev/zero", "not a regular file");
  check_refused("sparse --method nnls --dictionary /dev/zero --signal /dev/zero", "not a regular file");
  check_refused("fom --problem /dev/zero --param 0.1", "/dev/zero");
}

namespace {

/// Starts contactrom with `args` (stdout and stderr to /dev/null); returns its pid.
pid_t start(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO), ::dup2(null, STDERR_FILENO);
    std::vector<char*> argv{const_cast<char*>(kExe.c_str())};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(kExe.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

/// Runs `args`, sends `sig` after `delay` (unless it ended before), waits for it.
void run_and_signal(const std::vector<std::string>& args, int sig, std::chrono::microseconds delay) {
  const pid_t pid = start(args);
  std::this_thread::sleep_for(delay);
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

/// Wall time of one uninterrupted run of `args`, in microseconds.
long run_time_us(const std::vector<std::string>& args) {
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  ::waitpid(start(args), &status, 0);
  BOOST_REQUIRE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

BOOST_FIXTURE_TEST_CASE(signals_during_writes_leave_the_old_or_the_complete_new_file, Fixture) {
  // rope (no gmsh) keeps each run short; the moments cover the whole run, the
  // write at its end included. Old file or complete new one, never a temporary.
  const std::string db = file("db.h5"), part = file("part.h5"), rom = file("rom.h5"), old = file("old.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --part 1/2 --out " + part).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  std::ofstream(old) << "an older file, not a database";
  const std::string old_bytes = slurp(old), part_bytes = slurp(part);
  struct Target {
    std::string name, path;
    std::vector<std::string> args;
    std::string before;  // the file's content before each run ("" = absent)
    std::string check;   // a command that reads the new file (exit code 0 when complete)
  };
  const std::vector<Target> targets = {
      {"offline --out", file("t_out.h5"), {"offline", "--problem", "rope", "--out", file("t_out.h5")}, old_bytes,
       "chls --db " + file("t_out.h5")},
      {"offline --append", file("t_app.h5"), {"offline", "--problem", "rope", "--append", file("t_app.h5")}, part_bytes,
       "chls --db " + file("t_app.h5")},
      {"reduce --out", file("t_rom.h5"), {"reduce", "--db", db, "--method", "greedy", "--out", file("t_rom.h5")},
       old_bytes, "query --rom " + file("t_rom.h5") + " --param 20"},
  };
  std::mt19937 rng(2026);
  for (const Target& t : targets) {
    std::ofstream(t.path, std::ios::binary) << t.before;
    const long span = run_time_us(t.args);
    int kept_old = 0, complete_new = 0;
    // Every signal that ends a process and can be caught, not only Ctrl-C's.
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGUSR1, SIGUSR2, SIGALRM, SIGXCPU}) {
      for (int trial = 0; trial < 5; ++trial) {
        std::ofstream(t.path, std::ios::binary | std::ios::trunc) << t.before;
        const long delay = std::uniform_int_distribution<long>(0, span)(rng);
        run_and_signal(t.args, sig, std::chrono::microseconds(delay));
        BOOST_TEST_CONTEXT(t.name << ", signal " << sig << " after " << delay << " us of " << span) {
          BOOST_TEST(temporaries_in(dir) == 0);
          BOOST_REQUIRE(fs::exists(t.path));
          if (slurp(t.path) == t.before) {
            ++kept_old;
          } else {
            BOOST_TEST(run_command(kExe + " " + t.check).exit_code == 0);
            ++complete_new;
          }
        }
      }
    }
    BOOST_TEST_MESSAGE(t.name << ": " << kept_old << " runs kept the old file, " << complete_new
                              << " wrote the complete new one");
    BOOST_TEST(kept_old > 0);  // the signals did interrupt runs
  }
}

BOOST_FIXTURE_TEST_CASE(a_signal_during_a_large_set_of_field_files_leaves_no_file_and_no_folder, Fixture) {
  // 300 queries: 600 field files and the CSV, many more than are written at once
  // elsewhere; each interrupted run leaves no temporary file and no field folder, or
  // the whole set.
  const std::string db = file("db.h5"), rom = file("rom.h5"), params = file("p.csv");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  BOOST_REQUIRE(run_command(kExe + " reduce --db " + db + " --method greedy --out " + rom).exit_code == 0);
  {
    std::ofstream p(params);
    for (int i = 0; i < 300; ++i) p << 10.0 + 40.0 * (i + 0.5) / 300 << "\n";
  }
  const std::string fields = file("fields"), csv = file("answers.csv");
  const std::vector<std::string> args = {"query", "--rom", rom, "--params", params, "--out", csv, "--fields", fields};
  const long span = run_time_us(args);
  fs::remove_all(fields), fs::remove(csv);
  std::mt19937 rng(7);
  int none = 0, whole = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const long delay = std::uniform_int_distribution<long>(span / 4, span)(rng);
    run_and_signal(args, trial % 2 ? SIGTERM : SIGINT, std::chrono::microseconds(delay));
    BOOST_TEST_CONTEXT("signal after " << delay << " us of " << span) {
      BOOST_TEST(temporaries_in(dir) == 0);
      if (!fs::exists(fields)) {
        BOOST_TEST(!fs::exists(csv));
        ++none;
      } else {
        BOOST_TEST(std::distance(fs::directory_iterator(fields), fs::directory_iterator()) == 600);
        BOOST_TEST(fs::exists(csv));
        ++whole;
      }
    }
    fs::remove_all(fields), fs::remove(csv);
  }
  BOOST_TEST_MESSAGE(none << " runs left nothing, " << whole << " the whole set");
  BOOST_TEST(none > 0);
}

BOOST_FIXTURE_TEST_CASE(gmsh_ends_with_its_parent, Fixture) {
  // A .geo that loops for days, meshed by the gmsh child of `contactrom fom`: killed
  // by PID (SIGKILL: no handler runs), the parent leaves no gmsh behind.
  std::ofstream(file("loop.geo")) << "For i In {1:1e15}\n  x = i;\nEndFor\nPoint(1) = {0,0,0,0.1};\n";
  std::ofstream(file("loop.toml")) << "[problem]\nname = \"loop\"\nmesh = \"loop.geo\"\n[[parameters]]\nname = \"d\"\n"
                                      "range = [0.0, 1.0]\n[[bodies]]\ngroup = \"a\"\n[[dirichlet]]\ngroup = \"b\"\n"
                                      "displacement = [0.0, 0.0]\n[[contact]]\nslave = \"c\"\nmaster = \"e\"\n";
  const pid_t parent = start({"fom", "--problem", file("loop.toml"), "--param", "0.5"});
  // Wait for the child to appear.
  pid_t child = -1;
  for (int i = 0; i < 200 && child < 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::ifstream children("/proc/" + std::to_string(parent) + "/task/" + std::to_string(parent) + "/children");
    children >> child;
    if (!children) child = -1;
  }
  BOOST_REQUIRE_MESSAGE(child > 0, "the gmsh child did not start");
  ::kill(parent, SIGKILL);
  int status = 0;
  ::waitpid(parent, &status, 0);
  bool gone = false;
  for (int i = 0; i < 100 && !gone; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::ifstream stat("/proc/" + std::to_string(child) + "/stat");
    std::string pid, name, state;
    stat >> pid >> name >> state;
    gone = !stat || state == "Z" || state == "X";  // gone, or a zombie waiting for init
  }
  BOOST_TEST(gone, "gmsh child " << child << " outlived its parent");
  if (!gone) ::kill(child, SIGKILL);
}

BOOST_FIXTURE_TEST_CASE(user_strings_are_quoted_on_one_line, Fixture) {
  // A file name with a newline and an escape sequence: every message stays one line
  // and no control byte reaches the terminal.
  const std::string odd = "'" + file("a\nb\x1b[31m.h5") + "'";
  const std::string rom = std::string(CONTACTROM_SOURCE_DIR) + "/fuzz/corpus/reduced_model/rope_greedy.h5";
  for (const std::string& args :
       {"online --db " + odd, "chls --db " + odd, "reduce --db " + odd + " --method greedy --out " + file("r.h5"),
        "query --rom " + odd + " --param 20", "query --rom " + rom + " --params " + odd, "merge " + odd + " --out " + file("m.h5"),
        "offline --problem rope --append " + odd, "sparse --method nnls --dictionary " + odd + " --signal " + odd,
        "fom --problem " + odd + " --param 1", "offline --problem rope --part " + odd + " --out " + file("p.h5")}) {
    BOOST_TEST_CONTEXT("contactrom " + args) {
      const auto r = run_command(kExe + " " + args);
      BOOST_TEST(r.exit_code == 2);
      BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1, r.err);
      BOOST_TEST(r.err.find('\x1b') == std::string::npos, r.err);
    }
  }
}

BOOST_FIXTURE_TEST_CASE(pipes_devices_and_write_errors_are_reported_not_waited_on, Fixture) {
  const std::string db = file("db.h5"), fifo = file("fifo.h5");
  BOOST_REQUIRE(run_command(kExe + " offline --problem rope --out " + db).exit_code == 0);
  // An HDF5 input that is a pipe or a device: refused at once (the signature search
  // would block on the pipe and read /dev/zero for ever). `timeout` turns a hang into 124.
  BOOST_REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  const std::vector<std::string> readers = {"online --db " + fifo + " --param 20", "query --rom /dev/zero --param 20",
                                            "reduce --db " + fifo + " --out " + file("r.h5"),
                                            "merge " + fifo + " " + db + " --out " + file("m.h5")};
  for (const std::string& args : readers) {
    BOOST_TEST_CONTEXT(args) {
      const auto r = run_command("timeout 60 " + kExe + " " + args);
      BOOST_TEST(r.exit_code == 2);
      BOOST_TEST(r.err.find("is not a regular file") != std::string::npos, r.err);
    }
  }
  // The report on a full disk or a closed stdout: exit 1, one line on stderr.
  for (const char* redirect : {">/dev/full", ">&-"}) {
    const auto r = run_command("sh -c '" + kExe + " problems --json " + redirect + "'");
    BOOST_TEST(r.exit_code == 1, redirect);
    BOOST_TEST(r.err.find("cannot write the report to standard output") != std::string::npos, r.err);
    BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1, r.err);
  }
  // A file name that is not UTF-8 is printed in the JSON report, not a failure
  // after the file was written.
  const std::string latin1 = file("caf\xe9.h5");
  const auto named = run_command(kExe + " offline --problem rope --json --out '" + latin1 + "'");
  BOOST_TEST(named.exit_code == 0, named.err);
  BOOST_TEST(fs::exists(latin1));
  BOOST_TEST(named.out.find("\"out\":") != std::string::npos);
  // A parameter list with a UTF-8 byte-order mark reads as without it.
  std::ofstream(file("bom.csv")) << "\xEF\xBB\xBF" << "20\n30\n";
  const auto bom = run_command(kExe + " online --db " + db + " --validation --params " + file("bom.csv") + " --json");
  BOOST_TEST(bom.exit_code == 0, bom.err);
  BOOST_TEST(bom.out.find("\"validation_size\":2") != std::string::npos, bom.out);
  BOOST_TEST(temporaries_in(dir) == 0);
}

BOOST_FIXTURE_TEST_CASE(an_interrupted_demo_leaves_no_temporary_folder, Fixture) {
  // The demo's database lives in a temporary folder under $TMPDIR: removed at the
  // end and when a signal ends the run while the database is there.
  const std::string tmp = file("tmpdir");
  fs::create_directory(tmp);
  for (int trial = 0; trial < 4; ++trial) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::setenv("TMPDIR", tmp.c_str(), 1);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, STDOUT_FILENO), ::dup2(null, STDERR_FILENO);
      ::execl(kExe.c_str(), kExe.c_str(), "demo", "--train", "600", "--threads", "1", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Wait for the database to appear, then interrupt.
    bool seen = false;
    for (int i = 0; i < 3000 && !seen; ++i) {
      for (const auto& e : fs::recursive_directory_iterator(tmp))
        if (e.path().extension() == ".h5") seen = true;
      if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(pid, trial % 2 ? SIGTERM : SIGINT);
    int status = 0;
    ::waitpid(pid, &status, 0);
    BOOST_TEST_CONTEXT("trial " << trial) {
      BOOST_TEST(seen);
      BOOST_TEST(fs::is_empty(tmp));
    }
  }
}
