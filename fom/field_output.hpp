#pragma once
/// \file field_output.hpp
/// \brief Field output for ParaView and plotting: VTU (XML UnstructuredGrid,
/// ASCII) with displacement, stress and contact pressure, and a CSV of the
/// contact surface (x, y, gap, pressure, u_x, u_y; in 3D x, y, z, gap, pressure,
/// u_x, u_y, u_z). Files are written atomically.
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/fom/problem.hpp>

namespace contactrom::fom {

/// \brief Writes `path` (.vtu): points in the reference configuration, point data
/// `displacement` (3 components) and `contact_pressure` (on constrained nodes),
/// cell data `stress` (2D: σxx, σyy, σxy, σzz; 3D: σxx, σyy, σzz, σxy, σyz, σxz),
/// `von_mises` and `body`; cells are quads (2D), tetrahedra and hexahedra (3D).
/// The 1D rope is written as line cells; its transverse deflection is the y
/// component of `displacement`.
void write_vtu(const std::string& path, const Problem& problem, const Param& mu, const Eigen::VectorXd& u,
               const Eigen::VectorXd& lambda);

/// \brief Writes the contact surface CSV: columns `x,y,gap,pressure,u_x,u_y` (3D:
/// `x,y,z,gap,pressure,u_x,u_y,u_z`) (one
/// row per constraint: reference coordinates, gap with the pairing recomputed from
/// u, pressure, the node's displacement; rope: y = 0 and u_y is the deflection).
void write_surface_csv(const std::string& path, const Problem& problem, const Eigen::VectorXd& u,
                       const Eigen::VectorXd& lambda);

/// \brief Writes `dir`/`stem`.vtu and `dir`/`stem`_surface.csv as one set: both
/// are complete before either is published, and a failure leaves neither (nor
/// `dir`, if this call created it).
/// \throws InputError naming the folder or file and the reason.
void write_fields(const std::string& dir, const std::string& stem, const Problem& problem, const Param& mu,
                  const Eigen::VectorXd& u,
                  const Eigen::VectorXd& lambda);

/// \brief One solution to write as fields: `stem`.vtu and `stem`_surface.csv.
struct FieldSet {
  std::string stem;
  Param mu;
  const Eigen::VectorXd* u = nullptr;       ///< full displacement (must outlive the call)
  const Eigen::VectorXd* lambda = nullptr;  ///< pressure per constraint row
};

/// \brief Writes the fields of every set in `dir`, and the `extra` files (path,
/// writer), as one set: all complete before any is published; a failure leaves
/// none of them (nor `dir`, if this call created it).
/// \throws InputError naming the folder or file and the reason (WriteFailure on a full disk).
void write_field_sets(const std::string& dir, const Problem& problem, const std::vector<FieldSet>& sets,
                      const std::vector<std::pair<std::string, FileWriter>>& extra = {});

}  // namespace contactrom::fom
