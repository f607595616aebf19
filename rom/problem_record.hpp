#pragma once
/// \file problem_record.hpp
/// \brief The problem part of the files contactrom writes (snapshot databases and
/// reduced models): the problem file's text, the mesh, the contact rows and the
/// lifting terms — enough to rebuild the fom::Problem without the .toml and .geo
/// files and without gmsh. Layout in docs/database_format.md ("The problem"); read
/// and written by the library's HDF5 layer (not part of the installed headers).
#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include <contactrom/fom/mesh.hpp>
#include <contactrom/fom/problem.hpp>

namespace contactrom::rom {

/// \brief What a file stores of the problem it was built for.
struct ProblemRecord {
  std::string name;         ///< problem name (attribute `problem`)
  std::string fingerprint;  ///< Problem::fingerprint() (attribute `mesh_fingerprint`)
  std::vector<std::string> param_names;   ///< attribute `param_names` (comma-separated)
  /// Text of the problem file ("" for `rope`, which is built in).
  std::string text;
  std::shared_ptr<const fom::Mesh> mesh;  ///< the (refined) mesh; null for `rope`
  Eigen::MatrixXd contact_points;         ///< reference coordinates of the constraint rows (dim × n_c)
  Eigen::VectorXd contact_weights;        ///< tributary lengths of the constraint rows
  Eigen::MatrixXd lifting_terms;          ///< n_dofs × n_terms: the lifting basis L_k
};

/// \brief The record of `problem`.
ProblemRecord record_problem(const fom::Problem& problem);

/// \brief Rebuilds the problem from a record (problem-file text and mesh, no gmsh;
/// `rope` by name) and checks that it is the recorded discretisation (fingerprint,
/// numbers of dofs, constraints and parameters).
/// \param label how messages name the file, e.g. "database 'x.h5'"
/// \throws InputError naming `label`.
std::unique_ptr<fom::Problem> rebuild_problem(const ProblemRecord& record, const std::string& label);

}  // namespace contactrom::rom
