#include <contactrom/fom/gmsh_reader.hpp>

#include <contactrom/fom/gmsh_api.hpp>

#include <algorithm>
#include <cctype>
#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <unordered_map>
#include <utility>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>

namespace contactrom::fom {
namespace {

namespace gmsh = gmsh_api;  // gmsh's C++ API, opened on first use

// gmsh element type codes (gmsh.info, "MSH file format"): only the two we keep.
constexpr int kGmshLine2 = 1;
constexpr int kGmshQuad4 = 3;
constexpr int kGmshTriangle3 = 2;
constexpr int kGmshTetrahedron4 = 4;
constexpr int kGmshHexahedron8 = 5;

// A quad whose |signed area| is below this fraction of its squared diameter is
// rejected as degenerate (collapsed or self-overlapping corner numbering).
constexpr double kDegenerateAreaRatio = 1e-12;

/// Owns one gmsh API session: quiet initialisation on construction, finalize
/// on destruction (also when a check below throws), and the messages gmsh logged
/// meanwhile. gmsh keeps its model in global state, hence load_mesh is not
/// thread-safe; a fresh session per call makes it safe to call repeatedly and
/// leaves no option (e.g. Mesh.SubdivisionAlgorithm set by one .geo) behind for
/// the next file.
class GmshSession {
 public:
  GmshSession() {
    // gmsh calls setlocale(); give the host program its locale back afterwards.
    if (const char* loc = std::setlocale(LC_ALL, nullptr)) m_locale = loc;
    // No argv and no ~/.gmshrc: the mesh depends on the file only. This gmsh
    // build installs no signal handlers.
    gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", 0);  // nothing on stdout/stderr
    gmsh::option::setNumber("General.Verbosity", 2);  // log errors and warnings
    // Errors must not throw from inside gmsh's .geo parser: an exception skips
    // the parser's clean-up, and the stale lexer buffer then breaks every later
    // gmsh::open in the process ("line 0: syntax error"), even across
    // finalize/initialize. Errors are read from the log instead.
    gmsh::option::setNumber("General.AbortOnError", 0);
    gmsh::logger::start();
  }
  ~GmshSession() {
    try {
      gmsh::logger::stop();
      gmsh::finalize();
    } catch (...) {
    }
    if (!m_locale.empty()) std::setlocale(LC_ALL, m_locale.c_str());
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

  /// First error logged since the last call ("" if none); clears the log.
  std::string take_first_error() {
    std::vector<std::string> log;
    gmsh::logger::get(log);
    gmsh::logger::stop();
    gmsh::logger::start();
    for (const auto& line : log)
      if (line.rfind("Error", 0) == 0) {
        std::string msg = line.substr(line.find(':') == std::string::npos ? 0 : line.find(':') + 1);
        msg.erase(0, msg.find_first_not_of(' '));
        return msg.empty() ? line : msg;
      }
    return {};
  }

 private:
  std::string m_locale;
};

/// Human-readable plural name of a gmsh element type, for error messages.
std::string element_kind(int type) {
  if (type == kGmshTriangle3) return "triangles";
  std::string name;
  int dim = 0, order = 0, num_nodes = 0, num_primary = 0;
  std::vector<double> local;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, num_nodes, local, num_primary);
  } catch (...) {
    return "elements of gmsh type " + std::to_string(type);
  }
  return quoted(name, 200) + " elements";
}

struct PhysicalGroup {
  int tag;
  std::string name;
  std::vector<int> entities;
};

/// Physical groups of dimension `dim`, by ascending tag; unnamed groups are named
/// after their tag.
std::vector<PhysicalGroup> physical_groups(int dim) {
  gmsh::vectorpair dim_tags;
  gmsh::model::getPhysicalGroups(dim_tags, dim);
  std::vector<PhysicalGroup> groups;
  for (const auto& [d, tag] : dim_tags) {
    PhysicalGroup g{tag, {}, {}};
    gmsh::model::getPhysicalName(d, tag, g.name);
    if (g.name.empty()) g.name = std::to_string(tag);
    gmsh::model::getEntitiesForPhysicalGroup(d, tag, g.entities);
    std::sort(g.entities.begin(), g.entities.end());
    groups.push_back(std::move(g));
  }
  std::sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) { return a.tag < b.tag; });
  return groups;
}

