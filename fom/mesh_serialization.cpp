#include <contactrom/fom/mesh_serialization.hpp>

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

#include <contactrom/core/errors.hpp>

namespace contactrom::fom {
namespace {

class MeshWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    m_bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put(const std::string& s) {
    put<std::uint64_t>(s.size());
    m_bytes += s;
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    put<std::uint64_t>(v.size());
    m_bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string& bytes() { return m_bytes; }

 private:
  std::string m_bytes;
};

class MeshReader {
 public:
  MeshReader(const std::string& bytes, std::string where) : m_bytes(bytes), m_where(std::move(where)) {}
  template <class T>
  T get() {
    T v;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  std::string get_string() {
    const std::size_t n = count(1);
    return std::string(take(n), n);
  }
  template <class T>
  std::vector<T> get_vector() {
    const std::size_t n = count(sizeof(T));
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }

 private:
  std::size_t count(std::size_t item) {
    const auto n = get<std::uint64_t>();
    if (n > (m_bytes.size() - m_pos) / item) broken();
    return static_cast<std::size_t>(n);
  }
  const char* take(std::size_t n) {
    if (n > m_bytes.size() - m_pos) broken();
    const char* p = m_bytes.data() + m_pos;
    m_pos += n;
    return p;
  }
  [[noreturn]] void broken() const { throw InputError(m_where + ": incomplete mesh data"); }

  const std::string& m_bytes;
  std::string m_where;
  std::size_t m_pos = 0;
};

}  // namespace

std::string serialize_mesh(const Mesh& mesh) {
  MeshWriter w;
  w.put<std::int32_t>(mesh.dim);
  w.put_vector(std::vector<double>(mesh.nodes.data(), mesh.nodes.data() + mesh.nodes.size()));
  w.put_vector(mesh.quads);
  w.put_vector(mesh.quad_body);
  w.put<std::uint64_t>(mesh.body_names.size());
  for (const auto& name : mesh.body_names) w.put(name);
  w.put<std::uint64_t>(mesh.segments.size());
  for (const auto& [name, segs] : mesh.segments) w.put(name), w.put_vector(segs);
  w.put<std::uint64_t>(mesh.curve_nodes.size());
  for (const auto& [name, nodes] : mesh.curve_nodes) w.put(name), w.put_vector(nodes);
  w.put_vector(mesh.cells);
  w.put_vector(mesh.cell_body);
  w.put<std::uint64_t>(mesh.faces.size());
  for (const auto& [name, facets] : mesh.faces) w.put(name), w.put_vector(facets);
  return std::move(w.bytes());
}

Mesh deserialize_mesh(const std::string& bytes, const std::string& where) {
  MeshReader r(bytes, where);
  Mesh mesh;
  mesh.dim = r.get<std::int32_t>();
  if (mesh.dim != 2 && mesh.dim != 3) throw InputError(where + ": broken mesh data");
  const auto coords = r.get_vector<double>();
  mesh.nodes = Eigen::Map<const Eigen::MatrixXd>(coords.data(), mesh.dim,
                                                 static_cast<Eigen::Index>(coords.size()) / mesh.dim);
  mesh.quads = r.get_vector<std::array<int, 4>>();
  mesh.quad_body = r.get_vector<int>();
  for (auto n = r.get<std::uint64_t>(); n > 0; --n) mesh.body_names.push_back(r.get_string());
  for (auto n = r.get<std::uint64_t>(); n > 0; --n) {
    std::string name = r.get_string();
    mesh.segments[name] = r.get_vector<std::array<int, 2>>();
  }
  for (auto n = r.get<std::uint64_t>(); n > 0; --n) {
    std::string name = r.get_string();
    mesh.curve_nodes[name] = r.get_vector<int>();
  }
  mesh.cells = r.get_vector<std::array<int, 8>>();
  mesh.cell_body = r.get_vector<int>();
  for (auto n = r.get<std::uint64_t>(); n > 0; --n) {
    std::string name = r.get_string();
    mesh.faces[name] = r.get_vector<std::array<int, 4>>();
  }
  return mesh;
}

}  // namespace contactrom::fom
