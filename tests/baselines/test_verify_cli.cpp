// `contactrom verify` (tools/cmd_verify.cpp) end to end on hertz 12 and ironing
// level 4 for greedy, cpg and full-dictionary against the Ipopt reference (a subset
// of the validation set keeps the test short; the full-size runs are recorded in
// docs/baselines.md): JSON contract, reduced-level penetration ≤ τ + 1e-10, the
// reference's own KKT residuals, the summary table, the CSV file, --bench, and
// `contactrom online --method cpg|full-dictionary` through the registry. Bad input
// ends with one line on stderr, exit code 2 and no output file.
#define BOOST_TEST_MODULE baselines_verify_cli
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "common/run_command.hpp"

namespace fs = std::filesystem;
using contactrom::test::run_command;
using nlohmann::json;

namespace {

const std::string exe = CONTACTROM_EXE;

/// Databases built once for the whole file.
struct Databases {
  std::string dir = contactrom::test::temp_dir();
  std::string hertz = dir + "/hertz12.h5", ironing = dir + "/ironing4.h5";
  Databases() {
    const auto a = run_command(exe + " offline --problem hertz --train 12 --threads 2 --out " + hertz);
    BOOST_REQUIRE_MESSAGE(a.exit_code == 0, a.err);
    const auto b = run_command(exe + " offline --problem ironing --level 4 --threads 2 --out " + ironing);
    BOOST_REQUIRE_MESSAGE(b.exit_code == 0, b.err);
  }
  ~Databases() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

Databases& dbs() {
  static Databases d;
  return d;
}

json run_json(const std::string& args) {
  const auto r = run_command(exe + " " + args + " --json");
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, args + ": " + r.err);
  return json::parse(r.out);  // exactly one JSON object
}

void check_report(const json& j, const std::string& problem, int n, int inaccurate) {
  BOOST_TEST(j["problem"] == problem);
  BOOST_TEST(j["validation_size"] == n);
  const json& ref = j["reference"];
  BOOST_TEST(ref["solver"] == "ipopt");
  BOOST_TEST(ref["failures"] == 0);
  // The Ipopt solution itself satisfies the FOM KKT conditions.
  BOOST_TEST(ref["max_kkt"]["stationarity"].get<double>() <= 1e-8);
  BOOST_TEST(ref["max_kkt"]["penetration"].get<double>() <= 1e-8);
  BOOST_TEST(ref["max_kkt"]["negative_pressure"].get<double>() <= 1e-8);
  BOOST_TEST(ref["max_kkt"]["complementarity"].get<double>() <= 1e-8);
  for (const char* m : {"greedy", "cpg", "full-dictionary"}) {
    BOOST_TEST_CONTEXT(problem << " " << m) {
      const json& r = j["methods"][m];
      BOOST_REQUIRE(r.is_object());
      for (const char* k : {"stationarity", "penetration", "negative_pressure", "complementarity"})
        BOOST_TEST(r["max_kkt"][k].is_number());
      BOOST_TEST(r["nonconverged"] == 0);
      BOOST_TEST(r["reduced_constraint"] == true);
      BOOST_TEST(r["tau"].get<double>() == 1e-8);
      BOOST_TEST(r["inaccurate"] == inaccurate);
      // Reduced level: max_p W_pᵀ(Cu − g) ≤ τ + 1e-10 for the primal–dual active sets.
      // The greedy's fixed point is stopped by the physical test at its own pairing
      // instead (row by row, in units of U: docs/rom.md, "Fixed-point schedule").
      if (std::string(m) != "greedy") {
        BOOST_TEST(r["max_reduced_penetration"].get<double>() <= r["tau"].get<double>() + 1e-10);
        BOOST_TEST(r["reduced_penetration_ok"] == true);
      }
      // A ROM has no negative pressure (λ = Wλ̂, W ≥ 0, λ̂ ≥ 0); the full-order
      // penetration is reported as it is — positive and small.
      BOOST_TEST(r["max_kkt"]["negative_pressure"].get<double>() == 0.0);
      BOOST_TEST(r["max_kkt"]["penetration"].get<double>() > 0.0);
      BOOST_TEST(r["max_kkt"]["penetration"].get<double>() < 0.1);
      BOOST_TEST(r["max_primal_error"].get<double>() < 0.5);
      BOOST_TEST(r["mean_primal_error"].get<double>() <= r["max_primal_error"].get<double>());
      BOOST_TEST(r["dual_basis_size"].get<int>() >= 1);
      BOOST_TEST(r["dual_basis_size"].get<int>() <= r["dictionary_size"].get<int>());
    }
  }
  BOOST_TEST(j["methods"]["full-dictionary"]["dual_basis_size"] == j["methods"]["full-dictionary"]["dictionary_size"]);
}

}  // namespace

