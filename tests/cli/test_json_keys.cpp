// One name per quantity: the commands that report the same quantity (errors
// against the FOM, their means and maxima, sparsity, iterations, ...) use the same
// JSON key and CSV column, and `online --json` prints exactly the keys of the
// library's summary list (rom::summary_values), which the Python module uses too.
#define BOOST_TEST_MODULE cli_json_keys
#include <boost/test/unit_test.hpp>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "common/run_command.hpp"
#include <contactrom/rom/online_evaluation.hpp>

using contactrom::test::run_command;

namespace {

const std::string kExe = CONTACTROM_EXE;

/// The error keys every evaluation against the FOM prints (rom::append_error_values).
std::set<std::string> error_keys() {
  contactrom::rom::SummaryValues values;
  contactrom::rom::append_error_values(values, contactrom::rom::ErrorStatistics{});
  std::set<std::string> keys;
  for (const auto& kv : values) keys.insert(kv.first);
  return keys;
}

/// Every key naming an error, for the table of docs/json_keys.md.
const std::set<std::string> kErrorNames = {"primal_error", "dual_error", "errors", "chls_error", "max_chls_error",
                                           "mean_chls_error"};

std::set<std::string> keys_of(const nlohmann::json& j) {
  std::set<std::string> keys;
  for (const auto& item : j.items()) keys.insert(item.key());
  return keys;
}

/// Keys that name an error must be the documented ones.
void check_error_names(const nlohmann::json& j, const std::string& command) {
  const std::set<std::string> shared = error_keys();
  for (const std::string& key : keys_of(j))
    if (key.find("error") != std::string::npos)
      BOOST_TEST((shared.count(key) + kErrorNames.count(key) == 1u), command << ": undocumented error key " << key);
}

nlohmann::json json_of(const std::string& args) {
  const auto r = run_command(kExe + " " + args);
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, args << ": " << r.err);
  return nlohmann::json::parse(r.out);
}

std::string first_line(const std::string& path) {
  const std::string text = contactrom::test::slurp(path);
  return text.substr(0, text.find('\n'));
}

}  // namespace

BOOST_AUTO_TEST_CASE(commands_name_the_same_quantity_alike) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h5.h5";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 5 --threads 2 --out " + db).exit_code == 0);

  const nlohmann::json online =
      json_of("online --db " + db + " --method greedy --validation --threads 2 --out " + dir + "/online.csv --json");
  const nlohmann::json hull = json_of("hull-report --db " + db + " --threads 2 --out " + dir + "/hull.csv --json");
  const nlohmann::json verify = json_of("verify --db " + db + " --method greedy --reference fom --limit 3 --threads 2 "
                                        "--out " + dir + "/verify.csv --json");
  const nlohmann::json& verify_greedy = verify["methods"]["greedy"];

  // online --validation prints the library's summary list, nothing more or less.
  contactrom::rom::EvaluationSummary empty;
  std::set<std::string> library;
  for (const auto& kv : contactrom::rom::summary_values(empty)) library.insert(kv.first);
  BOOST_TEST((keys_of(online) == library));

  // The means and maxima of the errors carry the same keys in the three commands.
  for (const std::string& key : error_keys()) {
    BOOST_TEST(online.contains(key), "online lacks " << key);
    BOOST_TEST(hull.contains(key), "hull-report lacks " << key);
    BOOST_TEST(verify_greedy.contains(key), "verify lacks " << key);
  }
  for (const char* key : {"mean_sparsity", "mean_iterations", "nonconverged", "dictionary_size", "delta", "method"}) {
    BOOST_TEST(online.contains(key), "online lacks " << key);
    BOOST_TEST(hull.contains(key), "hull-report lacks " << key);
    BOOST_TEST((verify_greedy.contains(key) || verify.contains(key)), "verify lacks " << key);
  }
  // The same run, the same numbers: verify's errors against the FOM reference are
  // bounded by what online reports over the whole validation set.
  BOOST_TEST(verify_greedy["max_primal_error"].get<double>() <= online["max_primal_error"].get<double>() * (1 + 1e-12));

  const nlohmann::json single = json_of("online --db " + db + " --method greedy --param 0.1 --json");
  const nlohmann::json chls = json_of("chls --db " + db + " --json");
  check_error_names(online, "online --validation");
  check_error_names(single, "online --param");
  check_error_names(hull, "hull-report");
  check_error_names(verify_greedy, "verify");
  check_error_names(chls, "chls");
  for (const char* key : {"primal_error", "dual_error", "errors"}) BOOST_TEST(single.contains(key), key);
  for (const char* key : {"chls_error", "max_chls_error", "mean_chls_error"}) BOOST_TEST(chls.contains(key), key);

  // CSV columns: the per-row errors carry the JSON's names.
  BOOST_TEST(first_line(dir + "/online.csv").rfind("d,primal_error,dual_error,", 0) == 0u);
  BOOST_TEST(first_line(dir + "/hull.csv").rfind("d,primal_error,dual_error,errors,", 0) == 0u);
  BOOST_TEST(first_line(dir + "/verify.csv").rfind("method,d,primal_error,dual_error,errors,", 0) == 0u);
}

// verify --option gives a setting to every listed method that has it and to no other:
// a loose CPG tolerance shrinks CPG's basis while the greedy (which has no such
// setting) answers as without it; init=empty, which both have, sends the greedy back
// to the paper's empty start and its many more iterations; estimate=false is taken.
BOOST_AUTO_TEST_CASE(verify_option_reaches_the_methods_that_have_it) {
  const std::string dir = contactrom::test::temp_dir();
  const std::string db = dir + "/h8.h5";
  BOOST_REQUIRE(run_command(kExe + " offline --problem hertz --train 8 --threads 2 --out " + db).exit_code == 0);
  const std::string base = "verify --db " + db + " --method greedy,cpg --reference fom --limit 4 --threads 2 --json";
  const nlohmann::json plain = json_of(base);
  const nlohmann::json loose = json_of(base + " --option cpg_tolerance=0.5 --option estimate=false");
  const nlohmann::json empty = json_of(base + " --option init=empty");
  BOOST_TEST(loose["methods"]["cpg"]["dual_basis_size"].get<int>() < plain["methods"]["cpg"]["dual_basis_size"].get<int>());
  BOOST_TEST(loose["methods"]["greedy"]["mean_primal_error"].get<double>() ==
             plain["methods"]["greedy"]["mean_primal_error"].get<double>());
  BOOST_TEST(empty["methods"]["greedy"]["mean_iterations"].get<double>() >
             plain["methods"]["greedy"]["mean_iterations"].get<double>() + 1.0);
}