/// Elements of one type on the entities of a group, as flat node-tag lists (gmsh
/// tags). Any other element type throws `on_other_type(type)`.
template <class OnOther>
std::vector<std::size_t> group_elements(int dim, const PhysicalGroup& g, int wanted_type, OnOther on_other_type) {
  std::vector<std::size_t> result;
  for (int entity : g.entities) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, node_tags;
    gmsh::model::mesh::getElements(types, element_tags, node_tags, dim, entity);
    for (std::size_t k = 0; k < types.size(); ++k) {
      if (node_tags[k].empty()) continue;
      if (types[k] != wanted_type) on_other_type(types[k]);
      result.insert(result.end(), node_tags[k].begin(), node_tags[k].end());
    }
  }
  return result;
}

double signed_area(const Eigen::MatrixXd& x, const std::array<int, 4>& q) {
  double a = 0.0;
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    a += x(0, q[i]) * x(1, q[j]) - x(0, q[j]) * x(1, q[i]);
  }
  return 0.5 * a;
}

std::string point_string(const Eigen::MatrixXd& x, int node) {
  std::ostringstream s;
  s << "(" << x(0, node);
  for (Eigen::Index i = 1; i < x.rows(); ++i) s << ", " << x(i, node);
  s << ")";
  return s.str();
}

/// The segments at each node of a curve (node -> segment indices) and the chain's
/// ends (none for a closed curve); a zero-length segment, a branch or several
/// pieces throw.
std::map<int, std::vector<int>> chain_incidence(const std::string& where, const std::string& name,
                                                const Eigen::MatrixXd& x, const std::vector<std::array<int, 2>>& segs,
                                                std::vector<int>& ends) {
  if (segs.empty()) throw InputError(where + ": physical curve " + quoted(name, 200) + " has no line elements");
  std::map<int, std::vector<int>> incident;
  for (int s = 0; s < static_cast<int>(segs.size()); ++s) {
    if (segs[s][0] == segs[s][1])
      throw InputError(where + ": physical curve " + quoted(name, 200) + " has a zero-length segment at " +
                       point_string(x, segs[s][0]));
    for (int n : segs[s]) incident[n].push_back(s);
  }
  for (const auto& [node, list] : incident) {
    if (list.size() > 2)
      throw InputError(where + ": physical curve " + quoted(name, 200) + " branches at " + point_string(x, node) +
                       "; expected a single chain of segments");
    if (list.size() == 1) ends.push_back(node);
  }
  if (!ends.empty() && ends.size() != 2)
    throw InputError(where + ": physical curve " + quoted(name, 200) + " is not connected (" + std::to_string(ends.size() / 2) +
                     " pieces); expected a single chain of segments");
  return incident;
}

/// The nodes of the chain walked from `start` (a closed chain does not repeat it);
/// a segment the walk does not reach throws.
std::vector<int> walk_chain(const std::string& where, const std::string& name, const std::vector<std::array<int, 2>>& segs,
                            std::map<int, std::vector<int>>& incident, int start, bool closed) {
  std::vector<int> nodes{start};
  std::vector<char> used(segs.size(), 0);
  int current = start;
  for (std::size_t step = 0; step < segs.size(); ++step) {
    int next_seg = -1;
    for (int s : incident[current])
      if (!used[s]) {
        next_seg = s;
        break;
      }
    if (next_seg < 0) break;
    used[next_seg] = 1;
    current = segs[next_seg][0] == current ? segs[next_seg][1] : segs[next_seg][0];
    nodes.push_back(current);
  }
  if (std::find(used.begin(), used.end(), 0) != used.end())
    throw InputError(where + ": physical curve '" + name +
                     "' is not connected (a closed loop plus other pieces); expected a single chain of segments");
  if (closed) nodes.pop_back();  // the walk came back to the start
  return nodes;
}

/// +1 if the segment a-b is a counter-clockwise edge of a quad, -1 if b-a is, 0 if
/// neither.
int edge_orientation(const std::vector<std::array<int, 4>>& quads, int a, int b) {
  for (const auto& q : quads)
    for (int i = 0; i < 4; ++i) {
      const int p = q[i], r = q[(i + 1) % 4];
      if (p == a && r == b) return +1;
      if (p == b && r == a) return -1;
    }
  return 0;
}