BOOST_AUTO_TEST_CASE(hertz_greedy_cpg_full_dictionary_against_ipopt) {
  const json j = run_json("verify --db " + dbs().hertz + " --method greedy,cpg,full-dictionary --limit 5 --threads 2");
  // The first of the five, d = 0.00375, lies far below the smallest training load
  // (0.025): every method answers it with a pressure error of 0.78 and says so.
  check_report(j, "hertz", 5, 1);
  BOOST_TEST(j["train"] == 12);
}

BOOST_AUTO_TEST_CASE(ironing_greedy_cpg_full_dictionary_against_ipopt) {
  const json j = run_json("verify --db " + dbs().ironing + " --method greedy,cpg,full-dictionary --limit 5 --threads 2");
  check_report(j, "ironing", 5, 0);
  BOOST_TEST(j["level"] == 4);
  // The pressure moves with the iron, so no level-4 snapshot lies in the cone of the
  // others at the default tolerance 5e-2: CPG keeps every one of them.
  BOOST_TEST(j["methods"]["cpg"]["dual_basis_size"].get<int>() == j["methods"]["cpg"]["dictionary_size"].get<int>());
}

BOOST_AUTO_TEST_CASE(summary_table_and_csv) {
  const std::string csv = dbs().dir + "/verify.csv";
  const auto r = run_command(exe + " verify --db " + dbs().hertz + " --method cpg,greedy --limit 3 --out " + csv);
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, r.err);
  for (const char* text : {"ipopt reference", "greedy", "cpg", "stationar.", "red. pen.", "reduced penetration <= tau"})
    BOOST_TEST(r.out.find(text) != std::string::npos, "missing '" << text << "' in\n" << r.out);
  std::istringstream in(contactrom::test::slurp(csv));
  std::string line;
  std::getline(in, line);
  BOOST_TEST(line.rfind("method,d,primal_error,dual_error", 0) == 0u, line);
  int rows = 0, ipopt = 0;
  while (std::getline(in, line)) {
    ++rows;
    if (line.rfind("ipopt,", 0) == 0) ++ipopt;
  }
  BOOST_TEST(rows == 9);  // 3 parameters × (reference + 2 methods)
  BOOST_TEST(ipopt == 3);
}

BOOST_AUTO_TEST_CASE(bench_with_the_fom_reference) {
  const json j = run_json("verify --db " + dbs().hertz + " --method greedy,cpg --reference fom --bench --repeats 1");
  BOOST_TEST(j["reference"]["solver"] == "fom");
  BOOST_TEST(j["validation_size"] == 119);
  BOOST_TEST(j["fom_median_time_s"].get<double>() > 0.0);
  for (const char* m : {"greedy", "cpg"}) {
    // The speed-up is the quotient of the two medians of the same run (no assertion on
    // the times themselves: they are benchmarks, not tests).
    const double t = j["methods"][m]["median_time_s"].get<double>();
    BOOST_TEST(t > 0.0);
    const double expected = j["fom_median_time_s"].get<double>() / t;
    BOOST_TEST(std::abs(j["methods"][m]["speedup_vs_fom"].get<double>() - expected) <= 1e-12 * expected);
    BOOST_TEST(j["methods"][m]["nonconverged"] == 0);
  }
  BOOST_TEST(j["methods"]["cpg"]["basis_time_s"].get<double>() >= 0.0);
}

BOOST_AUTO_TEST_CASE(bench_on_a_database_skips_the_offline_stage) {
  // bench --db rebuilds the problem from the database and times on its snapshots.
  const json j = run_json("bench --db " + dbs().ironing + " --repeats 1 --queries 2 --ipopt-queries 1");
  BOOST_TEST(j["problem"] == "ironing");
  BOOST_TEST(j["training"] == 4);
  BOOST_TEST(j["snapshots"] == 17);
  BOOST_TEST(j["offline_s"].get<double>() == 0.0);
  BOOST_TEST(j["rom_greedy"].get<double>() > 0.0);
  // ironing's stiffness is constant: the FOM's limit (solve_at its final pairing) is timed.
  BOOST_TEST(j["fom_limit"].get<double>() > 0.0);
  BOOST_TEST(j["fom_pairing_iterations"].get<double>() >= 1.0);
  BOOST_TEST(j["ratios"].contains("fom_active_set/fom_limit"));
  // The text output: every time and ratio line is a name, blanks, then a number.
  const auto text = run_command(exe + " bench --db " + dbs().ironing + " --repeats 1 --queries 2 --ipopt-queries 1");
  BOOST_REQUIRE(text.exit_code == 0);
  std::istringstream lines(text.out);
  std::string line;
  int rows = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("  ", 0) != 0) continue;
    std::istringstream fields(line);
    std::string name;
    double value = 0.0;
    std::string rest;
    fields >> name >> value;
    BOOST_TEST((!fields.fail() && !(fields >> rest)), line);
    ++rows;
  }
  BOOST_TEST(rows > 20);
  const auto r = run_command(exe + " bench --db " + dbs().ironing + " --level 4");
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(r.err.find("--problem, not --db") != std::string::npos, r.err);
}

