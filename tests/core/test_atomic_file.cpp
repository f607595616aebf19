// core/atomic_file.hpp: a file is written completely or not at all. A writer that
// throws half-way leaves neither the target nor a temporary file; a set of files of
// which one fails leaves none of them (and keeps an existing target unchanged);
// refused targets (a device, a folder, a symbolic link, a missing folder, an empty
// name) are named in one line and nothing is written.
#define BOOST_TEST_MODULE core_atomic_file
#include <unistd.h>

#include <boost/test/unit_test.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/input_error.hpp"
#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>

namespace fs = std::filesystem;
using contactrom::test::input_error_of;

namespace {


/// A fresh, empty folder under the system's temporary folder, removed at the end.
struct Folder {
  fs::path path = fs::temp_directory_path() / ("contactrom_atomic_" + std::to_string(::getpid()));
  Folder() {
    fs::remove_all(path);
    fs::create_directory(path);
  }
  ~Folder() { fs::remove_all(path); }
  int entries() const { return static_cast<int>(std::distance(fs::directory_iterator(path), fs::directory_iterator())); }
  std::string read(const std::string& name) const {
    std::ifstream in(path / name);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
};

}  // namespace

BOOST_AUTO_TEST_CASE(a_complete_write_publishes_the_whole_content) {
  const Folder dir;
  const std::string target = (dir.path / "out.csv").string();
  contactrom::write_file_atomically(target, [](std::ostream& out) { out << "a,b\n1,2\n"; });
  BOOST_TEST(dir.read("out.csv") == "a,b\n1,2\n");
  BOOST_TEST(dir.entries() == 1);  // no temporary file left
}

BOOST_AUTO_TEST_CASE(a_writer_that_throws_leaves_nothing) {
  const Folder dir;
  const std::string target = (dir.path / "out.csv").string();
  BOOST_CHECK_THROW(contactrom::write_file_atomically(target,
                                                      [](std::ostream& out) {
                                                        out << "half of the content";
                                                        throw std::runtime_error("interrupted");
                                                      }),
                    std::runtime_error);
  BOOST_TEST(dir.entries() == 0);
}

BOOST_AUTO_TEST_CASE(a_failing_file_of_a_set_leaves_none_and_keeps_the_old_target) {
  const Folder dir;
  const std::string first = (dir.path / "a.vtu").string(), second = (dir.path / "a.csv").string();
  contactrom::write_file_atomically(second, [](std::ostream& out) { out << "old"; });
  BOOST_CHECK_THROW(contactrom::write_files_atomically(
                        {{first, [](std::ostream& out) { out << "new a"; }},
                         {second, [](std::ostream&) { throw std::runtime_error("disk full"); }}}),
                    std::runtime_error);
  BOOST_TEST(!fs::exists(first));
  BOOST_TEST(dir.read("a.csv") == "old");
  BOOST_TEST(dir.entries() == 1);
}

BOOST_AUTO_TEST_CASE(refused_targets_are_named_and_nothing_is_written) {
  const Folder dir;
  // check_output_path only inspects the target; nothing is written to /dev/null.
  const std::string m = input_error_of([] { contactrom::check_output_path("/dev/null"); });
  BOOST_TEST(m.find("'/dev/null': it is a device, pipe or socket") != std::string::npos, m);
  BOOST_TEST(input_error_of([] { contactrom::check_output_path(""); }) == "output file name is empty; expected a file name");
  BOOST_TEST(input_error_of([&] { contactrom::check_output_path(dir.path.string()); }).find("is a folder") !=
             std::string::npos);
  const std::string missing = (dir.path / "no_such_folder" / "out.csv").string();
  const std::string m_missing =
      input_error_of([&] { contactrom::write_file_atomically(missing, [](std::ostream& out) { out << "x"; }); });
  BOOST_TEST(m_missing.find("no_such_folder") != std::string::npos, m_missing);
  BOOST_TEST(m_missing.find('\n') == std::string::npos);
  // A symbolic link is refused, and its target is left as it was.
  const fs::path real = dir.path / "real.txt", link = dir.path / "link.txt";
  contactrom::write_file_atomically(real.string(), [](std::ostream& out) { out << "kept"; });
  fs::create_symlink(real, link);
  const std::string m_link =
      input_error_of([&] { contactrom::write_file_atomically(link.string(), [](std::ostream& out) { out << "x"; }); });
  BOOST_TEST(!m_link.empty());
  BOOST_TEST(dir.read("real.txt") == "kept");
  BOOST_TEST(fs::is_symlink(link));
  BOOST_TEST(dir.entries() == 2);
}