/// Orders the segments of one curve as a chain. The chain runs so that the body
/// owning the first segment lies on its left (the quad containing the segment
/// has it as a counter-clockwise edge); for a closed curve it starts at the
/// smallest node id.
void order_chain(const std::string& where, const std::string& name, const Eigen::MatrixXd& x,
                 const std::vector<std::array<int, 4>>& quads, const std::vector<std::array<int, 2>>& segs,
                 std::vector<std::array<int, 2>>& out_segments, std::vector<int>& out_nodes) {
  std::vector<int> ends;
  std::map<int, std::vector<int>> incident = chain_incidence(where, name, x, segs, ends);
  const bool closed = ends.empty();
  std::vector<int> nodes = walk_chain(where, name, segs, incident, closed ? incident.begin()->first : ends.front(), closed);

  // Orientation: body on the left of the first segment.
  const int orientation = edge_orientation(quads, nodes[0], nodes[1]);
  if (orientation == 0)
    throw InputError(where + ": physical curve " + quoted(name, 200) + " segment " + point_string(x, nodes[0]) + "-" +
                     point_string(x, nodes[1]) + " is not an edge of any quad of a physical surface");
  if (orientation < 0) {
    if (closed)
      std::reverse(nodes.begin() + 1, nodes.end());  // keep the start node
    else
      std::reverse(nodes.begin(), nodes.end());
  }
  out_nodes = nodes;
  out_segments.clear();
  const std::size_t nseg = closed ? nodes.size() : nodes.size() - 1;
  for (std::size_t k = 0; k < nseg; ++k) out_segments.push_back({nodes[k], nodes[(k + 1) % nodes.size()]});
}

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// Contiguous node numbering: body after body, and within a body by ascending gmsh
/// tag; a node shared by two bodies (bonded) keeps the id of the first.
std::unordered_map<std::size_t, int> number_nodes(const std::vector<std::vector<std::size_t>>& body_tags) {
  std::unordered_map<std::size_t, int> id_of;
  int next = 0;
  for (const auto& tags : body_tags) {
    std::vector<std::size_t> sorted(tags);
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    for (std::size_t t : sorted)
      if (id_of.emplace(t, next).second) ++next;
  }
  return id_of;
}

/// Coordinates (dim x n) of the numbered nodes; a 2D mesh must lie in z = 0.
Eigen::MatrixXd node_coordinates(const std::string& where, const std::unordered_map<std::size_t, int>& id_of, int dim) {
  std::vector<std::size_t> all_tags;
  std::vector<double> coord, param;
  gmsh::model::mesh::getNodes(all_tags, coord, param, -1, -1, true, false);
  Eigen::MatrixXd nodes(dim, static_cast<Eigen::Index>(id_of.size()));
  std::vector<char> found(id_of.size(), 0);
  for (std::size_t k = 0; k < all_tags.size(); ++k) {
    auto it = id_of.find(all_tags[k]);
    if (it == id_of.end()) continue;
    if (dim == 2 && std::abs(coord[3 * k + 2]) > 1e-12)
      throw InputError(where + ": node at z = " + std::to_string(coord[3 * k + 2]) + "; expected a planar mesh in z = 0");
    for (int i = 0; i < dim; ++i) nodes(i, it->second) = coord[3 * k + static_cast<std::size_t>(i)];
    found[static_cast<std::size_t>(it->second)] = 1;
  }
  if (std::find(found.begin(), found.end(), 0) != found.end())
    throw InputError(where + ": an element refers to a node without coordinates");
  return nodes;
}

/// Checks that the physical group `g` of bodies (`kind`: "surface" or "volume")
/// shares no entity with an earlier body and no name with one; records its entities
/// in `entity_owner`.
void check_body_group(const std::string& where, const char* kind, const PhysicalGroup& g,
                      std::map<int, std::string>& entity_owner, const std::vector<std::string>& body_names) {
  for (int e : g.entities) {
    auto [it, inserted] = entity_owner.emplace(e, g.name);
    if (!inserted)
      throw InputError(where + ": " + kind + " " + std::to_string(e) + " belongs to physical " + kind + "s " +
                       quoted(it->second, 200) + " and " + quoted(g.name, 200) + "; each element must belong to one body");
  }
  if (std::find(body_names.begin(), body_names.end(), g.name) != body_names.end())
    throw InputError(where + ": two physical " + kind + "s are named " + quoted(g.name, 200));
}