BOOST_AUTO_TEST_CASE(bench_without_ipopt) {
  // --ipopt-queries 0 leaves Ipopt out: no fom_ipopt time and no ratio naming it,
  // the active-set FOM and the ROMs still timed.
  const json j = run_json("bench --problem rope --repeats 1 --queries 2 --ipopt-queries 0");
  BOOST_TEST(j["ipopt_queries"].get<int>() == 0);
  BOOST_TEST(!j.contains("fom_ipopt"));
  BOOST_TEST(!j["ratios"].contains("fom_ipopt/fom_active_set"));
  BOOST_TEST(j["fom_active_set"].get<double>() > 0.0);
  BOOST_TEST(j["ratios"].contains("fom_active_set/rom_greedy"));
  // rope's stiffness depends on its parameter: no limit query, so no limit keys.
  BOOST_TEST(!j.contains("fom_limit"));
  BOOST_TEST(!j.contains("fom_pairing_iterations"));
  BOOST_TEST(!j["ratios"].contains("fom_active_set/fom_limit"));
}

BOOST_AUTO_TEST_CASE(bench_reports_every_method_and_consistent_ratios) {
  // `contactrom bench` on rope (tiny): every registered ROM and both FOM solvers are
  // timed in the one run, and every ratio is the quotient of the two medians it names
  // (no assertion on the times themselves: they are benchmarks, not tests).
  const json j = run_json("bench --problem rope --repeats 1 --queries 3 --ipopt-queries 1");
  for (const char* k : {"fom_active_set", "fom_ipopt", "rom_greedy", "rom_greedy_nested", "rom_cpg",
                        "rom_full_dictionary", "rom_convex_hull", "rom_cpg_warm", "rom_greedy_init_empty",
                        "rom_greedy_nested_init_empty"})
    BOOST_TEST((j.contains(k) && j[k].get<double>() > 0.0), k);
  const json& ratios = j["ratios"];
  for (const char* k : {"fom_active_set/rom_greedy", "fom_active_set/rom_greedy_nested", "rom_cpg/rom_greedy",
                        "rom_cpg/rom_greedy_nested", "rom_greedy_nested/rom_greedy", "fom_ipopt/fom_active_set",
                        "rom_cpg_warm/rom_greedy", "rom_greedy_init_empty/rom_greedy",
                        "rom_greedy_nested_init_empty/rom_greedy_nested", "fom_active_set/rom_cpg_warm",
                        "rom_cpg_without_operators/rom_greedy_without_operators",
                        "rom_full_dictionary_without_operators/rom_greedy_nested_without_operators"})
    BOOST_TEST(ratios.contains(k), k);
  // The paper's convention (contact-operator construction left out) for the methods
  // that clock it; convex-hull does not.
  for (const char* k : {"rom_greedy_without_operators", "rom_greedy_nested_without_operators",
                        "rom_cpg_without_operators", "rom_full_dictionary_without_operators"})
    BOOST_TEST((j.contains(k) && j[k].get<double>() > 0.0), k);
  BOOST_TEST(!j.contains("rom_convex_hull_without_operators"));
  // One FOM median per interleaved round (--repeats 1 here).
  BOOST_REQUIRE(j.contains("fom_active_set_rounds"));
  BOOST_TEST(j["fom_active_set_rounds"].size() == 1u);
  BOOST_TEST(j["fom_active_set_rounds"][0].get<double>() > 0.0);
  int checked = 0;
  for (auto it = ratios.begin(); it != ratios.end(); ++it) {
    const std::string key = it.key();
    const size_t slash = key.find('/');
    BOOST_REQUIRE(slash != std::string::npos);
    const double expected = j[key.substr(0, slash)].get<double>() / j[key.substr(slash + 1)].get<double>();
    BOOST_TEST(std::abs(it.value().get<double>() - expected) <= 1e-12 * expected, key);
    ++checked;
  }
  BOOST_TEST(checked >= 6);
}

BOOST_AUTO_TEST_CASE(online_runs_cpg_and_full_dictionary) {
  for (const char* m : {"cpg", "full-dictionary"}) {
    const json j = run_json("online --db " + dbs().hertz + " --method " + m + " --validation --threads 2");
    BOOST_TEST(j["method"] == m);
    for (const char* k : {"delta", "dictionary_size", "primal_rank", "mean_primal_error", "mean_dual_error",
                          "mean_sparsity", "mean_iterations", "mean_time_s", "nonconverged"})
      BOOST_TEST(j.contains(k), m << " misses " << k);
    BOOST_TEST(j["nonconverged"] == 0);
    BOOST_TEST(j["mean_primal_error"].get<double>() < 0.1);
    // The dual basis: all columns for the full dictionary, a subset for CPG.
    if (std::string(m) == "full-dictionary")
      BOOST_TEST(j["dual_basis_size"] == j["dictionary_size"]);
    else
      BOOST_TEST(j["dual_basis_size"].get<int>() <= j["dictionary_size"].get<int>());
  }
}

