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
/// Node numbering is contiguous 0..num_nodes()-1, body after body (in
/// `body_names` order), and within a body by ascending gmsh node tag; it is
/// deterministic for a given file and gmsh version. Two bodies that touch keep
/// distinct nodes. Quads are counter-clockwise (positive signed area).
///
/// Curve chains are oriented with their body on the LEFT, i.e. they run
/// counter-clockwise around the body that owns them, so for a segment with unit
/// tangent \f$ t = (x_b - x_a)/|x_b - x_a| \f$ the outward normal of the body is
/// \f$ n = (t_y, -t_x) \f$. (The body is the one whose quad has the first
/// segment as an edge; an open chain therefore starts at the end that keeps the
/// body on the left; a closed chain starts at its smallest node id.)
struct Mesh {
  Eigen::Matrix2Xd nodes;                     ///< reference coordinates, 2 x n
  std::vector<std::array<int, 4>> quads;      ///< node ids, counter-clockwise
  std::vector<int> quad_body;                 ///< body index (0-based) of each quad
  std::vector<std::string> body_names;        ///< physical surface names, by body index
  /// Physical curve name -> its line elements (node pairs), ordered as a chain
  /// from one end of the curve to the other (consecutive segments share a node).
  std::map<std::string, std::vector<std::array<int, 2>>> segments;
  /// Physical curve name -> its node ids, in chain order (one more than segments
  /// for an open curve, as many as segments for a closed one).
  std::map<std::string, std::vector<int>> curve_nodes;

  int num_nodes() const { return static_cast<int>(nodes.cols()); }
  int num_quads() const { return static_cast<int>(quads.size()); }
  /// Node ids of a named curve; throws InputError naming the group if absent.
  const std::vector<int>& group_nodes(const std::string& name) const;
  /// Segments of a named curve; throws InputError naming the group if absent.
  const std::vector<std::array<int, 2>>& group_segments(const std::string& name) const;
  /// 64-bit FNV-1a hash of coordinates (rounded to 1e-12) and connectivity
  /// (quads, their bodies, body names, curve names and chains), as 16 lower-case
  /// hex digits; databases store it to refuse a mesh they were not built on.
  std::string fingerprint() const;
};

/// \brief Options of load_mesh (documented defaults).
struct MeshOptions {
  /// Uniform refinement levels applied after meshing (or reading): each level splits
  /// every quad in four (`gmsh::model::mesh::refine()`), so node and quad counts grow
  /// about fourfold per level and every boundary division doubles. New boundary nodes
  /// of a `.geo` model are placed on the geometry's curves (arcs stay round); a `.msh`
  /// file has no geometry, so its new boundary nodes are segment midpoints. Physical
  /// groups keep their names and stay chains. Range 0..kMaxRefine; default 0.
  int refine = 0;
  /// Largest accepted `refine` (8 levels multiply the node count by about 65536).
  static constexpr int kMaxRefine = 8;
  /// Largest accepted number of nodes of the mesh, after refinement (problem files:
  /// `[problem] max_mesh_nodes`). A larger mesh is an InputError naming its count and
  /// the limit; a refinement that would exceed it is refused before it runs, from the
  /// element count. Must be >= 1; default 1,000,000 (about 2 M dofs).
  long long max_nodes = 1000000;
  /// Wall-clock limit of gmsh's reading, meshing and refinement, in seconds (problem
  /// files: `[problem] mesh_time_limit`); gmsh is stopped and an InputError names the
  /// file when it runs longer (e.g. a `.geo` with a NaN radius loops forever). Must be
  /// > 0; default 600.
  double time_limit_s = 600.0;
};

/// \brief Meshes a `.geo` file (or reads a `.msh`) with the gmsh API and returns
/// the Q1 mesh. Only quadrilateral surface elements are accepted.
///
/// Bodies are the physical surfaces, in ascending physical tag order; named
/// boundaries are the physical curves (each must be one chain of 2-node lines
/// whose segments are quad edges). Unnamed groups are named after their tag.
/// Elements outside physical surfaces are ignored. A `.geo` file is meshed with
/// `gmsh::model::mesh::generate(2)` and the options set in the file; a `.msh`
/// file is read as is.
///
/// A `.geo` file is a gmsh program, not data: it can run shell commands
/// (`System`), loop, or end the process (`Exit`). Read only trusted `.geo` files;
/// a `.msh` file is data. gmsh runs in a child process (fork) that sends the mesh
/// back: a `.geo` that ends the process (`Exit`), a gmsh crash (e.g.
/// `Mesh.Algorithm = 8` in gmsh 4.8.4) or gmsh running past `time_limit_s` is an
/// InputError naming the file, and the caller's process, its exit handlers and its
/// stdout are untouched (the child's stdout goes to /dev/null).
///
/// Each call starts its own gmsh (no config files, nothing printed), so it may be
/// called any number of times, also while the caller holds a gmsh session of its
/// own. Keep it out of hot loops: a call costs about 0.01-0.1 s.
/// \param path file to read
/// \param options refinement (see MeshOptions)
/// \throws InputError if `options.refine` is outside 0..MeshOptions::kMaxRefine, if the mesh has more than
///   `options.max_nodes` nodes, if gmsh exits, crashes or runs past `options.time_limit_s`, if the file is missing ("mesh file 'X' not found"),
///   unreadable, rejected by gmsh (syntax error, meshing error; the message names
///   the file and quotes gmsh), produces non-quad elements, lacks physical
///   groups, or has a curve group that is not a single chain.
Mesh load_mesh(const std::string& path, const MeshOptions& options = {});

/// \brief The folder holding the project's `.geo` files: `$CONTACTROM_MESH_DIR`
/// if set, else `share/contactrom/meshes` of the build tree or install prefix
/// (fom/data_directory.hpp).
std::string mesh_directory();

}  // namespace contactrom::fom