/// The quads of each physical surface (one body each), as gmsh node tags; records
/// the bodies' names in `mesh.body_names`.
std::vector<std::vector<std::size_t>> read_body_quads(const std::string& where, const std::vector<PhysicalGroup>& surfaces,
                                                      Mesh& mesh) {
  std::vector<std::vector<std::size_t>> body_quads;
  std::map<int, std::string> entity_owner;
  for (const auto& g : surfaces) {
    check_body_group(where, "surface", g, entity_owner, mesh.body_names);
    auto tags = group_elements(2, g, kGmshQuad4, [&](int type) {
      throw InputError(where + ": surface elements must be 4-node quads, found " + element_kind(type));
    });
    if (tags.empty()) throw InputError(where + ": physical surface " + quoted(g.name, 200) + " has no elements");
    mesh.body_names.push_back(g.name);
    body_quads.push_back(std::move(tags));
  }
  return body_quads;
}

/// Appends the quads of every body to `mesh` (numbered by `id_of`), counter-clockwise;
/// a degenerate quad throws.
void add_quads(const std::string& where, const std::vector<std::vector<std::size_t>>& body_quads,
               const std::unordered_map<std::size_t, int>& id_of, Mesh& mesh) {
  for (std::size_t b = 0; b < body_quads.size(); ++b) {
    const auto& tags = body_quads[b];
    for (std::size_t e = 0; e + 3 < tags.size(); e += 4) {
      std::array<int, 4> q{id_of.at(tags[e]), id_of.at(tags[e + 1]), id_of.at(tags[e + 2]), id_of.at(tags[e + 3])};
      const double area = signed_area(mesh.nodes, q);
      double diam2 = 0.0;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) diam2 = std::max(diam2, (mesh.nodes.col(q[i]) - mesh.nodes.col(q[j])).squaredNorm());
      if (!(std::abs(area) > kDegenerateAreaRatio * diam2))
        throw InputError(where + ": quad at " + point_string(mesh.nodes, q[0]) + " in body '" + mesh.body_names[b] +
                         "' is degenerate (zero area)");
      if (area < 0) std::swap(q[1], q[3]);  // clockwise -> counter-clockwise, same first node
      mesh.quads.push_back(q);
      mesh.quad_body.push_back(static_cast<int>(b));
    }
  }
}

/// Adds the physical curve `g` to `mesh` as a chain of segments (order_chain).
void add_curve(const std::string& where, const PhysicalGroup& g, const std::unordered_map<std::size_t, int>& id_of,
               Mesh& mesh) {
  if (mesh.segments.count(g.name)) throw InputError(where + ": two physical curves are named " + quoted(g.name, 200));
  const auto tags = group_elements(1, g, kGmshLine2, [&](int type) {
    throw InputError(where + ": curve elements of " + quoted(g.name, 200) + " must be 2-node lines, found " +
                     element_kind(type));
  });
  std::vector<std::array<int, 2>> segs;
  for (std::size_t e = 0; e + 1 < tags.size(); e += 2) {
    auto a = id_of.find(tags[e]), b = id_of.find(tags[e + 1]);
    if (a == id_of.end() || b == id_of.end())
      throw InputError(where + ": physical curve " + quoted(g.name, 200) + " has nodes that belong to no physical surface");
    segs.push_back({a->second, b->second});
  }
  order_chain(where, g.name, mesh.nodes, mesh.quads, segs, mesh.segments[g.name], mesh.curve_nodes[g.name]);
}

/// The nodes of the physical group `g` of dimension `dim` (`kind`: "curve" or
/// "point"), numbered by `id_of`, in gmsh's order; a node of no body throws
/// (`body_kind`: "surface" or "volume"), and so does an empty group.
std::vector<int> group_nodes(const std::string& where, int dim, const char* kind, const char* body_kind,
                             const PhysicalGroup& g, const std::unordered_map<std::size_t, int>& id_of) {
  std::vector<int> nodes;
  for (int entity : g.entities) {
    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(tags, coord, param, dim, entity, true, false);
    for (std::size_t t : tags) {
      auto it = id_of.find(t);
      if (it == id_of.end())
        throw InputError(where + ": physical " + kind + " " + quoted(g.name, 200) + " has a node of no physical " +
                         body_kind);
      nodes.push_back(it->second);
    }
  }
  if (nodes.empty()) throw InputError(where + ": physical " + kind + " " + quoted(g.name, 200) + " has no mesh node");
  return nodes;
}