BOOST_AUTO_TEST_CASE(online_option_reaches_the_method) {
  // A looser CPG tolerance can only give a basis of at most the same size; cpg_max_size
  // caps it exactly, so the option demonstrably reaches the method.
  const std::string base = "online --db " + dbs().hertz + " --method cpg --validation --threads 2";
  const json tight = run_json(base + " --option cpg_tolerance=1e-3");
  const json loose = run_json(base + " --option cpg_tolerance=0.2");
  const json capped = run_json(base + " --option cpg_max_size=2");
  BOOST_TEST(loose["dual_basis_size"].get<int>() <= tight["dual_basis_size"].get<int>());
  BOOST_TEST(loose["dual_basis_size"].get<int>() < tight["dual_basis_size"].get<int>());
  BOOST_TEST(capped["dual_basis_size"] == 2);
}

BOOST_AUTO_TEST_CASE(init_option_reaches_the_methods) {
  // The warm start (default) needs fewer solves than the paper's empty start, for the
  // greedy through `online --option` and for CPG through `verify --init`.
  const std::string base = "online --db " + dbs().hertz + " --validation --threads 2 --method ";
  const json warm = run_json(base + "greedy");
  const json cold = run_json(base + "greedy --option init=empty");
  BOOST_TEST(warm["mean_iterations"].get<double>() < cold["mean_iterations"].get<double>());
  BOOST_TEST(warm["nonconverged"] == 0);
  const std::string verify = "verify --db " + dbs().hertz + " --method cpg --reference fom --threads 2 --limit 9";
  const json cpg_cold = run_json(verify);
  const json cpg_warm = run_json(verify + " --init cell");
  BOOST_TEST(cpg_warm["methods"]["cpg"]["mean_iterations"].get<double>() <
             cpg_cold["methods"]["cpg"]["mean_iterations"].get<double>());
}

BOOST_AUTO_TEST_CASE(bad_input_is_one_line_exit_2_and_no_file) {
  const std::string csv = dbs().dir + "/bad.csv";
  const std::string cases[] = {
      "verify --db " + dbs().hertz + " --method nosuch --out " + csv,
      "verify --db " + dbs().hertz + " --method greedy,greedy --out " + csv,
      "verify --db " + dbs().dir + "/missing.h5 --method cpg --out " + csv,
      "verify --db " + dbs().hertz + " --method cpg --reference nosuch --out " + csv,
      "verify --db " + dbs().hertz + " --method cpg --cpg-tolerance 2 --out " + csv,
      "verify --db " + dbs().hertz + " --out " + csv,
      "online --db " + dbs().hertz + " --method greedy --option foo=1 --out " + csv,
      "online --db " + dbs().hertz + " --method cpg --option cpg_tolerance --out " + csv,
      "online --db " + dbs().hertz + " --method cpg --option cpg_tolerance=x --out " + csv,
      "online --db " + dbs().hertz + " --method greedy --option init=warm --out " + csv,
      "online --db " + dbs().hertz + " --method cpg --option init=nearest --out " + csv,
      "verify --db " + dbs().hertz + " --method greedy-nested --init hot --out " + csv,
  };
  for (const std::string& c : cases) {
    const auto r = run_command(exe + " " + c);
    BOOST_TEST(r.exit_code == 2, c << ": exit " << r.exit_code);
    BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1, c << ": " << r.err);
    BOOST_TEST(r.err.rfind("contactrom: error: ", 0) == 0u, c << ": " << r.err);
    BOOST_TEST(!fs::exists(csv), c);
  }
}

BOOST_AUTO_TEST_CASE(a_delta_that_keeps_no_mode_is_warned_about) {
  // δ = 1 keeps no POD mode: a valid but degenerate request (exit 0) that says so
  // on stderr; a usual δ does not.
  const std::string base = exe + " online --db " + dbs().hertz + " --method greedy --param 0.1 --json";
  const auto none = run_command(base + " --delta 1");
  BOOST_TEST(none.exit_code == 0, none.err);
  BOOST_TEST(none.err.find("keeps no POD mode") != std::string::npos, none.err);
  const auto usual = run_command(base + " --delta 1e-8");
  BOOST_TEST(usual.exit_code == 0, usual.err);
  BOOST_TEST(usual.err.find("warning") == std::string::npos, usual.err);
}
