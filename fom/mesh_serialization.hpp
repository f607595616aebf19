#pragma once
/// \file mesh_serialization.hpp
/// \brief A fom::Mesh as bytes and back, for the pipe between load_mesh()'s gmsh
/// child process and the caller (same machine: native byte order, no versioning).
/// A private header of contactrom::fom.
#include <string>

#include <contactrom/fom/mesh.hpp>

namespace contactrom::fom {

/// \brief Every field of `mesh` as bytes.
std::string serialize_mesh(const Mesh& mesh);

/// \brief The mesh serialize_mesh() wrote.
/// \throws InputError "<where>: incomplete mesh data" if `bytes` ends early or
///   declares more than it holds.
Mesh deserialize_mesh(const std::string& bytes, const std::string& where);

}  // namespace contactrom::fom