/// Adds the physical group `g` of dimension `dim` as a node group without segments
/// or faces (Dirichlet data on a point, or on an edge in 3D).
void add_node_group(const std::string& where, int dim, const char* body_kind, const PhysicalGroup& g,
                    const std::unordered_map<std::size_t, int>& id_of, Mesh& mesh) {
  const char* kind = dim == 1 ? "curve" : "point";
  if (mesh.curve_nodes.count(g.name))
    throw InputError(where + ": the physical " + kind + " " + quoted(g.name, 200) + " has the name of another group");
  std::vector<int>& nodes = mesh.curve_nodes[g.name];
  nodes = group_nodes(where, dim, kind, body_kind, g, id_of);
  if (mesh.dim == 2) {
    mesh.segments[g.name];  // a point: no segments
  } else {  // (2D keeps gmsh's order, which its mesh fingerprint has always hashed)
    sort_unique(nodes);
  }
}

/// The 2D mesh of gmsh's current model: physical surfaces are bodies of quads,
/// physical curves chains of boundary segments, physical points node groups.
Mesh read_current_model(const std::string& where) {
  const auto surfaces = physical_groups(2);
  const auto curves = physical_groups(1);
  if (surfaces.empty() && curves.empty())
    throw InputError(where + " has no physical groups; expected physical surfaces (bodies) and physical curves "
                             "(boundaries)");
  if (surfaces.empty()) throw InputError(where + " has no physical surface; expected one per body");

  Mesh mesh;
  const std::vector<std::vector<std::size_t>> body_quads = read_body_quads(where, surfaces, mesh);
  const std::unordered_map<std::size_t, int> id_of = number_nodes(body_quads);
  mesh.nodes = node_coordinates(where, id_of, 2);
  add_quads(where, body_quads, id_of, mesh);
  for (const auto& g : curves) add_curve(where, g, id_of, mesh);
  for (const auto& g : physical_groups(0)) add_node_group(where, 0, "surface", g, id_of, mesh);
  return mesh;
}

// --- 3D ----------------------------------------------------------------------

/// Elements of dimension `dim` on the entities of a group, by gmsh type, as flat
/// node-tag lists.
std::map<int, std::vector<std::size_t>> group_elements_by_type(int dim, const PhysicalGroup& g) {
  std::map<int, std::vector<std::size_t>> result;
  for (int entity : g.entities) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, node_tags;
    gmsh::model::mesh::getElements(types, element_tags, node_tags, dim, entity);
    for (std::size_t k = 0; k < types.size(); ++k)
      if (!node_tags[k].empty())
        result[types[k]].insert(result[types[k]].end(), node_tags[k].begin(), node_tags[k].end());
  }
  return result;
}

Eigen::Vector3d point3(const Eigen::MatrixXd& x, int node) { return x.col(node).head<3>(); }

double tetra_volume(const Eigen::MatrixXd& x, const std::array<int, 8>& c) {
  const Eigen::Vector3d a = point3(x, c[1]) - point3(x, c[0]), b = point3(x, c[2]) - point3(x, c[0]),
                        d = point3(x, c[3]) - point3(x, c[0]);
  return a.cross(b).dot(d) / 6.0;
}

/// Jacobian determinant of a trilinear hexahedron at its corner k (the triple
/// product of the three edges leaving it, in the order of the reference axes).
double hexa_corner_jacobian(const Eigen::MatrixXd& x, const std::array<int, 8>& c, int k) {
  // Neighbours of corner k along ξ, η, ζ, with the sign of the step.
  static const int along[8][3] = {{1, 3, 4}, {0, 2, 5}, {3, 1, 6}, {2, 0, 7},
                                  {5, 7, 0}, {4, 6, 1}, {7, 5, 2}, {6, 4, 3}};
  static const double sx[8] = {-1, 1, 1, -1, -1, 1, 1, -1}, sy[8] = {-1, -1, 1, 1, -1, -1, 1, 1},
                      sz[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
  const Eigen::Vector3d o = point3(x, c[k]);
  const Eigen::Vector3d e0 = -sx[k] * (point3(x, c[along[k][0]]) - o), e1 = -sy[k] * (point3(x, c[along[k][1]]) - o),
                        e2 = -sz[k] * (point3(x, c[along[k][2]]) - o);
  return e0.cross(e1).dot(e2);
}

double cell_diameter(const Eigen::MatrixXd& x, const std::array<int, 8>& c) {
  double d2 = 0.0;
  const int n = Mesh::cell_size(c);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) d2 = std::max(d2, (x.col(c[i]) - x.col(c[j])).squaredNorm());
  return std::sqrt(d2);
}

