#pragma once
/// \file mesh.hpp
/// \brief Meshes read from gmsh `.geo`/`.msh` files through the gmsh API: 2D
/// bilinear quads, or 3D linear tetrahedra and trilinear hexahedra. Boundary groups
/// (Dirichlet faces, slave and master surfaces) come from the file's physical
/// groups, never from coordinates guessed in code.
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <contactrom/core/parallel_for.hpp>

namespace contactrom::fom {

/// \brief A 2D Q1 mesh with named node/segment groups, or a 3D mesh of tetrahedra
/// and hexahedra with named node/facet groups (`dim` says which).
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
///
/// In 3D (`dim == 3`) the bodies are physical volumes, their elements `cells`
/// (a tetrahedron has positive volume, a hexahedron a positive Jacobian at its
/// corners, both in gmsh's node order) and the boundary groups physical surfaces,
/// whose facets (`faces`, triangles or quads) are numbered counter-clockwise seen
/// from outside their body, so that the right-hand normal
/// \f$ (x_1 - x_0) \times (x_2 - x_0) \f$ of a triangle (of the quad's diagonals
/// \f$ (x_2 - x_0) \times (x_3 - x_1) \f$) points out of the body. Physical
/// surfaces, curves and points all give node groups (`curve_nodes`, ascending ids in
/// 3D); `quads` and `segments` are empty.
struct Mesh {
  int dim = 2;                                ///< spatial dimension: 2 (quads) or 3 (tetrahedra, hexahedra)
  Eigen::MatrixXd nodes;                      ///< reference coordinates, dim x n
  std::vector<std::array<int, 4>> quads;      ///< 2D: node ids, counter-clockwise
  std::vector<int> quad_body;                 ///< 2D: body index (0-based) of each quad
  /// 3D: node ids of each volume element in gmsh order: a tetrahedron's 4 then −1s,
  /// a hexahedron's 8 (bottom face 0-3, top face 4-7 above it).
  std::vector<std::array<int, 8>> cells;
  std::vector<int> cell_body;                 ///< 3D: body index (0-based) of each cell
  /// 3D: physical surface name -> its facets (triangle: 3 ids and −1; quad: 4 ids),
  /// counter-clockwise seen from outside the body they bound.
  std::map<std::string, std::vector<std::array<int, 4>>> faces;
  std::vector<std::string> body_names;        ///< physical surface (2D) or volume (3D) names, by body index
  /// Physical curve name -> its line elements (node pairs), ordered as a chain
  /// from one end of the curve to the other (consecutive segments share a node),
  /// running with the body of its first segment on the left.
  std::map<std::string, std::vector<std::array<int, 2>>> segments;
  /// Physical curve name -> its node ids, in chain order (one more than segments
  /// for an open curve, as many as segments for a closed one).
  std::map<std::string, std::vector<int>> curve_nodes;

  int num_nodes() const { return static_cast<int>(nodes.cols()); }
  int num_quads() const { return static_cast<int>(quads.size()); }
  int num_cells() const { return static_cast<int>(cells.size()); }
  /// Elements of the mesh: quads in 2D, cells in 3D.
  int num_elements() const { return dim == 3 ? num_cells() : num_quads(); }
  /// Body index of element e (quads in 2D, cells in 3D).
  int element_body(int e) const { return dim == 3 ? cell_body[static_cast<size_t>(e)] : quad_body[static_cast<size_t>(e)]; }
  /// Node ids of element e: its 4 quad corners, or a cell's 4 or 8 nodes.
  std::vector<int> element_nodes(int e) const;
  /// Nodes of a 3D cell (4: tetrahedron, 8: hexahedron).
  static int cell_size(const std::array<int, 8>& cell) { return cell[4] < 0 ? 4 : 8; }
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
  /// every quad in four, every tetrahedron and hexahedron in eight
  /// (`gmsh::model::mesh::refine()`), so node and element counts grow about fourfold
  /// (2D) or eightfold (3D) per level and every boundary division doubles. New boundary nodes
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
  /// Called from the calling thread about every 0.1 s while gmsh runs, with (0, 1);
  /// an exception it throws (e.g. the Python module's Ctrl-C check) stops gmsh: its
  /// process is killed and reaped, and the exception propagates. Optional.
  ProgressCallback progress;
};

/// \brief Meshes a `.geo` file (or reads a `.msh`) with the gmsh API and returns
/// the mesh. A model with physical volumes is 3D (meshed with
/// `gmsh::model::mesh::generate(3)`; 4-node tetrahedra and 8-node hexahedra, mixed
/// as gmsh gives them; boundary groups are the physical surfaces, of 3-node triangles
/// and 4-node quads that are faces of the volume elements); otherwise it is 2D and
/// only quadrilateral surface elements are accepted.
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
