#pragma once
/// \file gmsh_api.hpp
/// \brief The part of gmsh's C++ API that fom/gmsh_reader.cpp uses, with gmsh's
/// names and signatures, on a gmsh library loaded when it is first called.
///
/// Why: libgmsh brings about 80 libraries with it (OpenCASCADE, FLTK, X11), and
/// linking them costs every process about 0.1 s at start-up, more than most
/// commands' own work; commands on a database or a reduced model (online --db,
/// query, reduce, merge, verify) and Python's `import contactrom` never mesh. Here the
/// library is opened (dlopen) by load() or the first call, in the first process
/// that meshes (docs/results.md, "Process start-up"). The functions call gmsh's C API
/// (gmshc.h) and, as gmsh's C++ API does, throw the C API's error code (an int)
/// when a call fails; the message is in gmsh's log. A gmsh library that cannot be
/// opened throws std::runtime_error naming it. A private header of contactrom::fom.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace contactrom::fom::gmsh_api {

using vectorpair = std::vector<std::pair<int, int>>;

/// \brief Opens the gmsh library now (once per process; later calls do nothing).
/// load_mesh() calls it before forking its child, so that the children of one
/// process share one load. \throws std::runtime_error if it cannot be opened.
void load();

void initialize(int argc, char** argv, bool read_config_files);
void finalize();
void open(const std::string& file_name);

namespace option {
void setNumber(const std::string& name, double value);
}  // namespace option

namespace logger {
void start();
void stop();
void get(std::vector<std::string>& log);
}  // namespace logger

namespace model {
void getPhysicalGroups(vectorpair& dim_tags, int dim);
void getPhysicalName(int dim, int tag, std::string& name);
void getEntitiesForPhysicalGroup(int dim, int tag, std::vector<int>& tags);

namespace mesh {
void generate(int dim);
void refine();
void getNodes(std::vector<std::size_t>& node_tags, std::vector<double>& coord, std::vector<double>& parametric_coord,
              int dim, int tag, bool include_boundary, bool return_parametric_coord);
void getElements(std::vector<int>& element_types, std::vector<std::vector<std::size_t>>& element_tags,
                 std::vector<std::vector<std::size_t>>& node_tags, int dim, int tag);
void getElementProperties(int element_type, std::string& element_name, int& dim, int& order, int& num_nodes,
                          std::vector<double>& local_node_coord, int& num_primary_nodes);
}  // namespace mesh
}  // namespace model

}  // namespace contactrom::fom::gmsh_api