/// Orients a cell positively (tetrahedron: positive volume; hexahedron: positive
/// Jacobian at every corner), mirroring a negatively numbered one.
void orient_cell(const std::string& where, const std::string& body, const Eigen::MatrixXd& x, std::array<int, 8>& c) {
  const double h = cell_diameter(x, c), floor = kDegenerateAreaRatio * h * h * h;
  if (Mesh::cell_size(c) == 4) {
    const double v = tetra_volume(x, c);
    if (!(std::abs(v) > floor))
      throw InputError(where + ": tetrahedron at " + point_string(x, c[0]) + " in body '" + body +
                       "' is degenerate (zero volume)");
    if (v < 0) std::swap(c[1], c[2]);
    return;
  }
  if (hexa_corner_jacobian(x, c, 0) < 0) std::swap_ranges(c.begin(), c.begin() + 4, c.begin() + 4);  // top <-> bottom
  for (int k = 0; k < 8; ++k)
    if (!(hexa_corner_jacobian(x, c, k) > floor))
      throw InputError(where + ": hexahedron at " + point_string(x, c[0]) + " in body '" + body +
                       "' is inverted, degenerate or not convex (corner Jacobian " +
                       std::to_string(hexa_corner_jacobian(x, c, k)) + "); expected gmsh's node order");
}

/// Cells containing each node (compressed rows).
struct NodeCells {
  std::vector<int> start, cells;
  NodeCells(int num_nodes, const std::vector<std::array<int, 8>>& all) : start(static_cast<size_t>(num_nodes) + 1, 0) {
    for (const auto& c : all)
      for (int a = 0; a < Mesh::cell_size(c); ++a) ++start[static_cast<size_t>(c[a]) + 1];
    for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    cells.resize(static_cast<size_t>(start.back()));
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int e = 0; e < static_cast<int>(all.size()); ++e)
      for (int a = 0; a < Mesh::cell_size(all[static_cast<size_t>(e)]); ++a)
        cells[static_cast<size_t>(fill[static_cast<size_t>(all[static_cast<size_t>(e)][a])]++)] = e;
  }
  /// Cells holding every node of the facet.
  std::vector<int> holding(const std::array<int, 4>& f, const std::vector<std::array<int, 8>>& all) const {
    std::vector<int> out;
    for (int k = start[static_cast<size_t>(f[0])]; k < start[static_cast<size_t>(f[0]) + 1]; ++k) {
      const auto& c = all[static_cast<size_t>(cells[static_cast<size_t>(k)])];
      bool all_in = true;
      for (int a = 1; a < 4 && f[a] >= 0; ++a) all_in = all_in && std::find(c.begin(), c.end(), f[a]) != c.end();
      if (all_in) out.push_back(cells[static_cast<size_t>(k)]);
    }
    return out;
  }
};

Eigen::Vector3d facet_normal(const Eigen::MatrixXd& x, const std::array<int, 4>& f) {
  if (f[3] < 0) return (point3(x, f[1]) - point3(x, f[0])).cross(point3(x, f[2]) - point3(x, f[0]));
  return (point3(x, f[2]) - point3(x, f[0])).cross(point3(x, f[3]) - point3(x, f[1]));
}

/// The volume elements of each physical volume (one body each): their gmsh node
/// tags, and each cell as (gmsh type, offset into the tags).
struct BodyCells {
  std::vector<std::vector<std::size_t>> tags;
  std::vector<std::vector<std::pair<int, std::size_t>>> cells;
};

/// Reads the cells of every physical volume; records the bodies' names in
/// `mesh.body_names`.
BodyCells read_body_cells(const std::string& where, const std::vector<PhysicalGroup>& volumes, Mesh& mesh) {
  BodyCells bodies;
  std::map<int, std::string> entity_owner;
  for (const auto& g : volumes) {
    check_body_group(where, "volume", g, entity_owner, mesh.body_names);
    std::vector<std::size_t> tags;
    std::vector<std::pair<int, std::size_t>> cells;
    for (const auto& [type, list] : group_elements_by_type(3, g)) {
      if (type != kGmshTetrahedron4 && type != kGmshHexahedron8)
        throw InputError(where + ": volume elements must be 4-node tetrahedra or 8-node hexahedra, found " +
                         element_kind(type));
      const std::size_t n = type == kGmshTetrahedron4 ? 4 : 8;
      for (std::size_t e = 0; e + n <= list.size(); e += n) cells.emplace_back(type, tags.size() + e);
      tags.insert(tags.end(), list.begin(), list.end());
    }
    if (tags.empty()) throw InputError(where + ": physical volume " + quoted(g.name, 200) + " has no elements");
    mesh.body_names.push_back(g.name);
    bodies.tags.push_back(std::move(tags));
    bodies.cells.push_back(std::move(cells));
  }
  return bodies;
}

