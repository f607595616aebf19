#include <contactrom/fom/field_output.hpp>

#include <filesystem>
#include <iomanip>
#include <limits>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/fom/input_values.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/rope.hpp>

namespace contactrom::fom {
namespace {

void data_array(std::ostream& out, const char* name, int components, const Eigen::MatrixXd& values) {
  // values: one row per point/cell, `components` columns
  out << "        <DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"" << components
      << "\" format=\"ascii\">\n";
  for (int i = 0; i < values.rows(); ++i) {
    out << "         ";
    for (int c = 0; c < components; ++c) out << ' ' << values(i, c);
    out << '\n';
  }
  out << "        </DataArray>\n";
}

/// The VTU content (see write_vtu); captures its arguments by reference.
FileWriter vtu_writer(const Problem& problem, const Param& mu, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda) {
  return [&problem, &mu, &u, &lambda](std::ostream& out) {
    const Mesh* mesh = problem.mesh();
    const ContactModel& contact = problem.contact();
    out << std::setprecision(std::numeric_limits<double>::max_digits10);
    const Eigen::VectorXd rope_x = mesh ? Eigen::VectorXd() : rope_nodes(problem);  // no mesh: the 1D rope
    const int np = mesh ? mesh->num_nodes() : static_cast<int>(rope_x.size());
    const int ncell = mesh ? mesh->num_elements() : np - 1;
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n";
    // The parameter of the solution, one field value per parameter, named after it.
    if (mu.size() == problem.num_params() && mu.size() > 0) {
      out << "    <FieldData>\n";
      for (Eigen::Index k = 0; k < mu.size(); ++k)
        out << "      <DataArray type=\"Float64\" Name=\"" << problem.param_names()[static_cast<size_t>(k)]
            << "\" NumberOfTuples=\"1\" format=\"ascii\">" << format_number(mu(k)) << "</DataArray>\n";
      out << "    </FieldData>\n";
    }
    out << "    <Piece NumberOfPoints=\"" << np << "\" NumberOfCells=\"" << ncell << "\">\n";
    Eigen::MatrixXd pts = Eigen::MatrixXd::Zero(np, 3);
    for (int i = 0; i < np; ++i) {
      if (mesh) pts.row(i).head(mesh->dim) = mesh->nodes.col(i).transpose();
      else pts(i, 0) = rope_x(i);
    }
    out << "      <Points>\n";
    data_array(out, "Points", 3, pts);
    out << "      </Points>\n      <Cells>\n"
        << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    // VTK cell types: 3 line, 9 quad, 10 tetra, 12 hexahedron (gmsh's node order is VTK's).
    std::vector<int> offsets, types;
    int offset = 0;
    for (int c = 0; c < ncell; ++c) {
      out << "         ";
      const std::vector<int> nodes = mesh ? mesh->element_nodes(c) : std::vector<int>{c, c + 1};
      for (int v : nodes) out << ' ' << v;
      out << '\n';
      offsets.push_back(offset += static_cast<int>(nodes.size()));
      types.push_back(!mesh ? 3 : mesh->dim == 2 ? 9 : nodes.size() == 4 ? 10 : 12);
    }
    out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n         ";
    for (int o : offsets) out << ' ' << o;
    out << "\n        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n         ";
    for (int t : types) out << ' ' << t;
    out << "\n        </DataArray>\n      </Cells>\n      <PointData Vectors=\"displacement\">\n";
    Eigen::MatrixXd disp = Eigen::MatrixXd::Zero(np, 3), press = Eigen::MatrixXd::Zero(np, 1);
    // The rope's one dof per node is its transverse deflection: the y component.
    for (int i = 0; i < np; ++i)
      if (problem.dofs_per_node() == 1) disp(i, 1) = u(i);
      else for (int d = 0; d < problem.dofs_per_node(); ++d) disp(i, d) = u(problem.dofs_per_node() * i + d);
    // Constraint row s sits on the node of its first surface dof column.
    const std::vector<int>& surf = contact.surface_dofs();
    for (int s = 0; s < contact.num_constraints(); ++s)
      press(surf[problem.dofs_per_node() * s] / problem.dofs_per_node(), 0) = lambda(s);
    data_array(out, "displacement", 3, disp);
    data_array(out, "contact_pressure", 1, press);
    out << "      </PointData>\n";
    if (mesh) {
      const Eigen::MatrixXd stress = element_stresses(*mesh, problem.materials(mu), u);
      Eigen::MatrixXd body(ncell, 1);
      for (int c = 0; c < ncell; ++c) body(c, 0) = mesh->element_body(c);
      out << "      <CellData>\n";
      const int components = static_cast<int>(stress.cols()) - 1;  // 2D: 4, 3D: 6, then von Mises
      data_array(out, "stress", components, stress.leftCols(components));
      data_array(out, "von_mises", 1, stress.col(components));
      data_array(out, "body", 1, body);
      out << "      </CellData>\n";
    }
    out << "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  };
}

/// The contact surface CSV content (see write_surface_csv).
FileWriter surface_csv_writer(const Problem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& lambda) {
  return [&problem, &u, &lambda](std::ostream& out) {
    const ContactModel& contact = problem.contact();
    const Eigen::VectorXd gap = normal_gaps(problem, u);
    out << std::setprecision(std::numeric_limits<double>::max_digits10);
    const std::vector<int>& surf = contact.surface_dofs();
    const int per_node = problem.dofs_per_node();
    if (per_node == 3) {
      out << "x,y,z,gap,pressure,u_x,u_y,u_z\n";
      for (int s = 0; s < contact.num_constraints(); ++s) {
        const int dof = surf[static_cast<size_t>(3 * s)];
        for (int c = 0; c < 3; ++c) out << contact.constraint_points()(c, s) << ',';
        if (std::isfinite(gap(s))) out << gap(s) + 0.0;  // + 0.0: a gap of -0 is written 0
        else out << "inf";
        out << ',' << lambda(s) << ',' << u(dof) << ',' << u(dof + 1) << ',' << u(dof + 2) << '\n';
      }
      return;
    }
    out << "x,y,gap,pressure,u_x,u_y\n";
    for (int s = 0; s < contact.num_constraints(); ++s) {
      // Reference coordinates (the rope lies on y = 0), then the node's displacement
      // (the rope's is transverse: u_y).
      const double y = problem.mesh() ? contact.constraint_points()(1, s) : 0.0;
      out << contact.constraint_points()(0, s) << ',' << y << ',';
      if (std::isfinite(gap(s))) out << gap(s) + 0.0;  // + 0.0: a gap of -0 is written 0
      else out << "inf";
      const int dof = surf[static_cast<size_t>(per_node * s)];
      if (per_node == 1) out << ',' << lambda(s) << ",0," << u(dof) << '\n';
      else out << ',' << lambda(s) << ',' << u(dof) << ',' << u(dof + 1) << '\n';
    }
  };
}

}  // namespace

void write_vtu(const std::string& path, const Problem& problem, const Param& mu, const Eigen::VectorXd& u,
               const Eigen::VectorXd& lambda) {
  write_file_atomically(path, vtu_writer(problem, mu, u, lambda));
}

void write_surface_csv(const std::string& path, const Problem& problem, const Eigen::VectorXd& u,
                       const Eigen::VectorXd& lambda) {
  write_file_atomically(path, surface_csv_writer(problem, u, lambda));
}

void write_fields(const std::string& dir, const std::string& stem, const Problem& problem, const Param& mu,
                  const Eigen::VectorXd& u,
                  const Eigen::VectorXd& lambda) {
  write_field_sets(dir, problem, {{stem, mu, &u, &lambda}});
}

void write_field_sets(const std::string& dir, const Problem& problem, const std::vector<FieldSet>& sets,
                      const std::vector<std::pair<std::string, FileWriter>>& extra) {
  namespace fs = std::filesystem;
  if (dir.empty()) throw InputError("output folder name is empty; expected a folder");
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(dir, ec);
  bool created = false;
  if (fs::exists(st)) {
    if (!fs::is_directory(fs::status(dir, ec)))
      throw InputError("cannot create output folder " + quoted(dir, 200) + ": a file of that name exists");
  } else {
    fs::create_directories(dir, ec);
    if (ec) throw InputError("cannot create output folder " + quoted(dir, 200) + ": " + ec.message());
    created = true;
    register_created_folder(dir);
  }
  std::vector<std::pair<std::string, FileWriter>> files = extra;
  for (const FieldSet& set : sets) {
    const std::string base = dir + "/" + set.stem;
    files.emplace_back(base + ".vtu", vtu_writer(problem, set.mu, *set.u, *set.lambda));
    files.emplace_back(base + "_surface.csv", surface_csv_writer(problem, *set.u, *set.lambda));
  }
  try {
    write_files_atomically(files);
  } catch (...) {
    if (created) {
      fs::remove(dir, ec);  // only if still empty
      forget_created_folder(dir);
    }
    throw;
  }
  if (created) forget_created_folder(dir);
}

}  // namespace contactrom::fom
