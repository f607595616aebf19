#pragma once
/// \file gmsh_reader.hpp
/// \brief A mesh read with the gmsh API in the calling process: open the file,
/// mesh a `.geo`, refine, and turn gmsh's model into a fom::Mesh with the checks
/// load_mesh() documents (element types, orientation, chains, groups). load_mesh()
/// calls it in a child process (fom/child_process.hpp); a private header of
/// contactrom::fom.
#include <string>

#include <contactrom/fom/mesh.hpp>

namespace contactrom::fom {

/// \brief Reads, meshes and refines `path` with gmsh in this process. Not
/// thread-safe (gmsh keeps its model in global state); each call starts and ends
/// its own gmsh session.
/// \throws InputError naming the file (see load_mesh()).
Mesh mesh_with_gmsh(const std::string& path, const MeshOptions& options);

/// \brief The extension of `path` in lower case, with its dot (".geo").
std::string lower_extension(const std::string& path);

}  // namespace contactrom::fom
