// Tests of fom/gmsh_api: the gmsh library is opened by the first mesh a process
// makes, not when a program linking contactrom starts; commands that only read a
// database or a reduced model run without it, and a gmsh library that cannot be
// opened is an error naming it (exit code 1, not an input error).
#define BOOST_TEST_MODULE fom_gmsh_on_demand
#include <boost/test/unit_test.hpp>

#include <fstream>
#include <string>

#include <contactrom/fom/mesh.hpp>

#include "common/run_command.hpp"

namespace {

bool gmsh_mapped() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);)
    if (line.find("libgmsh") != std::string::npos) return true;
  return false;
}

const std::string kExe = CONTACTROM_EXE;
// The shim refuses to open gmsh; AddressSanitizer builds accept a library preloaded
// before their runtime.
const std::string kNoGmsh = std::string("ASAN_OPTIONS=verify_asan_link_order=0 LD_PRELOAD=") +
                            CONTACTROM_REFUSE_GMSH + " ";

}  // namespace

BOOST_AUTO_TEST_CASE(gmsh_is_opened_by_the_first_mesh_not_at_start) {
  BOOST_TEST(!gmsh_mapped());  // this program links contactrom::fom
  const std::string mesh = std::string(CONTACTROM_SOURCE_DIR) + "/meshes/hertz.geo";
  const contactrom::fom::Mesh first = contactrom::fom::load_mesh(mesh);
  BOOST_TEST(gmsh_mapped());
  const contactrom::fom::Mesh second = contactrom::fom::load_mesh(mesh);  // the same library, a new child
  BOOST_TEST(first.num_nodes() > 0);
  BOOST_TEST(second.num_nodes() == first.num_nodes());
}

BOOST_AUTO_TEST_CASE(database_commands_run_without_gmsh_and_meshing_says_it_is_missing) {
  const std::string dir = contactrom::test::temp_dir();
  const auto offline = contactrom::test::run_command(kExe + " offline --problem hertz --train 4 --threads 1 --out " +
                                                     dir + "/h4.h5");
  BOOST_TEST_REQUIRE(offline.exit_code == 0, offline.err);

  // Without a gmsh library: a database and a reduced model are all these need.
  for (const std::string& args : {"online --db " + dir + "/h4.h5 --param 0.1",
                                  "reduce --db " + dir + "/h4.h5 --out " + dir + "/h4_rom.h5",
                                  "query --rom " + dir + "/h4_rom.h5 --param 0.1"}) {
    const auto r = contactrom::test::run_command(kNoGmsh + kExe + " " + args);
    BOOST_TEST(r.exit_code == 0, args << ": " << r.err);
  }

  // A command that meshes: one line naming the library, exit code 1, no output file.
  const auto fom = contactrom::test::run_command(kNoGmsh + kExe + " fom --problem hertz --param 0.1");
  BOOST_TEST(fom.exit_code == 1);
  BOOST_TEST(fom.err.find("the gmsh library could not be loaded (tried ") != std::string::npos, fom.err);
  BOOST_TEST(fom.out.empty(), fom.out);
  const auto off = contactrom::test::run_command(kNoGmsh + kExe + " offline --problem hertz --train 2 --out " + dir +
                                                 "/none.h5");
  BOOST_TEST(off.exit_code == 1, off.err);
  BOOST_TEST(!std::ifstream(dir + "/none.h5").good());
}
