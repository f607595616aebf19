#include <contactrom/fom/gmsh_api.hpp>

#include <gmshc.h>

#include <dlfcn.h>

#include <stdexcept>

namespace contactrom::fom::gmsh_api {
namespace {

/// The gmsh library, opened once per process: the file found at configure time, else
/// a file of that name on the loader's search path (LD_LIBRARY_PATH included). Its
/// symbols stay out of the global scope (RTLD_LOCAL): nothing loaded later binds to
/// them. (Ours cannot stand in for theirs either: the executable exports none,
/// CMakeLists.txt's hidden visibility.)
void* library() {
  static void* const handle = [] {
    std::string tried, errors;
    for (const char* name : {CONTACTROM_GMSH_LIBRARY, CONTACTROM_GMSH_NAME}) {
      if (void* h = dlopen(name, RTLD_LAZY | RTLD_LOCAL)) return h;
      tried += std::string(tried.empty() ? "" : ", ") + name;
      if (const char* e = dlerror()) errors += std::string("; ") + e;
    }
    throw std::runtime_error("the gmsh library could not be loaded (tried " + tried + ")" + errors);
  }();
  return handle;
}

template <class Fn>
Fn* symbol(const char* name) {
  void* address = dlsym(library(), name);
  if (!address) throw std::runtime_error(std::string("the gmsh library has no function ") + name);
  return reinterpret_cast<Fn*>(address);
}

/// gmsh's C function `name` (gmshc.h), looked up in the library.
#define CONTACTROM_GMSH(name) symbol<decltype(name)>(#name)

/// Calls a gmsh C function with `args` and its error flag; a failure throws the
/// error code, as gmsh's C++ API does.
template <class Fn, class... Args>
void call(Fn* function, Args... args) {
  int ierr = 0;
  function(args..., &ierr);
  if (ierr != 0) throw ierr;
}

/// gmsh's allocations (output arrays of the C API) are released with gmshFree.
void release(void* p) { CONTACTROM_GMSH(gmshFree)(p); }

template <class T>
std::vector<T> take_array(T* data, std::size_t n) {
  std::vector<T> out(data, data + n);
  release(data);
  return out;
}

std::string take_string(char* text) {
  std::string out = text ? text : "";
  release(text);
  return out;
}

template <class T>
std::vector<std::vector<T>> take_arrays(T** data, std::size_t* sizes, std::size_t n) {
  std::vector<std::vector<T>> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = take_array(data[i], sizes[i]);
  release(sizes);
  release(data);
  return out;
}

}  // namespace

void load() { library(); }

void initialize(int argc, char** argv, bool read_config_files) {
  call(CONTACTROM_GMSH(gmshInitialize), argc, argv, read_config_files ? 1 : 0);
}

void finalize() { call(CONTACTROM_GMSH(gmshFinalize)); }

void open(const std::string& file_name) { call(CONTACTROM_GMSH(gmshOpen), file_name.c_str()); }

namespace option {
void setNumber(const std::string& name, double value) {
  call(CONTACTROM_GMSH(gmshOptionSetNumber), name.c_str(), value);
}
}  // namespace option

namespace logger {
void start() { call(CONTACTROM_GMSH(gmshLoggerStart)); }

void stop() { call(CONTACTROM_GMSH(gmshLoggerStop)); }

void get(std::vector<std::string>& log) {
  char** lines = nullptr;
  std::size_t n = 0;
  call(CONTACTROM_GMSH(gmshLoggerGet), &lines, &n);
  log.clear();
  for (std::size_t i = 0; i < n; ++i) log.push_back(take_string(lines[i]));
  release(lines);
}
}  // namespace logger

namespace model {
void getPhysicalGroups(vectorpair& dim_tags, int dim) {
  int* flat = nullptr;
  std::size_t n = 0;
  call(CONTACTROM_GMSH(gmshModelGetPhysicalGroups), &flat, &n, dim);
  const std::vector<int> pairs = take_array(flat, n);
  dim_tags.clear();
  for (std::size_t i = 0; i + 1 < pairs.size(); i += 2) dim_tags.emplace_back(pairs[i], pairs[i + 1]);
}

void getPhysicalName(int dim, int tag, std::string& name) {
  char* text = nullptr;
  call(CONTACTROM_GMSH(gmshModelGetPhysicalName), dim, tag, &text);
  name = take_string(text);
}

void getEntitiesForPhysicalGroup(int dim, int tag, std::vector<int>& tags) {
  int* data = nullptr;
  std::size_t n = 0;
  call(CONTACTROM_GMSH(gmshModelGetEntitiesForPhysicalGroup), dim, tag, &data, &n);
  tags = take_array(data, n);
}

namespace mesh {
void generate(int dim) { call(CONTACTROM_GMSH(gmshModelMeshGenerate), dim); }

void refine() { call(CONTACTROM_GMSH(gmshModelMeshRefine)); }

void getNodes(std::vector<std::size_t>& node_tags, std::vector<double>& coord, std::vector<double>& parametric_coord,
              int dim, int tag, bool include_boundary, bool return_parametric_coord) {
  std::size_t *tags = nullptr, n_tags = 0, n_coord = 0, n_param = 0;
  double *xyz = nullptr, *param = nullptr;
  call(CONTACTROM_GMSH(gmshModelMeshGetNodes), &tags, &n_tags, &xyz, &n_coord, &param, &n_param, dim, tag,
       include_boundary ? 1 : 0, return_parametric_coord ? 1 : 0);
  node_tags = take_array(tags, n_tags);
  coord = take_array(xyz, n_coord);
  parametric_coord = take_array(param, n_param);
}

void getElements(std::vector<int>& element_types, std::vector<std::vector<std::size_t>>& element_tags,
                 std::vector<std::vector<std::size_t>>& node_tags, int dim, int tag) {
  int* types = nullptr;
  std::size_t n_types = 0, **elements = nullptr, *n_elements = nullptr, nn_elements = 0, **nodes = nullptr,
              *n_nodes = nullptr, nn_nodes = 0;
  call(CONTACTROM_GMSH(gmshModelMeshGetElements), &types, &n_types, &elements, &n_elements, &nn_elements, &nodes,
       &n_nodes, &nn_nodes, dim, tag);
  element_types = take_array(types, n_types);
  element_tags = take_arrays(elements, n_elements, nn_elements);
  node_tags = take_arrays(nodes, n_nodes, nn_nodes);
}

void getElementProperties(int element_type, std::string& element_name, int& dim, int& order, int& num_nodes,
                          std::vector<double>& local_node_coord, int& num_primary_nodes) {
  char* name = nullptr;
  double* local = nullptr;
  std::size_t n_local = 0;
  call(CONTACTROM_GMSH(gmshModelMeshGetElementProperties), element_type, &name, &dim, &order, &num_nodes, &local,
       &n_local, &num_primary_nodes);
  element_name = take_string(name);
  local_node_coord = take_array(local, n_local);
}
}  // namespace mesh
}  // namespace model

}  // namespace contactrom::fom::gmsh_api