/// Appends the cells of every body to `mesh` (numbered by `id_of`), positively
/// oriented (orient_cell).
void add_cells(const std::string& where, const BodyCells& bodies, const std::unordered_map<std::size_t, int>& id_of,
               Mesh& mesh) {
  for (std::size_t b = 0; b < bodies.tags.size(); ++b)
    for (const auto& [type, offset] : bodies.cells[b]) {
      std::array<int, 8> c;
      c.fill(-1);
      const int n = type == kGmshTetrahedron4 ? 4 : 8;
      for (int a = 0; a < n; ++a) c[static_cast<size_t>(a)] = id_of.at(bodies.tags[b][offset + static_cast<size_t>(a)]);
      orient_cell(where, mesh.body_names[b], mesh.nodes, c);
      mesh.cells.push_back(c);
      mesh.cell_body.push_back(static_cast<int>(b));
    }
}

/// Orients the facet `f` (`n` nodes) out of the cell `c` that has it: the cell's
/// centroid lies behind it.
void orient_outward(const Eigen::MatrixXd& x, const std::array<int, 8>& c, std::size_t n, std::array<int, 4>& f) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), mid = Eigen::Vector3d::Zero();
  for (int a = 0; a < Mesh::cell_size(c); ++a) centre += point3(x, c[a]) / Mesh::cell_size(c);
  for (std::size_t a = 0; a < n; ++a) mid += point3(x, f[a]) / static_cast<double>(n);
  if (facet_normal(x, f).dot(centre - mid) > 0) std::swap(f[1], f[n - 1]);
}

/// The facets of the physical surface `g`, each oriented out of the body whose
/// cell has it.
std::vector<std::array<int, 4>> surface_facets(const std::string& where, const PhysicalGroup& g,
                                               const std::unordered_map<std::size_t, int>& id_of,
                                               const NodeCells& node_cells, const Mesh& mesh) {
  std::vector<std::array<int, 4>> facets;
  for (const auto& [type, list] : group_elements_by_type(2, g)) {
    if (type != kGmshTriangle3 && type != kGmshQuad4)
      throw InputError(where + ": facets of the physical surface " + quoted(g.name, 200) +
                       " must be 3-node triangles or 4-node quads, found " + element_kind(type));
    const std::size_t n = type == kGmshTriangle3 ? 3 : 4;
    for (std::size_t e = 0; e + n <= list.size(); e += n) {
      std::array<int, 4> f{-1, -1, -1, -1};
      for (std::size_t a = 0; a < n; ++a) {
        auto it = id_of.find(list[e + a]);
        if (it == id_of.end())
          throw InputError(where + ": physical surface " + quoted(g.name, 200) +
                           " has nodes that belong to no physical volume");
        f[a] = it->second;
      }
      const std::vector<int> owners = node_cells.holding(f, mesh.cells);
      if (owners.empty())
        throw InputError(where + ": physical surface " + quoted(g.name, 200) + " has the facet at " +
                         point_string(mesh.nodes, f[0]) + " that is no face of a volume element");
      orient_outward(mesh.nodes, mesh.cells[static_cast<size_t>(owners.front())], n, f);
      facets.push_back(f);
    }
  }
  if (facets.empty()) throw InputError(where + ": physical surface " + quoted(g.name, 200) + " has no elements");
  return facets;
}

/// Adds the physical surface `g` to `mesh`: its outward facets and their nodes.
void add_surface(const std::string& where, const PhysicalGroup& g, const std::unordered_map<std::size_t, int>& id_of,
                 const NodeCells& node_cells, Mesh& mesh) {
  if (mesh.curve_nodes.count(g.name))
    throw InputError(where + ": two physical surfaces are named " + quoted(g.name, 200));
  const std::vector<std::array<int, 4>>& facets = mesh.faces[g.name] =
      surface_facets(where, g, id_of, node_cells, mesh);
  std::vector<int>& nodes = mesh.curve_nodes[g.name];
  for (const auto& f : facets)
    for (int v : f)
      if (v >= 0) nodes.push_back(v);
  sort_unique(nodes);
}

