// Tests of `contactrom sparse` (tools/cmd_sparse.cpp) and of the CSV reader behind
// it (rom/dense_csv.hpp): the JSON contract, the human-readable summary, one-line
// errors with exit code 2 for bad input, and the objective of the CLI's NNLS
// against SciPy's scipy.optimize.nnls (tests/rom/nnls_scipy_check.py).
//
// The SciPy comparison FAILS when /usr/bin/python3 cannot import SciPy, unless the
// environment sets CONTACTROM_ALLOW_NO_SCIPY=1; the skip is then reported.
#define BOOST_TEST_MODULE rom_sparse_cli
#include <boost/test/unit_test.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "common/random_problems.hpp"
#include <contactrom/core/errors.hpp>
#include <contactrom/core/nnls.hpp>
#include <contactrom/rom/dense_csv.hpp>
#include <contactrom/rom/omp.hpp>

namespace fs = std::filesystem;
using contactrom::InputError;
using contactrom::test::gaussian;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// A fresh folder under the system temporary directory, removed on destruction.
struct TempDir {
  fs::path path;
  TempDir() {
    static std::atomic<int> counter{0};
    path = fs::temp_directory_path() /
           ("contactrom_sparse_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

void write_csv(const std::string& path, const MatrixXd& m) {
  std::ofstream out(path);
  out << std::setprecision(17);
  for (Index i = 0; i < m.rows(); ++i) {
    for (Index j = 0; j < m.cols(); ++j) out << (j ? "," : "") << m(i, j);
    out << "\n";
  }
}

std::string quote(const std::string& s) { return "'" + s + "'"; }

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs `contactrom <args>` for every entry of `arguments` concurrently (one shell,
/// background jobs) and collects exit codes, stdout and stderr.
std::vector<CommandResult> run_cli(const std::vector<std::string>& arguments, const TempDir& dir) {
  std::string script;
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string stem = dir.file("run" + std::to_string(i));
    script += "( " + quote(CONTACTROM_EXE) + " " + arguments[i] + " > " + quote(stem + ".out") + " 2> " +
              quote(stem + ".err") + "; echo $? > " + quote(stem + ".rc") + " ) &\n";
  }
  script += "wait\n";
  const int status = std::system(script.c_str());
  BOOST_REQUIRE_MESSAGE(status == 0, "the shell running contactrom failed: " << status);
  std::vector<CommandResult> results(arguments.size());
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string stem = dir.file("run" + std::to_string(i));
    results[i].exit_code = std::stoi(read_text(stem + ".rc"));
    results[i].out = read_text(stem + ".out");
    results[i].err = read_text(stem + ".err");
  }
  return results;
}

CommandResult run_one(const std::string& arguments, const TempDir& dir) { return run_cli({arguments}, dir).at(0); }

VectorXd coefficients(const nlohmann::json& out) {
  const auto values = out.at("coefficients").get<std::vector<double>>();
  return Eigen::Map<const VectorXd>(values.data(), static_cast<Index>(values.size()));
}

std::string sparse_args(const std::string& method, const std::string& d, const std::string& x,
                        const std::string& extra = "") {
  return "sparse --method " + method + " --dictionary " + quote(d) + " --signal " + quote(x) + " " + extra;
}

}  // namespace

// ---------------------------------------------------------------------------
// CSV reader
// ---------------------------------------------------------------------------

BOOST_AUTO_TEST_CASE(csv_reader_accepts_blanks_comments_and_crlf) {
  std::istringstream in("# header\n1, 2.5 ,-3e-1\r\n\n  4,5,6\n");
  const MatrixXd m = contactrom::rom::read_dense_csv(in, "inline.csv");
  BOOST_TEST(m.rows() == 2);
  BOOST_TEST(m.cols() == 3);
  BOOST_TEST(m(0, 1) == 2.5);
  BOOST_TEST(m(0, 2) == -0.3);
  BOOST_TEST(m(1, 0) == 4.0);
}

BOOST_AUTO_TEST_CASE(csv_reader_accepts_numpy_savetxt_default_blank_separated_files) {
  // numpy.savetxt(f, a) writes "%.18e" values separated by one space.
  std::istringstream in("1.000000000000000000e+00 2.500000000000000000e+00\n\t-3e-1\t 4\n");
  const MatrixXd m = contactrom::rom::read_dense_csv(in, "savetxt.txt");
  BOOST_TEST(m.rows() == 2);
  BOOST_TEST(m.cols() == 2);
  BOOST_TEST(m(0, 1) == 2.5);
  BOOST_TEST(m(1, 0) == -0.3);
  std::istringstream ragged("1 2\n3\n");
  BOOST_CHECK_THROW(contactrom::rom::read_dense_csv(ragged, "r.txt"), InputError);
}

BOOST_AUTO_TEST_CASE(csv_reader_errors_name_file_line_and_column) {
  const auto message_of = [](const std::string& text) {
    std::istringstream in(text);
    try {
      contactrom::rom::read_dense_csv(in, "m.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  BOOST_TEST(message_of("1,2\n3,4\n5\n") == "m.csv: line 3: 1 values, expected 2 (as on line 1)");
  BOOST_TEST(message_of("1,2\n3,abc\n") == "m.csv: line 2, column 2: 'abc' is not a number");
  BOOST_TEST(message_of("1,,2\n") == "m.csv: line 1, column 2: empty value, expected a number");
  BOOST_TEST(message_of("1,nan\n") == "m.csv: line 1, column 2: 'nan' is not a finite number");
  BOOST_TEST(message_of("1,2x\n") == "m.csv: line 1, column 2: '2x' is not a number");
  BOOST_TEST(message_of("\n# only a comment\n").find("m.csv: no values (nothing but blank lines, comments or a header)") == 0u);
}

BOOST_AUTO_TEST_CASE(vector_reader_takes_a_row_or_a_column_only) {
  TempDir dir;
  write_text(dir.file("col.csv"), "1\n2\n3\n");
  write_text(dir.file("row.csv"), "1,2,3\n");
  write_text(dir.file("mat.csv"), "1,2\n3,4\n");
  BOOST_TEST((contactrom::rom::read_vector_csv(dir.file("col.csv")) == contactrom::rom::read_vector_csv(dir.file("row.csv"))));
  BOOST_CHECK_THROW(contactrom::rom::read_vector_csv(dir.file("mat.csv")), InputError);
  try {
    contactrom::rom::read_vector_csv(dir.file("missing.csv"));
    BOOST_FAIL("no error for a missing file");
  } catch (const InputError& e) {
    BOOST_TEST(std::string(e.what()) == "CSV file '" + dir.file("missing.csv") + "' not found");
  }
  // A device is not a CSV file: refused before reading (it would never end).
  try {
    contactrom::rom::read_vector_csv("/dev/zero");
    BOOST_FAIL("no error for /dev/zero");
  } catch (const InputError& e) {
    BOOST_TEST(std::string(e.what()).find("not a regular file") != std::string::npos, e.what());
  }
}

// ---------------------------------------------------------------------------
// contactrom sparse: output contract
// ---------------------------------------------------------------------------

BOOST_AUTO_TEST_CASE(json_output_holds_the_contract_keys_at_full_precision) {
  TempDir dir;
  std::mt19937_64 gen(101);
  const MatrixXd d = gaussian(12, 30, gen);
  VectorXd a = VectorXd::Zero(30);
  a(4) = 1.25;
  a(17) = -0.75;
  a(22) = 2.0 / 3.0;
  const VectorXd x = d * a;
  write_csv(dir.file("D.csv"), d);
  write_csv(dir.file("x_col.csv"), x);
  write_csv(dir.file("x_row.csv"), x.transpose());
  const auto results = run_cli({sparse_args("omp", dir.file("D.csv"), dir.file("x_col.csv"), "--json"),
                                sparse_args("omp", dir.file("D.csv"), dir.file("x_row.csv"), "--json --atoms 2"),
                                sparse_args("focuss", dir.file("D.csv"), dir.file("x_col.csv"), "--json"),
                                sparse_args("nnfocuss", dir.file("D.csv"), dir.file("x_col.csv"), "--json --max-iter 50")},
                               dir);
  for (const auto& r : results) {
    BOOST_TEST_CONTEXT(r.err) {
      BOOST_TEST(r.exit_code == 0);
      BOOST_TEST(r.err.empty());
    }
  }
  // Exactly one JSON object on stdout (parse() rejects anything after it).
  const nlohmann::json omp = nlohmann::json::parse(results[0].out);
  BOOST_TEST(omp.at("method").get<std::string>() == "omp");
  BOOST_TEST(omp.at("status").get<std::string>() == "success");
  BOOST_TEST(omp.at("iterations").get<int>() == 3);
  BOOST_TEST(omp.at("residual").get<double>() <= 1e-12 * x.norm());
  // The printed coefficients are bit-identical to the library's (round-trip output).
  contactrom::rom::Omp library;
  const VectorXd expected = library.compute(contactrom::rom::read_dense_csv(dir.file("D.csv")))
                                .solve(contactrom::rom::read_vector_csv(dir.file("x_col.csv")));
  BOOST_TEST((coefficients(omp) - expected).norm() == 0.0);
  BOOST_TEST((coefficients(omp) - a).norm() <= 1e-12);

  const nlohmann::json capped = nlohmann::json::parse(results[1].out);
  BOOST_TEST(capped.at("iterations").get<int>() == 2);
  BOOST_TEST(capped.at("stop_reason").get<std::string>() == "atom_limit");

  const nlohmann::json focuss = nlohmann::json::parse(results[2].out);
  BOOST_TEST(focuss.at("status").get<std::string>() == "success");
  BOOST_TEST(focuss.at("residual").get<double>() <= 1e-10 * x.norm());

  const nlohmann::json nnfocuss = nlohmann::json::parse(results[3].out);
  BOOST_TEST(nnfocuss.at("method").get<std::string>() == "nnfocuss");
  BOOST_TEST(coefficients(nnfocuss).minCoeff() >= 0.0);
  BOOST_TEST(coefficients(nnfocuss).size() == 30);
}

BOOST_AUTO_TEST_CASE(human_readable_summary_without_json) {
  TempDir dir;
  write_text(dir.file("D.csv"), "1,0\n0,1\n");
  write_text(dir.file("x.csv"), "2,-1\n");
  const CommandResult r = run_one(sparse_args("nnls", dir.file("D.csv"), dir.file("x.csv")), dir);
  BOOST_TEST(r.exit_code == 0);
  BOOST_TEST(r.out.find("status      success") != std::string::npos);
  BOOST_TEST(r.out.find("||D a - x|| = 1") != std::string::npos);
  BOOST_TEST(r.out.find("a[0] = 2") != std::string::npos);
  BOOST_TEST(r.out.find("non-zeros   1 of 2") != std::string::npos);
}

// ---------------------------------------------------------------------------
// contactrom sparse: bad input
// ---------------------------------------------------------------------------

BOOST_AUTO_TEST_CASE(bad_input_gives_a_one_line_error_and_exit_code_2) {
  TempDir dir;
  write_text(dir.file("D.csv"), "1,2,3\n4,5,6\n");
  write_text(dir.file("x.csv"), "1\n2\n");
  write_text(dir.file("x3.csv"), "1\n2\n3\n");
  write_text(dir.file("ragged.csv"), "1,2,3\n4,5\n");
  write_text(dir.file("text.csv"), "1,2,3\n4,five,6\n");
  write_text(dir.file("empty.csv"), "");
  const std::string d = dir.file("D.csv");
  const std::string x = dir.file("x.csv");
  struct Case {
    std::string args;
    std::string expected;  // substring of the one-line message
  };
  const std::vector<Case> cases = {
      {sparse_args("omp", dir.file("ragged.csv"), x), "ragged.csv: line 2: 2 values, expected 3 (as on line 1)"},
      {sparse_args("omp", dir.file("text.csv"), x), "text.csv: line 2, column 2: 'five' is not a number"},
      {sparse_args("nnls", d, dir.file("x3.csv")), "has 3 values, expected 2 (the rows of dictionary"},
      {sparse_args("lasso", d, x), "unknown --method 'lasso': expected nnls, omp, focuss or nnfocuss"},
      {sparse_args("nnls", dir.file("empty.csv"), x), "empty.csv: no values (nothing but blank lines, comments or a header)"},
      {sparse_args("nnls", d, x, "--atoms 2"), "--atoms applies to --method omp only"},
      {"bench-sparse --repeats 0", "--repeats '0' is outside the range; expected an integer in [1, 1000]"},
  };
  std::vector<std::string> args;
  for (const auto& c : cases) args.push_back(c.args);
  const auto results = run_cli(args, dir);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    BOOST_TEST_CONTEXT(cases[i].args) {
      BOOST_TEST(results[i].exit_code == 2);
      BOOST_TEST(results[i].out.empty());
      BOOST_TEST(results[i].err.find(cases[i].expected) != std::string::npos, "stderr: " << results[i].err);
      BOOST_TEST(results[i].err.find("contactrom: error: ") == 0u);
      BOOST_TEST(std::count(results[i].err.begin(), results[i].err.end(), '\n') == 1);
    }
  }
}

// ---------------------------------------------------------------------------
// NNLS objective against SciPy, through the CLI
// ---------------------------------------------------------------------------

BOOST_AUTO_TEST_CASE(nnls_objective_matches_scipy_through_the_cli) {
  TempDir dir;
  std::mt19937_64 gen(2024);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  struct Problem {
    std::string name;
    MatrixXd a;
    VectorXd b;
  };
  std::vector<Problem> problems;
  problems.push_back({"tall", gaussian(40, 15, gen), gaussian(40, 1, gen)});
  problems.push_back({"wide", gaussian(15, 40, gen), gaussian(15, 1, gen)});
  problems.push_back({"rank_deficient", gaussian(30, 4, gen) * gaussian(4, 20, gen), gaussian(30, 1, gen)});
  {
    MatrixXd a = gaussian(25, 20, gen);
    VectorXd x = VectorXd::Zero(20);
    for (Index j = 0; j < 20; j += 3) x(j) = 0.5 + uniform(gen);
    problems.push_back({"exact_non_negative", a, a * x});
  }
  {
    MatrixXd a = gaussian(30, 10, gen);
    problems.push_back({"all_negative", a, -a * (VectorXd::Ones(10) + 0.5 * gaussian(10, 1, gen).cwiseAbs())});
  }
  {
    MatrixXd a = gaussian(20, 12, gen);
    a.col(3).setZero();
    a.col(7) = a.col(2);
    problems.push_back({"zero_and_duplicate", a, gaussian(20, 1, gen)});
  }
  {
    MatrixXd a = gaussian(79, 30, gen);
    for (Index j = 0; j < 30; ++j) a.col(j) *= std::pow(10.0, 3.0 * uniform(gen) - 1.5);
    problems.push_back({"scaled_79x30", a, gaussian(79, 1, gen)});
  }
  problems.push_back({"wide_60x129", gaussian(60, 129, gen), gaussian(60, 1, gen)});

  std::vector<std::string> args;
  for (const auto& p : problems) {
    write_csv(dir.file(p.name + ".A.csv"), p.a);
    write_csv(dir.file(p.name + ".b.csv"), p.b);
    args.push_back(sparse_args("nnls", dir.file(p.name + ".A.csv"), dir.file(p.name + ".b.csv"), "--json"));
  }
  const auto results = run_cli(args, dir);

  // SciPy reference (one interpreter for all problems).
  const std::string python = "/usr/bin/python3";
  const std::string script = std::string(CONTACTROM_SOURCE_DIR) + "/tests/rom/nnls_scipy_check.py";
  const std::string command = quote(python) + " " + quote(script) + " " + quote(dir.path.string()) + " > " +
                              quote(dir.file("scipy.json")) + " 2> " + quote(dir.file("scipy.err"));
  const int status = std::system(command.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 3 || code == 126 || code == 127) {
    std::string why = code == 3 ? read_text(dir.file("scipy.err")) : python + " cannot be run";
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
    const char* allow = std::getenv("CONTACTROM_ALLOW_NO_SCIPY");
    if (allow && std::string(allow) == "1") {
      BOOST_TEST_MESSAGE("SKIPPED nnls_objective_matches_scipy_through_the_cli: " << why
                                                                                  << " (CONTACTROM_ALLOW_NO_SCIPY=1)");
      return;
    }
    BOOST_FAIL("SciPy reference unavailable: " << why
                                               << " -- install python3-scipy for /usr/bin/python3, or set "
                                                  "CONTACTROM_ALLOW_NO_SCIPY=1 to skip this comparison");
  }
  BOOST_REQUIRE_MESSAGE(code == 0, "nnls_scipy_check.py failed (" << code << "): " << read_text(dir.file("scipy.err")));
  const nlohmann::json scipy = nlohmann::json::parse(read_text(dir.file("scipy.json")));
  BOOST_TEST_MESSAGE("SciPy " << scipy.at("scipy").get<std::string>());

  for (std::size_t i = 0; i < problems.size(); ++i) {
    const Problem& p = problems[i];
    BOOST_TEST_CONTEXT(p.name) {
      BOOST_TEST(results[i].exit_code == 0, results[i].err);
      const nlohmann::json out = nlohmann::json::parse(results[i].out);
      BOOST_TEST(out.at("status").get<std::string>() == "success");
      const VectorXd x = coefficients(out);
      BOOST_TEST(x.minCoeff() >= 0.0);
      const double ours = 0.5 * (p.a * x - p.b).squaredNorm();
      const nlohmann::json& reference = scipy.at("problems").at(p.name);
      BOOST_REQUIRE_MESSAGE(!reference.contains("error"), "SciPy failed: " << reference.dump());
      const double theirs = reference.at("objective").get<double>();
      // Relative agreement 1e-8; the absolute floor (1e-14 of the objective at x = 0)
      // only matters when both objectives are zero up to rounding.
      const double allowed = 1e-8 * theirs + 1e-14 * 0.5 * p.b.squaredNorm();
      BOOST_TEST(std::abs(ours - theirs) <= allowed, "ours " << ours << " scipy " << theirs);
    }
  }
}
