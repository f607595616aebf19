#pragma once
/// \file problem_file.hpp
/// \brief Problem files: a TOML file next to a gmsh mesh describes a contact
/// problem as data (bodies, materials, Dirichlet and traction data affine in the
/// parameters, contact pairs, parameters, sampling plans). The format and every
/// key are documented in docs/problems.md.
///
/// Every error names the file, the line and the key, e.g.
/// "problem file 'clamp.toml', line 12, key 'bodies[1].young': expression 'E*d' ...".
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <contactrom/fom/mesh.hpp>
#include <contactrom/fom/parameter_space.hpp>
#include <contactrom/fom/sampling.hpp>

namespace contactrom::fom {

/// Where a value came from, for error messages.
struct SourceLocation {
  int line = 0;     ///< 1-based line in the problem file (0: unknown)
  std::string key;  ///< e.g. "bodies[1].young"
};

/// \brief One body: a physical surface (2D) or volume (3D) of the mesh and its material.
struct BodySpec {
  std::string group;
  AffineExpression young;  ///< Young's modulus, affine in the parameters (> 0 over the box)
  double poisson = 0.3;    ///< Poisson's ratio, in (−1, 0.5)
  SourceLocation where;
};

/// \brief Prescribed displacement on a physical curve or point (3D: surface, curve
/// or point); a component without a value is free. 2D uses the first two components.
struct DirichletSpec {
  std::string group;
  std::array<std::optional<AffineExpression>, 3> displacement;
  SourceLocation where;
};

/// \brief Force per unit length on a physical curve (global x, y components); in 3D
/// force per unit area on a physical surface (x, y, z).
struct TractionSpec {
  std::string group;
  std::array<AffineExpression, 3> traction;  ///< 2D: the third is unused
  SourceLocation where;
};

/// \brief A contact pair: slave curve (its nodes carry the pressure) against master
/// curve; in 3D slave and master physical surfaces.
struct ContactPairSpec {
  std::string slave, master;
  SourceLocation where;         ///< of its `slave` key
  SourceLocation where_master;  ///< of its `master` key
  /// Where the group `name` (its slave or its master) was given.
  const SourceLocation& where_of(const std::string& name) const { return &name == &master ? where_master : where; }
};

/// \brief Settings of the reduced models that depend on the problem (`[rom]`).
struct RomSettings {
  /// Whether the feasible set is convex and parameter-independent, so that the
  /// convex-hull ROM applies (default false; the hull method refuses otherwise).
  bool convex_hull = false;
  /// Default CPG tolerance for this problem (0: the method's own default).
  double cpg_tolerance = 0.0;
  /// Tolerances of the row-by-row contact residuals a reduced answer must meet to
  /// report `success` (fom/contact_residuals.hpp; 0: the defaults of
  /// fom::ContactTolerances): penetration and separation under pressure in units of
  /// the displacement scale U, negative pressure relative to the largest pressure.
  double penetration_tolerance = 0.0;
  double complementarity_tolerance = 0.0;
  double negative_pressure_tolerance = 0.0;
};

/// \brief A problem file read into plain data; see the file comment.
struct ProblemDefinition {
  std::string name;                      ///< `[problem] name`
  std::string path;                      ///< the file it was read from ("" if from text)
  std::string text;                      ///< the file's text (stored in databases)
  std::string mesh;                      ///< mesh path, resolved against the file's folder
  SourceLocation mesh_where;             ///< where `mesh` was given
  bool plane_stress = false;             ///< `formulation = "plane_stress"` (unit thickness)
  int dimension = 2;                     ///< 3 for `formulation = "3d"` (a mesh of physical volumes), else 2
  SourceLocation formulation_where;      ///< where `formulation` is (or the [problem] table), for messages
  int refine = 0;                        ///< uniform refinements of the mesh (each splits a quad in four, a cell in eight)
  long long max_mesh_nodes = MeshOptions{}.max_nodes;   ///< `[problem] max_mesh_nodes` (MeshOptions::max_nodes)
  double mesh_time_limit = MeshOptions{}.time_limit_s;  ///< `[problem] mesh_time_limit` in s (MeshOptions::time_limit_s)
  double displacement_scale = 0.0;       ///< U for relative residuals; 0: max |Dirichlet value| over the box
  std::string builtin;                   ///< non-empty for problems written in C++ ("rope")
  ParameterSpace parameters;
  std::vector<BodySpec> bodies;
  std::vector<DirichletSpec> dirichlet;
  std::vector<TractionSpec> traction;
  std::vector<ContactPairSpec> contact;
  SamplingPlan training, validation;
  RomSettings rom;

  /// "problem file 'P', line L, key 'K'" for messages.
  std::string where(const SourceLocation& at) const;
};

/// \brief Reads and checks a problem file (syntax, keys, types, ranges, affine
/// expressions). Groups are checked against the mesh when the problem is built.
/// \throws InputError naming the file, line and key.
ProblemDefinition read_problem_file(const std::string& path);

/// \brief Same, from the text of a problem file; `path` is used for messages and
/// to resolve the mesh path.
ProblemDefinition parse_problem_text(const std::string& text, const std::string& path);

/// \brief Folder of the shipped problem files: `$CONTACTROM_PROBLEM_DIR` if set,
/// else `share/contactrom/problems` of the build tree or install prefix
/// (fom/data_directory.hpp).
std::string problem_directory();

/// \brief Resolves `--problem`: a path (contains '/' or ends in .toml) is used as
/// is, a name N becomes problem_directory()/N.toml.
/// \throws InputError if there is no such file (listing the shipped names).
std::string find_problem_file(const std::string& name_or_path);

/// Names of the shipped problems (the .toml files of problem_directory(), and "rope").
std::vector<std::string> shipped_problem_names();

}  // namespace contactrom::fom
