#pragma once
/// \file mesh.hpp
/// \brief 2D bilinear-quad meshes read from gmsh `.geo`/`.msh` files through the
/// gmsh API. Boundary groups (Dirichlet faces, slave and master surfaces) come
/// from the file's physical groups, never from coordinates guessed in code.
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace contactrom::fom {

/// \brief A 2D Q1 mesh with named node/segment groups.
///
/// Node numbering is contiguous 0..num_nodes()-1; two bodies that touch keep
/// distinct nodes. Quads are counter-clockwise.
struct Mesh {
  Eigen::Matrix2Xd nodes;                     ///< reference coordinates, 2 x n
  std::vector<std::array<int, 4>> quads;      ///< node ids, counter-clockwise
  std::vector<int> quad_body;                 ///< body index (0-based) of each quad
  std::vector<std::string> body_names;        ///< physical surface names, by body index
  /// Physical curve name -> its line elements (node pairs), ordered as a chain
  /// from one end of the curve to the other (consecutive segments share a node).
  std::map<std::string, std::vector<std::array<int, 2>>> segments;
  /// Physical curve name -> its node ids, in chain order (one more than segments
  /// for an open curve).
  std::map<std::string, std::vector<int>> curve_nodes;

  int num_nodes() const { return static_cast<int>(nodes.cols()); }
  int num_quads() const { return static_cast<int>(quads.size()); }
  /// Node ids of a named curve; throws InputError naming the group if absent.
  const std::vector<int>& group_nodes(const std::string& name) const;
  /// Segments of a named curve; throws InputError naming the group if absent.
  const std::vector<std::array<int, 2>>& group_segments(const std::string& name) const;
  /// 64-bit FNV-1a hash of coordinates (rounded to 1e-12) and connectivity, as
  /// 16 hex digits; databases store it to refuse a mesh they were not built on.
  std::string fingerprint() const;
};

/// \brief Meshes a `.geo` file (or reads a `.msh`) with the gmsh API and returns
/// the Q1 mesh. Only quadrilateral surface elements are accepted.
/// \param path file to read
/// \throws InputError if the file is missing, unreadable, produces non-quad
///   elements, or lacks physical groups.
Mesh load_mesh(const std::string& path);

/// \brief The folder holding the project's `.geo` files: `$CONTACTROM_MESH_DIR`
/// if set, else the source tree's `meshes/` recorded at configure time.
std::string mesh_directory();

}  // namespace contactrom::fom
