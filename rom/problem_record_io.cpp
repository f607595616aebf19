#include <contactrom/rom/problem_record_io.hpp>

#include <array>
#include <cmath>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/rom/hdf5_io.hpp>

namespace contactrom::rom {
namespace {

using hdf5::Handle;

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  size_t start = 0;
  for (;;) {
    const size_t end = text.find(sep, start);
    out.push_back(text.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

/// A rows × cols dataset of finite doubles with the expected shape (cols = 0: rank 1).
std::vector<double> read_doubles(hid_t f, const char* name, hsize_t rows, hsize_t cols) {
  const std::vector<hsize_t> dims = hdf5::dataset_shape(f, name);
  const bool ok = cols == 0 ? dims.size() == 1 && dims[0] == rows : dims.size() == 2 && dims[0] == rows && dims[1] == cols;
  if (!ok)
    throw hdf5::Refused(std::string("dataset /") + name + " has shape (" + std::to_string(dims[0]) +
                        (dims.size() == 2 ? ", " + std::to_string(dims[1]) : std::string()) + "), expected (" +
                        std::to_string(rows) + (cols ? ", " + std::to_string(cols) : std::string()) + ")");
  std::vector<double> out;
  hsize_t r = 0, c = 0;
  hdf5::read_double_dataset(f, name, out, r, c);
  for (double v : out)
    if (!std::isfinite(v)) throw hdf5::Refused(std::string("dataset /") + name + " holds a non-finite number");
  return out;
}

/// The body of every element (dataset /mesh/<element>_body, one entry per element of
/// `count`) and the body names, each body index checked against the names.
void read_element_bodies(hid_t f, const std::string& element, hsize_t count, fom::Mesh& mesh, std::vector<int>& body) {
  const std::string name = "mesh/" + element + "_body";
  hsize_t rows = 0, cols = 0;
  hdf5::read_int_dataset(f, name.c_str(), body, rows, cols);
  if (rows != count || cols != 1)
    throw hdf5::Refused("dataset /" + name + " has " + std::to_string(rows) + " entries, expected one per " + element +
                        " (" + std::to_string(count) + ")");
  mesh.body_names = hdf5::read_string_list(f, "mesh/body_names", hdf5::file_size(f));
  for (int b : body)
    if (b < 0 || b >= static_cast<int>(mesh.body_names.size()))
      throw hdf5::Refused("dataset /" + name + " holds the body " + std::to_string(b) + " of " +
                          std::to_string(mesh.body_names.size()));
}

/// The 3D part of a mesh: cells, their bodies, and facet groups (docs/database_format.md).
template <class CheckIds>
std::shared_ptr<const fom::Mesh> read_mesh_3d(hid_t f, std::shared_ptr<fom::Mesh> mesh, CheckIds&& check_ids) {
  hsize_t rows = 0, cols = 0;
  std::vector<int> cells;
  hdf5::read_int_dataset(f, "mesh/cells", cells, rows, cols);
  if (cols != 8) throw hdf5::Refused("dataset /mesh/cells does not have 8 columns");
  check_ids(cells, "mesh/cells", true);
  for (size_t e = 0; e + 7 < cells.size(); e += 8) {
    std::array<int, 8> c;
    std::copy(cells.begin() + static_cast<long>(e), cells.begin() + static_cast<long>(e) + 8, c.begin());
    if (c[3] < 0 || (c[4] < 0) != (c[7] < 0)) throw hdf5::Refused("dataset /mesh/cells holds a cell of neither 4 nor 8 nodes");
    mesh->cells.push_back(c);
  }
  read_element_bodies(f, "cell", rows, *mesh, mesh->cell_body);
  const std::vector<std::string> groups = hdf5::read_string_list(f, "mesh/curve_names", hdf5::file_size(f));
  for (size_t i = 0; i < groups.size(); ++i) {
    const std::string base = "mesh/curve_" + std::to_string(i);
    std::vector<int> nodes, facets;
    hdf5::read_int_dataset(f, (base + "_nodes").c_str(), nodes, rows, cols);
    check_ids(nodes, base + "_nodes");
    mesh->curve_nodes[groups[i]] = nodes;
    if (H5Lexists(f, (base + "_facets").c_str(), H5P_DEFAULT) <= 0) continue;
    hdf5::read_int_dataset(f, (base + "_facets").c_str(), facets, rows, cols);
    if (cols != 4 && !facets.empty()) throw hdf5::Refused("dataset /" + base + "_facets does not have 4 columns");
    check_ids(facets, base + "_facets", true);
    auto& out = mesh->faces[groups[i]];
    for (size_t k = 0; k + 3 < facets.size(); k += 4) out.push_back({facets[k], facets[k + 1], facets[k + 2], facets[k + 3]});
  }
  return mesh;
}

/// Reads the mesh, checking every index against the node count.
std::shared_ptr<const fom::Mesh> read_mesh(hid_t f) {
  auto mesh = std::make_shared<fom::Mesh>();
  std::vector<double> xy;
  hsize_t rows = 0, cols = 0;
  hdf5::read_double_dataset(f, "mesh/nodes", xy, rows, cols);
  if (cols != 2 && cols != 3) throw hdf5::Refused("dataset /mesh/nodes does not have 2 or 3 columns");
  for (double v : xy)
    if (!std::isfinite(v)) throw hdf5::Refused("dataset /mesh/nodes holds a non-finite coordinate");
  mesh->dim = static_cast<int>(cols);
  mesh->nodes = Eigen::Map<Eigen::MatrixXd>(xy.data(), mesh->dim, static_cast<Eigen::Index>(rows));
  const int nn = static_cast<int>(rows);
  auto check_ids = [&](const std::vector<int>& ids, const std::string& what, bool allow_unused = false) {
    for (int id : ids)
      if ((id < 0 && !(allow_unused && id == -1)) || id >= nn)
        throw hdf5::Refused("dataset /" + what + " refers to node " + std::to_string(id) + ", expected 0.." +
                            std::to_string(nn - 1));
  };
  if (mesh->dim == 3) return read_mesh_3d(f, mesh, check_ids);
  std::vector<int> quads;
  hdf5::read_int_dataset(f, "mesh/quads", quads, rows, cols);
  if (cols != 4) throw hdf5::Refused("dataset /mesh/quads does not have 4 columns");
  check_ids(quads, "mesh/quads");
  for (size_t q = 0; q + 3 < quads.size(); q += 4)
    mesh->quads.push_back({quads[q], quads[q + 1], quads[q + 2], quads[q + 3]});
  read_element_bodies(f, "quad", rows, *mesh, mesh->quad_body);
  const std::vector<std::string> curves = hdf5::read_string_list(f, "mesh/curve_names", hdf5::file_size(f));
  for (size_t i = 0; i < curves.size(); ++i) {
    const std::string base = "mesh/curve_" + std::to_string(i);
    std::vector<int> nodes, segs;
    hdf5::read_int_dataset(f, (base + "_nodes").c_str(), nodes, rows, cols);
    hdf5::read_int_dataset(f, (base + "_segments").c_str(), segs, rows, cols);
    if (cols != 2 && !segs.empty()) throw hdf5::Refused("dataset /" + base + "_segments does not have 2 columns");
    check_ids(nodes, base + "_nodes");
    check_ids(segs, base + "_segments");
    mesh->curve_nodes[curves[i]] = nodes;
    auto& out = mesh->segments[curves[i]];
    for (size_t k = 0; k + 1 < segs.size(); k += 2) out.push_back({segs[k], segs[k + 1]});
  }
  return mesh;
}

/// The 3D part of a mesh (after /mesh/nodes): cells, bodies, node groups and facet groups.
void write_mesh_3d(hid_t f, hid_t dcpl, const fom::Mesh& m) {
  using hdf5::write_dataset;
  write_dataset(f, dcpl, "mesh/cells", H5T_STD_I32LE, H5T_NATIVE_INT, 2, static_cast<hsize_t>(m.num_cells()), 8,
                m.cells.data());
  write_dataset(f, dcpl, "mesh/cell_body", H5T_STD_I32LE, H5T_NATIVE_INT, 1, static_cast<hsize_t>(m.num_cells()), 0,
                m.cell_body.data());
  hdf5::write_string_list(f, dcpl, "mesh/body_names", m.body_names);
  std::vector<std::string> groups;
  for (const auto& [name, nodes] : m.curve_nodes) groups.push_back(name);
  hdf5::write_string_list(f, dcpl, "mesh/curve_names", groups);
  for (size_t i = 0; i < groups.size(); ++i) {
    const auto& nodes = m.curve_nodes.at(groups[i]);
    const std::string base = "mesh/curve_" + std::to_string(i);
    write_dataset(f, dcpl, (base + "_nodes").c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, 1, nodes.size(), 0, nodes.data());
    auto facets = m.faces.find(groups[i]);
    if (facets != m.faces.end())
      write_dataset(f, dcpl, (base + "_facets").c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, 2, facets->second.size(), 4,
                    facets->second.data());
  }
}

}  // namespace

void write_problem_record(hid_t f, hid_t dcpl, const ProblemRecord& r) {
  using hdf5::write_dataset;
  const hsize_t nc = static_cast<hsize_t>(r.contact_weights.size());
  if (r.contact_points.cols() != r.contact_weights.size())
    throw hdf5::Failure("problem record: contact points and weights differ in size");
  hdf5::write_string_attribute(f, "problem", r.name);
  hdf5::write_string_attribute(f, "mesh_fingerprint", r.fingerprint);
  hdf5::write_string_attribute(f, "param_names", join(r.param_names, ","));
  if (!r.text.empty()) hdf5::write_string_list(f, dcpl, "problem_file", {r.text});
  Handle contact(H5Gcreate2(f, "contact", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /contact");
  write_dataset(f, dcpl, "contact/points", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, nc,
                static_cast<hsize_t>(r.contact_points.rows()), r.contact_points.data());
  write_dataset(f, dcpl, "contact/weights", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, nc, 0, r.contact_weights.data());
  // n_dofs × n_terms column-major == row-major n_terms × n_dofs: one term per row.
  write_dataset(f, dcpl, "lifting", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, static_cast<hsize_t>(r.lifting_terms.cols()),
                static_cast<hsize_t>(r.lifting_terms.rows()), r.lifting_terms.data());
  if (!r.mesh) return;
  const fom::Mesh& m = *r.mesh;
  Handle group(H5Gcreate2(f, "mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "group /mesh");
  write_dataset(f, dcpl, "mesh/nodes", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, static_cast<hsize_t>(m.num_nodes()),
                static_cast<hsize_t>(m.dim), m.nodes.data());
  if (m.dim == 3) return write_mesh_3d(f, dcpl, m);
  write_dataset(f, dcpl, "mesh/quads", H5T_STD_I32LE, H5T_NATIVE_INT, 2, static_cast<hsize_t>(m.num_quads()), 4,
                m.quads.data());
  write_dataset(f, dcpl, "mesh/quad_body", H5T_STD_I32LE, H5T_NATIVE_INT, 1, static_cast<hsize_t>(m.num_quads()), 0,
                m.quad_body.data());
  hdf5::write_string_list(f, dcpl, "mesh/body_names", m.body_names);
  std::vector<std::string> curves;
  for (const auto& [name, nodes] : m.curve_nodes) curves.push_back(name);
  hdf5::write_string_list(f, dcpl, "mesh/curve_names", curves);
  for (size_t i = 0; i < curves.size(); ++i) {
    const auto& nodes = m.curve_nodes.at(curves[i]);
    const auto& segs = m.segments.at(curves[i]);
    const std::string base = "mesh/curve_" + std::to_string(i);
    write_dataset(f, dcpl, (base + "_nodes").c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, 1, nodes.size(), 0, nodes.data());
    write_dataset(f, dcpl, (base + "_segments").c_str(), H5T_STD_I32LE, H5T_NATIVE_INT, 2, segs.size(), 2, segs.data());
  }
}

ProblemRecord read_problem_record(hid_t f, hsize_t num_constraints, hsize_t num_dofs) {
  ProblemRecord r;
  r.name = hdf5::read_string_attribute(f, "problem");
  r.fingerprint = hdf5::read_string_attribute(f, "mesh_fingerprint");
  r.param_names = split(hdf5::read_string_attribute(f, "param_names"), ',');
  if (H5Lexists(f, "problem_file", H5P_DEFAULT) > 0) {
    const std::vector<std::string> text = hdf5::read_string_list(f, "problem_file", hdf5::file_size(f));
    if (text.size() != 1) throw hdf5::Refused("dataset /problem_file does not hold one text");
    r.text = text[0];
  }
  if (H5Lexists(f, "mesh", H5P_DEFAULT) > 0) r.mesh = read_mesh(f);
  const hsize_t dim = r.mesh ? static_cast<hsize_t>(r.mesh->dim) : 2;
  std::vector<double> points = read_doubles(f, "contact/points", num_constraints, dim);
  r.contact_points = Eigen::Map<Eigen::MatrixXd>(points.data(), static_cast<Eigen::Index>(dim),
                                                 static_cast<Eigen::Index>(num_constraints));
  std::vector<double> weights = read_doubles(f, "contact/weights", num_constraints, 0);
  r.contact_weights = Eigen::Map<Eigen::VectorXd>(weights.data(), static_cast<Eigen::Index>(num_constraints));
  const std::vector<hsize_t> lift_dims = hdf5::dataset_shape(f, "lifting");
  if (lift_dims.size() != 2 || lift_dims[1] != num_dofs)
    throw hdf5::Refused("dataset /lifting has " + std::to_string(lift_dims.size() == 2 ? lift_dims[1] : 1) +
                        " columns, expected one per dof (" + std::to_string(num_dofs) + ")");
  std::vector<double> lift = read_doubles(f, "lifting", lift_dims[0], num_dofs);
  r.lifting_terms = Eigen::Map<Eigen::MatrixXd>(lift.data(), static_cast<Eigen::Index>(num_dofs),
                                                static_cast<Eigen::Index>(lift_dims[0]));
  return r;
}

}  // namespace contactrom::rom