/// The 3D mesh of gmsh's current model: physical volumes are bodies of tetrahedra
/// and hexahedra, physical surfaces boundary facets, physical curves and points node
/// groups.
Mesh read_current_model_3d(const std::string& where) {
  Mesh mesh;
  mesh.dim = 3;
  const BodyCells bodies = read_body_cells(where, physical_groups(3), mesh);
  const std::unordered_map<std::size_t, int> id_of = number_nodes(bodies.tags);
  mesh.nodes = node_coordinates(where, id_of, 3);
  add_cells(where, bodies, id_of, mesh);
  const NodeCells node_cells(mesh.num_nodes(), mesh.cells);
  for (const auto& g : physical_groups(2)) add_surface(where, g, id_of, node_cells, mesh);
  for (int dim : {1, 0})
    for (const auto& g : physical_groups(dim)) add_node_group(where, dim, "volume", g, id_of, mesh);
  return mesh;
}

std::size_t node_count() {
  std::vector<std::size_t> tags;
  std::vector<double> coord, param;
  gmsh::model::mesh::getNodes(tags, coord, param, -1, -1, false, false);
  return tags.size();
}

std::size_t element_count(int dim) {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> element_tags, node_tags;
  gmsh::model::mesh::getElements(types, element_tags, node_tags, dim, -1);
  std::size_t n = 0;
  for (const auto& tags : element_tags) n += tags.size();
  return n;
}

std::string refined_times(int refine) {
  return refine == 0 ? std::string() : " refined " + std::to_string(refine) + (refine == 1 ? " time" : " times");
}

[[noreturn]] void refuse_size(const std::string& where, const std::string& count, int refine, long long limit) {
  throw InputError(where + refined_times(refine) + " has " + count + " nodes, above the limit of " +
                   std::to_string(limit) + " (max_mesh_nodes)");
}

}  // namespace

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

Mesh mesh_with_gmsh(const std::string& path, const MeshOptions& options) {
  const std::string where = "mesh " + quoted(path, 200);
  GmshSession session;
  try {
    gmsh::open(path);
    if (std::string err = session.take_first_error(); !err.empty())
      throw InputError(where + ": gmsh could not read it: " + err);
    // A model with physical volumes is 3D (bodies are volumes), else 2D.
    gmsh::vectorpair volumes;
    gmsh::model::getPhysicalGroups(volumes, 3);
    const int dim = volumes.empty() ? 2 : 3;
    if (lower_extension(path) == ".geo") {
      gmsh::model::mesh::generate(dim);
      if (std::string err = session.take_first_error(); !err.empty())
        throw InputError(where + ": gmsh meshing failed: " + err);
    }
    if (const std::size_t n = node_count(); n > static_cast<std::size_t>(options.max_nodes))
      refuse_size(where, std::to_string(n), 0, options.max_nodes);
    // Each level multiplies the surface elements by four, and a quad mesh has at
    // least as many nodes as quads; it multiplies the volume elements by eight, and a
    // mesh of tetrahedra has at least an eighth as many nodes as tetrahedra (about a
    // fifth in practice): refuse before refining what would be too large.
    const double at_least = dim == 2 ? static_cast<double>(element_count(2)) * std::pow(4.0, options.refine)
                                     : static_cast<double>(element_count(3)) * std::pow(8.0, options.refine) / 8.0;
    if (at_least > static_cast<double>(options.max_nodes))
      refuse_size(where, "at least " + std::to_string(static_cast<long long>(at_least)), options.refine,
                  options.max_nodes);
    // gmsh's refine splits each quad in four through its mid-edge and centre nodes,
    // placed on the model's curves and surfaces (not at straight-line midpoints)
    // because Mesh.SecondOrderLinear is 0 by default.
    for (int level = 0; level < options.refine; ++level) {
      gmsh::model::mesh::refine();
      if (std::string err = session.take_first_error(); !err.empty())
        throw InputError(where + ": gmsh refinement failed: " + err);
    }
    Mesh mesh = dim == 3 ? read_current_model_3d(where) : read_current_model(where);
    if (mesh.num_nodes() > options.max_nodes)
      refuse_size(where, std::to_string(mesh.num_nodes()), options.refine, options.max_nodes);
    return mesh;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(where + ": gmsh failed: " + e.what());
  } catch (...) {
    // gmsh 4.8 throws non-std values (ints, strings) from its API on errors.
    std::string err = session.take_first_error();
    throw InputError(where + ": gmsh failed" + (err.empty() ? std::string() : ": " + err));
  }
}

}  // namespace contactrom::fom
