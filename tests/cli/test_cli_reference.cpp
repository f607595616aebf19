// docs/cli.md stays in step with the program: every subcommand that `contactrom --help`
// lists has a section `## \`name\`` in docs/cli.md, every option its `--help` prints
// appears in that section, and every online method and method setting of the
// `--option KEY=VALUE` list appears in the section "Online methods and their settings".
#define BOOST_TEST_MODULE cli_reference
#include <boost/test/unit_test.hpp>

#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/run_command.hpp"

using contactrom::test::run_command;
using contactrom::test::slurp;

namespace {

const std::string exe = CONTACTROM_EXE;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// The lines of `text` after the line `header` up to the next line that starts
/// without indentation (CLI11's sections: "Options:", "Subcommands:", ...).
std::vector<std::string> section_lines(const std::string& text, const std::string& header) {
  std::vector<std::string> out;
  bool inside = false;
  for (const std::string& line : lines_of(text)) {
    if (line == header) {
      inside = true;
      continue;
    }
    if (inside && !line.empty() && line[0] != ' ') break;
    if (inside && !line.empty()) out.push_back(line);
  }
  return out;
}

/// The subcommands `contactrom --help` lists.
std::vector<std::string> subcommands() {
  const auto r = run_command(exe + " --help");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  std::vector<std::string> names;
  const std::regex entry(R"(^  ([a-z][a-z-]*)\s)");
  for (const std::string& line : section_lines(r.out, "Subcommands:")) {
    std::smatch m;
    if (std::regex_search(line, m, entry)) names.push_back(m[1]);
  }
  return names;
}

/// The long options a subcommand's `--help` prints under "Options:" (help itself left out).
std::set<std::string> options_of(const std::string& command) {
  const auto r = run_command(exe + " " + command + " --help");
  BOOST_REQUIRE_MESSAGE(r.exit_code == 0, command + " --help exited with " + std::to_string(r.exit_code));
  std::set<std::string> options;
  const std::regex option(R"(^\s+(?:-[a-zA-Z],)?(--[a-z][a-z-]*))");
  for (const std::string& line : section_lines(r.out, "Options:")) {
    std::smatch m;
    if (std::regex_search(line, m, option) && m[1] != "--help") options.insert(m[1]);
  }
  return options;
}

/// The text of docs/cli.md from the heading `heading` to the next heading of the same level.
std::string doc_section(const std::string& doc, const std::string& heading) {
  const std::size_t begin = doc.find("\n" + heading + "\n");
  if (begin == std::string::npos) return "";
  const std::size_t level = heading.find(' ');
  const std::size_t end = doc.find("\n" + heading.substr(0, level + 1), begin + heading.size() + 1);
  return doc.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

const std::string& cli_doc() {
  static const std::string doc = slurp(std::string(CONTACTROM_SOURCE_DIR) + "/docs/cli.md");
  return doc;
}

/// The `--help` output of `command` and the section `heading` of docs/cli.md (both must exist).
std::pair<std::string, std::string> help_and_section(const std::string& command, const std::string& heading) {
  const auto r = run_command(exe + " " + command + " --help");
  BOOST_REQUIRE_EQUAL(r.exit_code, 0);
  std::string section = doc_section(cli_doc(), heading);
  BOOST_REQUIRE_MESSAGE(!section.empty(), "docs/cli.md has no section '" + heading + "'");
  return {r.out, section};
}

}  // namespace

BOOST_AUTO_TEST_CASE(every_subcommand_and_option_of_the_help_is_in_the_reference) {
  BOOST_REQUIRE_MESSAGE(!cli_doc().empty(), "docs/cli.md is missing or empty");
  const std::vector<std::string> names = subcommands();
  BOOST_TEST(names.size() >= 10u, "contactrom --help lists " << names.size() << " subcommands");
  for (const std::string& name : names) {
    const std::string section = doc_section(cli_doc(), "## `" + name + "`");
    BOOST_TEST(!section.empty(), "docs/cli.md has no section '## `" << name << "`'");
    if (section.empty()) continue;
    for (const std::string& option : options_of(name))
      BOOST_TEST(section.find("`" + option) != std::string::npos,
                 "docs/cli.md, section " << name << ": option " << option << " is not documented");
  }
}

BOOST_AUTO_TEST_CASE(every_online_method_and_setting_of_the_help_is_in_the_reference) {
  const auto [help, section] = help_and_section("online", "## Online methods and their settings");
  const std::regex method(R"(^  ([a-z][a-z-]*): )"), key(R"(^    ([a-z_]+): )");
  int methods = 0, keys = 0;
  for (const std::string& line : section_lines(help, "Online methods and their options (--option KEY=VALUE):")) {
    std::smatch m;
    if (std::regex_search(line, m, method)) {
      ++methods;
      BOOST_TEST(section.find("### `" + m[1].str() + "`") != std::string::npos,
                 "docs/cli.md: method " << m[1] << " has no heading");
    } else if (std::regex_search(line, m, key)) {
      ++keys;
      BOOST_TEST(section.find("`" + m[1].str() + "`") != std::string::npos,
                 "docs/cli.md: method setting " << m[1] << " is not documented");
    }
  }
  BOOST_TEST(methods >= 4, "online --help lists " << methods << " methods");
  BOOST_TEST(keys >= 20, "online --help lists " << keys << " method settings");
}

namespace {

/// The default column of the row of `key` in the tables of `text` ("" if none),
/// without backticks and with "−" written "-".
std::string documented_default(const std::string& text, const std::string& key) {
  const std::string row = "\n| `" + key + "` | ";
  const std::size_t at = text.find(row);
  if (at == std::string::npos) return "";
  const std::size_t begin = at + row.size();
  std::string cell = text.substr(begin, text.find(" |", begin) - begin);
  std::string out;
  for (std::size_t i = 0; i < cell.size(); ++i) {
    if (cell[i] == '`') continue;
    if (cell.compare(i, 3, "\u2212") == 0) {
      out += '-';
      i += 2;
      continue;
    }
    out += cell[i];
  }
  return out;
}

/// Whether the documented default `doc` ("-1 (tau = delta)", "1e-3", "svd") states `value`.
bool states(const std::string& doc, const std::string& value) {
  const std::string first = doc.substr(0, doc.find_first_of(" :("));
  if (first == value) return true;
  try {
    std::size_t a = 0, b = 0;
    const double x = std::stod(first, &a), y = std::stod(value, &b);
    return a == first.size() && b == value.size() && x == y;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

BOOST_AUTO_TEST_CASE(every_documented_setting_default_is_the_programs) {
  // The default of every setting in docs/cli.md is the one --help prints (read from
  // the options structs): looked up in the method's own table, then in the shared
  // tables above the methods, then in the method its text refers to ("as for `cpg`").
  const auto [help, section] = help_and_section("online", "## Online methods and their settings");
  const std::string shared = section.substr(0, section.find("\n### "));
  const std::regex method(R"(^  ([a-z][a-z-]*): )"), key(R"(^    ([a-z_]+): .*; default (.*)\]$)"),
      refers(R"((?:as for|settings of)\s+`([a-z-]+)`)");
  std::string name, own, referred;
  int checked = 0;
  for (const std::string& line : section_lines(help, "Online methods and their options (--option KEY=VALUE):")) {
    std::smatch m;
    if (std::regex_search(line, m, method)) {
      name = m[1];
      own = doc_section(section, "### `" + name + "`");
      referred.clear();
      if (std::regex_search(own, m, refers)) referred = doc_section(section, "### `" + m[1].str() + "`");
    } else if (std::regex_search(line, m, key)) {
      std::string doc = documented_default(own, m[1]);
      if (doc.empty()) doc = documented_default(shared, m[1]);
      if (doc.empty()) doc = documented_default(referred, m[1]);
      BOOST_TEST(!doc.empty(), "docs/cli.md: no default of " << name << " " << m[1]);
      if (doc.empty()) continue;
      ++checked;
      BOOST_TEST(states(doc, m[2]), "docs/cli.md: " << name << " " << m[1] << " default '" << doc
                                                    << "', the program's is " << m[2]);
    }
  }
  BOOST_TEST(checked >= 60, checked << " defaults checked");
}

BOOST_AUTO_TEST_CASE(every_documented_adaptive_default_is_the_programs) {
  // The settings of `offline --adaptive` (one declaration: rom::adaptive_option_table())
  // print their defaults in `offline --help`; the table of docs/cli.md states the same.
  const auto [help, section] = help_and_section("offline", "### `offline --adaptive`");
  // CLI11 prints an option's name, then (on the same line or the next) its help.
  const std::regex name(R"(^\s+(--[a-z][a-z-]*)\s)"), setting(R"(adaptive: .*; (default ([^)]*)|required for a new run)\)\s*$)");
  int checked = 0;
  std::string flag;
  for (const std::string& line : section_lines(help, "Options:")) {
    std::smatch m;
    if (std::regex_search(line, m, name)) flag = m[1];
    if (!std::regex_search(line, m, setting)) continue;
    const std::string doc = documented_default(section, flag);
    BOOST_TEST(!doc.empty(), "docs/cli.md: no row of " << flag << " in the table of offline --adaptive");
    ++checked;
    if (!m[2].matched) {
      BOOST_TEST(doc.rfind("required", 0) == 0, "docs/cli.md: " << flag << " default '" << doc << "', the program requires it");
      continue;
    }
    BOOST_TEST(states(doc, m[2]), "docs/cli.md: " << flag << " default '" << doc << "', the program's is " << m[2]);
  }
  BOOST_TEST(checked == 8, checked << " adaptive settings found in offline --help");
}

// Test sources are listed by name in tests/CMakeLists.txt (no globs): a file that is
// not listed would never run. Every tests/<folder>/test_*.cpp must appear there as
// <folder>/<stem>, every tests/python/test_*.py as its stem.
BOOST_AUTO_TEST_CASE(every_test_source_is_listed_in_the_test_build) {
  namespace fs = std::filesystem;
  const fs::path tests = fs::path(CONTACTROM_SOURCE_DIR) / "tests";
  const std::string listing = slurp((tests / "CMakeLists.txt").string());
  BOOST_REQUIRE(!listing.empty());
  const std::regex word_end("[A-Za-z0-9_]");
  const auto listed = [&](const std::string& name) {
    for (size_t at = listing.find(name); at != std::string::npos; at = listing.find(name, at + 1)) {
      const size_t end = at + name.size();
      const bool starts = at == 0 || !std::regex_match(std::string(1, listing[at - 1]), word_end);
      const bool ends = end == listing.size() || !std::regex_match(std::string(1, listing[end]), word_end);
      if (starts && ends) return true;
    }
    return false;
  };
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(tests)) {
    const fs::path& p = entry.path();
    const std::string stem = p.stem().string(), folder = p.parent_path().filename().string();
    if (!entry.is_regular_file() || stem.rfind("test_", 0) != 0) continue;
    if (p.extension() == ".cpp" && p.parent_path().parent_path() == tests) {
      ++files;
      BOOST_TEST(listed(folder + "/" + stem), "tests/" << folder << "/" << stem << ".cpp is not in tests/CMakeLists.txt");
    } else if (p.extension() == ".py" && folder == "python") {
      ++files;
      BOOST_TEST(listed(stem), "tests/python/" << stem << ".py is not in tests/CMakeLists.txt");
    }
  }
  BOOST_TEST(files > 50);  // the walk found the test sources at all
}
