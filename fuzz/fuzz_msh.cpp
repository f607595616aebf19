// libFuzzer target: the .msh reader (fom/gmsh_reader.cpp, with load_mesh's file check of fom/mesh.cpp). The input is written to a .msh
// file and read as load_mesh reads it, but in this process (load_mesh forks a child
// for gmsh, whose coverage libFuzzer could not see): the header check that keeps a
// non-mesh from reaching gmsh's .geo parser, gmsh's MSH reader, and contactrom's
// checks of the mesh it returns (quads, physical groups, chains). Any input must give
// a mesh or throw InputError; a crash inside libgmsh is attributed to gmsh by
// tools/fuzz.sh.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

// load_mesh's file check lives in an anonymous namespace of fom/mesh.cpp: this
// target is that translation unit and the reader's plus the entry point (it links
// contactrom::core, not contactrom::fom, so they are compiled once, here; gmsh_api.cpp
// opens gmsh as the library does).
#include "../fom/gmsh_api.cpp"
#include "../fom/gmsh_reader.cpp"
#include "../fom/mesh.cpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/contactrom_fuzz_msh_" + std::to_string(::getpid()) + ".msh";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  contactrom::fom::MeshOptions options;
  options.max_nodes = 20000;  // small meshes only: the time goes to parsing, not to allocation
  try {
    contactrom::fom::check_mesh_file(path);
    const contactrom::fom::Mesh mesh = contactrom::fom::mesh_with_gmsh(path, options);
    (void)mesh.fingerprint();
  } catch (const contactrom::InputError&) {
  }
  return 0;
}
