#include <contactrom/fom/mesh.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/input_file.hpp>
#include <contactrom/fom/child_process.hpp>
#include <contactrom/fom/data_directory.hpp>
#include <contactrom/fom/gmsh_api.hpp>
#include <contactrom/fom/gmsh_reader.hpp>
#include <contactrom/fom/mesh_serialization.hpp>

namespace contactrom::fom {
namespace {

// Coordinates are hashed after rounding to this resolution, so that the last-bit
// noise of a different libm does not change the fingerprint of the same mesh.
constexpr double kFingerprintResolution = 1e-12;

template <class T>
void fnv1a(std::uint64_t& h, T value) {
  // Hash the value's bytes least significant first, independent of endianness.
  using U = std::make_unsigned_t<T>;
  U u = static_cast<U>(value);
  for (std::size_t i = 0; i < sizeof(U); ++i) {
    h ^= static_cast<std::uint64_t>(u & 0xffu);
    h *= 1099511628211ull;
    u = static_cast<U>(u >> 8);
  }
}

void fnv1a(std::uint64_t& h, const std::string& s) {
  fnv1a(h, static_cast<std::int64_t>(s.size()));
  for (unsigned char c : s) fnv1a(h, c);
}


/// Refuses a mesh file gmsh should not read: unreadable, named other than .geo or
/// .msh, or a .msh that does not start as one. A .msh is data: gmsh parses anything
/// it cannot read as a mesh as a .geo program (System commands included), so only
/// a file that opens as the MSH format reaches gmsh.
void check_mesh_file(const std::string& path) {
  check_input_file(path, "mesh file", std::uintmax_t{4} << 30);  // a regular file of at most 4 GiB
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("mesh file " + quoted(path, 200) + " is not readable");
  const std::string ext = lower_extension(path);
  if (ext != ".geo" && ext != ".msh")
    throw InputError("mesh file " + quoted(path, 200) + " has the extension '" + ext +
                     "'; expected a gmsh mesh (.msh) or a gmsh geometry program (.geo)");
  if (ext == ".msh") {
    std::string first;
    std::getline(in, first);
    if (!first.empty() && first.back() == '\r') first.pop_back();
    if (first != "$MeshFormat")
      throw InputError("mesh file " + quoted(path, 200) + " does not start with the line $MeshFormat; expected a gmsh MSH file");
  }
}

}  // namespace


const std::vector<int>& Mesh::group_nodes(const std::string& name) const {
  auto it = curve_nodes.find(name);
  if (it != curve_nodes.end()) return it->second;
  std::string have;
  for (const auto& [n, list] : curve_nodes) have += (have.empty() ? "" : ", ") + n;
  throw InputError("mesh has no physical group " + quoted(name, 200) + " (has: " + have + ")");
}

const std::vector<std::array<int, 2>>& Mesh::group_segments(const std::string& name) const {
  auto it = segments.find(name);
  if (it != segments.end()) return it->second;
  std::string have;
  for (const auto& [n, list] : segments) have += (have.empty() ? "" : ", ") + n;
  throw InputError("mesh has no physical group " + quoted(name, 200) + " (has: " + have + ")");
}

std::string Mesh::fingerprint() const {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64 offset basis
  fnv1a(h, static_cast<std::int64_t>(nodes.cols()));
  for (Eigen::Index j = 0; j < nodes.cols(); ++j)
    for (Eigen::Index i = 0; i < nodes.rows(); ++i)
      fnv1a(h, static_cast<std::int64_t>(std::llround(nodes(i, j) / kFingerprintResolution)));
  fnv1a(h, static_cast<std::int64_t>(quads.size()));
  for (std::size_t e = 0; e < quads.size(); ++e) {
    for (int n : quads[e]) fnv1a(h, static_cast<std::int32_t>(n));
    fnv1a(h, static_cast<std::int32_t>(e < quad_body.size() ? quad_body[e] : -1));
  }
  for (const auto& name : body_names) fnv1a(h, name);
  for (const auto& [name, segs] : segments) {
    fnv1a(h, name);
    fnv1a(h, static_cast<std::int64_t>(segs.size()));
    for (const auto& s : segs) {
      fnv1a(h, static_cast<std::int32_t>(s[0]));
      fnv1a(h, static_cast<std::int32_t>(s[1]));
    }
  }
  // The node chains too: Dirichlet data and contact pairs read them, so a file
  // whose chain was altered is another discretisation.
  for (const auto& [name, chain] : curve_nodes) {
    fnv1a(h, name);
    fnv1a(h, static_cast<std::int64_t>(chain.size()));
    for (int n : chain) fnv1a(h, static_cast<std::int32_t>(n));
  }
  if (dim == 3) {  // (2D meshes keep the fingerprint they had before 3D existed)
    fnv1a(h, static_cast<std::int32_t>(dim));
    fnv1a(h, static_cast<std::int64_t>(cells.size()));
    for (std::size_t e = 0; e < cells.size(); ++e) {
      for (int n : cells[e]) fnv1a(h, static_cast<std::int32_t>(n));
      fnv1a(h, static_cast<std::int32_t>(e < cell_body.size() ? cell_body[e] : -1));
    }
    for (const auto& [name, list] : faces) {
      fnv1a(h, name);
      fnv1a(h, static_cast<std::int64_t>(list.size()));
      for (const auto& f : list)
        for (int n : f) fnv1a(h, static_cast<std::int32_t>(n));
    }
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::vector<int> Mesh::element_nodes(int e) const {
  if (dim == 3) {
    const auto& c = cells[static_cast<size_t>(e)];
    return std::vector<int>(c.begin(), c.begin() + cell_size(c));
  }
  const auto& q = quads[static_cast<size_t>(e)];
  return std::vector<int>(q.begin(), q.end());
}


Mesh load_mesh(const std::string& path, const MeshOptions& options) {
  if (options.refine < 0 || options.refine > MeshOptions::kMaxRefine)
    throw InputError("mesh refinement " + std::to_string(options.refine) + " invalid; expected an integer in 0.." +
                     std::to_string(MeshOptions::kMaxRefine));
  if (options.max_nodes < 1)
    throw InputError("mesh node limit (max_nodes) " + std::to_string(options.max_nodes) +
                     " invalid; expected a positive integer");
  if (!(options.time_limit_s > 0) || !std::isfinite(options.time_limit_s))
    throw InputError("mesh time limit " + std::to_string(options.time_limit_s) +
                     " s invalid; expected a positive number of seconds");

  check_mesh_file(path);
  const std::string where = "mesh " + quoted(path, 200);
  gmsh_api::load();  // once per process, before the fork: every later child shares it
  const ChildOutcome child = run_in_child_process(
      [&] { return serialize_mesh(mesh_with_gmsh(path, options)); }, options.time_limit_s, where,
      options.progress);
  switch (child.end) {
    case ChildOutcome::End::Answered:
      return deserialize_mesh(child.text, where);
    case ChildOutcome::End::Failed:
      throw InputError(child.text);
    case ChildOutcome::End::Error:  // not the file's fault (e.g. no gmsh library): exit code 1, not 2
      throw std::runtime_error(where + ": " + child.text);
    case ChildOutcome::End::TimedOut: {
      std::ostringstream limit;
      limit << options.time_limit_s;
      throw InputError(where + ": gmsh did not finish within the time limit of " + limit.str() +
                       " s (mesh_time_limit); stopped");
    }
    case ChildOutcome::End::Crashed:
      throw InputError(where + ": gmsh crashed (" + signal_name(child.signal) +
                       ") while reading or meshing it; expected a file gmsh can mesh");
    case ChildOutcome::End::CalledExit:
      throw InputError(where + " ended the program while gmsh read it (an Exit command); a .geo file is a program: "
                               "expected one that only builds a mesh");
    case ChildOutcome::End::ExitCode:
      break;
  }
  throw InputError(where + ": gmsh ended with exit code " + std::to_string(child.exit_code) +
                   " while reading or meshing it");
}

std::string mesh_directory() { return data_directory("meshes", "CONTACTROM_MESH_DIR"); }

}  // namespace contactrom::fom
