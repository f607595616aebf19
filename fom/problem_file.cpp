#include <contactrom/fom/problem_file.hpp>

#include <contactrom/fom/data_directory.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/input_file.hpp>

#ifndef CONTACTROM_DEFAULT_PROBLEM_DIR
#define CONTACTROM_DEFAULT_PROBLEM_DIR "problems"
#endif

namespace contactrom::fom {
namespace {

namespace fs = std::filesystem;

/// Reads one problem file's TOML tree into a ProblemDefinition, reporting every
/// error with the file, line and key of the offending node.
class Reader {
 public:
  Reader(ProblemDefinition& def) : m_def(def) {}

  void read(const toml::table& root) {
    allow_keys(root, "", {"problem", "parameters", "bodies", "dirichlet", "traction", "contact", "training",
                          "validation", "rom"});
    read_problem(table(root, "problem", true));
    read_parameters(root);
    read_bodies(root);
    read_dirichlet(root);
    read_traction(root);
    read_contact(root);
    read_training(table(root, "training", false));
    read_validation(table(root, "validation", false));
    read_rom(table(root, "rom", false));
  }

 private:
  [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& what) const {
    SourceLocation at{node ? static_cast<int>(node->source().begin.line) : 0, key};
    throw InputError(m_def.where(at) + ": " + what);
  }
  SourceLocation at(const toml::node* node, const std::string& key) const {
    return {node ? static_cast<int>(node->source().begin.line) : 0, key};
  }

  /// Refuses keys not in `allowed` (typos would otherwise be ignored silently).
  void allow_keys(const toml::table& t, const std::string& prefix, std::initializer_list<const char*> allowed) const {
    for (auto&& [k, v] : t) {
      const std::string key(k.str());
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(&v, prefix + key, "unknown key " + quoted(key, 200) + "; expected one of: " + list);
      }
    }
  }

  const toml::table* table(const toml::table& root, const char* key, bool required) const {
    const toml::node* n = root.get(key);
    if (!n) {
      if (required) fail(nullptr, key, std::string("the table [") + key + "] is missing");
      return nullptr;
    }
    if (!n->is_table()) fail(n, key, std::string("expected a table [") + key + "]");
    return n->as_table();
  }

  /// Array of tables `[[key]]` (may be absent: empty).
  std::vector<const toml::table*> tables(const toml::table& root, const char* key) const {
    std::vector<const toml::table*> out;
    const toml::node* n = root.get(key);
    if (!n) return out;
    if (!n->is_array_of_tables()) fail(n, key, std::string("expected an array of tables [[") + key + "]]");
    for (const toml::node& e : *n->as_array()) out.push_back(e.as_table());
    return out;
  }

  const toml::node* node(const toml::table& t, const std::string& prefix, const char* key, bool required) const {
    const toml::node* n = t.get(key);
    if (!n && required) fail(&t, prefix + key, std::string("the key '") + key + "' is missing");
    return n;
  }

  std::string string(const toml::table& t, const std::string& prefix, const char* key, bool required,
                     const std::string& fallback = "") const {
    const toml::node* n = node(t, prefix, key, required);
    if (!n) return fallback;
    if (!n->is_string()) fail(n, prefix + key, "expected a string");
    const std::string s = n->as_string()->get();
    if (s.empty()) fail(n, prefix + key, "is empty; expected a non-empty string");
    return s;
  }

  double number(const toml::node* n, const std::string& key) const {
    if (!n->is_number()) fail(n, key, "expected a number");
    const double v = n->value<double>().value_or(NAN);
    if (!std::isfinite(v)) fail(n, key, "is " + format_number(v) + "; expected a finite number");
    return v;
  }

  bool boolean(const toml::table& t, const std::string& prefix, const char* key, bool fallback) const {
    const toml::node* n = node(t, prefix, key, false);
    if (!n) return fallback;
    if (!n->is_boolean()) fail(n, prefix + key, "expected true or false");
    return n->as_boolean()->get();
  }

  long integer(const toml::table& t, const std::string& prefix, const char* key, long fallback, long lo,
               long hi) const {
    const toml::node* n = node(t, prefix, key, false);
    if (!n) return fallback;
    if (!n->is_integer()) fail(n, prefix + key, "expected an integer");
    const long v = static_cast<long>(n->as_integer()->get());
    if (v < lo || v > hi)
      fail(n, prefix + key, "is " + std::to_string(v) + "; expected " + std::to_string(lo) + ".." + std::to_string(hi));
    return v;
  }

  /// A number or an affine expression string.
  AffineExpression affine(const toml::node* n, const std::string& key) const {
    if (n->is_string()) {
      try {
        return parse_affine_expression(n->as_string()->get(), m_def.parameters);
      } catch (const InputError& e) {
        fail(n, key, e.what());
      }
    }
    if (!n->is_number()) fail(n, key, "expected a number or an affine expression string such as \"-d\"");
    return AffineExpression::constant_value(number(n, key), m_def.parameters.size());
  }

  /// A vector of one affine value per dimension (two in 2D, three in 3D);
  /// `allow_free` accepts "free" for a component without a value.
  std::array<std::optional<AffineExpression>, 3> vector_value(const toml::table& t, const std::string& prefix,
                                                              const char* key, bool allow_free) const {
    const toml::node* n = node(t, prefix, key, true);
    const int dim = m_def.dimension;
    if (!n->is_array() || static_cast<int>(n->as_array()->size()) != dim)
      fail(n, prefix + key, std::string(dim == 3 ? "expected an array of three components [x, y, z]"
                                                 : "expected an array of two components [x, y]") +
                                (allow_free ? " (number, affine expression or \"free\")" : "") +
                                (n->is_array() && n->as_array()->size() == (dim == 3 ? 2u : 3u)
                                     ? std::string("; the problem's formulation is ") +
                                           (dim == 3 ? "\"3d\"" : "2D (formulation = \"3d\" for three)")
                                     : std::string()));
    std::array<std::optional<AffineExpression>, 3> out;
    for (int c = 0; c < dim; ++c) {
      const toml::node& e = *n->as_array()->get(static_cast<size_t>(c));
      const std::string ckey = prefix + key + "[" + std::to_string(c) + "]";
      if (allow_free && e.is_string() && e.as_string()->get() == "free") continue;
      out[static_cast<size_t>(c)] = affine(&e, ckey);
    }
    return out;
  }

  void read_problem(const toml::table* t) {
    const std::string p = "problem.";
    allow_keys(*t, p,
               {"name", "mesh", "formulation", "refine", "displacement_scale", "max_mesh_nodes", "mesh_time_limit"});
    m_def.name = string(*t, p, "name", true);
    for (char ch : m_def.name)
      if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.'))
        fail(t->get("name"), p + "name", quoted(m_def.name, 200) + " has the character '" + std::string(1, ch) +
                                              "'; expected letters, digits, '_', '-' or '.' (it names output files)");
    const std::string mesh = string(*t, p, "mesh", true);
    const fs::path base = m_def.path.empty() ? fs::path(".") : fs::path(m_def.path).parent_path();
    m_def.mesh = fs::path(mesh).is_absolute() ? mesh : (base / mesh).lexically_normal().string();
    m_def.mesh_where = at(t->get("mesh"), p + "mesh");
    const std::string formulation = string(*t, p, "formulation", false, "plane_strain");
    if (formulation != "plane_strain" && formulation != "plane_stress" && formulation != "3d")
      fail(t->get("formulation"), p + "formulation",
           quoted(formulation, 200) + " is unknown; expected \"plane_strain\", \"plane_stress\" or \"3d\"");
    m_def.plane_stress = formulation == "plane_stress";
    m_def.dimension = formulation == "3d" ? 3 : 2;
    m_def.formulation_where = at(t->get("formulation") ? t->get("formulation") : t, p + "formulation");
    m_def.refine = static_cast<int>(integer(*t, p, "refine", 0, 0, 6));
    m_def.max_mesh_nodes = integer(*t, p, "max_mesh_nodes", static_cast<long>(m_def.max_mesh_nodes), 1,
                                   std::numeric_limits<long>::max());
    if (const toml::node* n = t->get("mesh_time_limit")) {
      m_def.mesh_time_limit = number(n, p + "mesh_time_limit");
      if (!(m_def.mesh_time_limit > 0)) fail(n, p + "mesh_time_limit", "expected a positive number of seconds");
    }
    if (const toml::node* n = t->get("displacement_scale")) {
      m_def.displacement_scale = number(n, p + "displacement_scale");
      if (!(m_def.displacement_scale > 0)) fail(n, p + "displacement_scale", "expected a positive number");
    }
  }

  void read_parameters(const toml::table& root) {
    const auto list = tables(root, "parameters");
    if (list.empty()) fail(nullptr, "parameters", "no [[parameters]] table; expected at least one parameter");
    for (size_t i = 0; i < list.size(); ++i) {
      const toml::table& t = *list[i];
      const std::string p = "parameters[" + std::to_string(i) + "].";
      allow_keys(t, p, {"name", "range", "lower_open"});
      const std::string name = string(t, p, "name", true);
      if (!(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') ||
          std::any_of(name.begin(), name.end(), [](char c) { return !(std::isalnum(static_cast<unsigned char>(c)) || c == '_'); }))
        fail(t.get("name"), p + "name", quoted(name, 200) + " is not a valid name; expected letters, digits and '_', not starting with a digit");
      const toml::node* r = node(t, p, "range", true);
      if (!r->is_array() || r->as_array()->size() != 2) fail(r, p + "range", "expected [lo, hi]");
      const double lo = number(r->as_array()->get(0), p + "range[0]");
      const double hi = number(r->as_array()->get(1), p + "range[1]");
      if (!(lo < hi))
        fail(r, p + "range", "[" + format_number(lo) + ", " + format_number(hi) + "] is empty; expected lo < hi");
      if (!std::isfinite(hi - lo))
        fail(r, p + "range", "[" + format_number(lo) + ", " + format_number(hi) +
                                 "] has a width hi - lo that overflows; expected a finite width");
      const bool lower_open = boolean(t, p, "lower_open", false);
      try {
        m_def.parameters.add(name, lo, hi, lower_open);
      } catch (const InputError& e) {
        fail(t.get("name"), p + "name", e.what());
      }
    }
  }

  void read_bodies(const toml::table& root) {
    const auto list = tables(root, "bodies");
    if (list.empty()) fail(nullptr, "bodies", "no [[bodies]] table; expected one per physical surface of the mesh");
    for (size_t i = 0; i < list.size(); ++i) {
      const toml::table& t = *list[i];
      const std::string p = "bodies[" + std::to_string(i) + "].";
      allow_keys(t, p, {"group", "young", "poisson"});
      BodySpec b;
      b.group = string(t, p, "group", true);
      b.where = at(&t, p + "group");
      const toml::node* young = node(t, p, "young", false);
      b.young = young ? affine(young, p + "young") : AffineExpression::constant_value(1.0, m_def.parameters.size());
      if (!(b.young.min_over(m_def.parameters) > 0))
        fail(young, p + "young", "takes the value " + format_number(b.young.min_over(m_def.parameters)) +
                                     " in the parameter range; expected E > 0 everywhere");
      if (const toml::node* nu = t.get("poisson")) {
        b.poisson = number(nu, p + "poisson");
        if (!(b.poisson > -1.0 && b.poisson < 0.5))
          fail(nu, p + "poisson", "is " + format_number(b.poisson) + "; expected a Poisson ratio in (-1, 0.5)");
      }
      for (const BodySpec& other : m_def.bodies)
        if (other.group == b.group) fail(&t, p + "group", "the body " + quoted(b.group, 200) + " is listed twice");
      m_def.bodies.push_back(std::move(b));
    }
  }

  void read_dirichlet(const toml::table& root) {
    const auto list = tables(root, "dirichlet");
    for (size_t i = 0; i < list.size(); ++i) {
      const toml::table& t = *list[i];
      const std::string p = "dirichlet[" + std::to_string(i) + "].";
      allow_keys(t, p, {"group", "displacement"});
      DirichletSpec d;
      d.group = string(t, p, "group", true);
      d.where = at(&t, p + "group");
      d.displacement = vector_value(t, p, "displacement", true);
      m_def.dirichlet.push_back(std::move(d));
    }
  }

  void read_traction(const toml::table& root) {
    const auto list = tables(root, "traction");
    for (size_t i = 0; i < list.size(); ++i) {
      const toml::table& t = *list[i];
      const std::string p = "traction[" + std::to_string(i) + "].";
      allow_keys(t, p, {"group", "traction"});
      TractionSpec s;
      s.group = string(t, p, "group", true);
      s.where = at(&t, p + "group");
      const auto v = vector_value(t, p, "traction", false);
      for (int c = 0; c < m_def.dimension; ++c) s.traction[static_cast<size_t>(c)] = *v[static_cast<size_t>(c)];
      m_def.traction.push_back(std::move(s));
    }
  }

  void read_contact(const toml::table& root) {
    const auto list = tables(root, "contact");
    if (list.empty()) fail(nullptr, "contact", "no [[contact]] table; expected at least one contact pair");
    for (size_t i = 0; i < list.size(); ++i) {
      const toml::table& t = *list[i];
      const std::string p = "contact[" + std::to_string(i) + "].";
      allow_keys(t, p, {"slave", "master"});
      ContactPairSpec c;
      c.slave = string(t, p, "slave", true);
      c.master = string(t, p, "master", true);
      c.where = at(t.get("slave"), p + "slave");
      c.where_master = at(t.get("master"), p + "master");
      const std::string group = m_def.dimension == 3 ? "surface" : "curve";
      if (c.slave == c.master)
        fail(t.get("master"), p + "master", "is the slave " + group + " " + quoted(c.slave, 200) + " itself; expected another " + group);
      m_def.contact.push_back(std::move(c));
    }
  }

  SamplingPlan sampling(const toml::table* t, const char* table_name, bool validation) {
    SamplingPlan plan;
    if (!t) {
      plan.kind = validation ? SamplingPlan::Kind::Midpoints : SamplingPlan::Kind::Uniform;
      return plan;
    }
    const std::string p = std::string(table_name) + ".";
    if (validation)
      allow_keys(*t, p, {"sampling", "of", "seed", "points"});
    else
      allow_keys(*t, p, {"sampling", "seed", "points", "default_size"});
    const std::string kind = string(*t, p, "sampling", true);
    try {
      plan.kind = sampling_kind_from_name(kind, validation);
    } catch (const InputError& e) {
      fail(t->get("sampling"), p + "sampling", e.what());
    }
    plan.seed = static_cast<unsigned>(integer(*t, p, "seed", 0, 0, 4294967295L));
    // Present, a size or level is at least 1 (0 would read as "not given").
    if (validation) plan.of = static_cast<int>(integer(*t, p, "of", 0, 1, SamplingPlan::kMaxPoints));
    else plan.default_size = static_cast<int>(integer(*t, p, "default_size", 0, 1, SamplingPlan::kMaxPoints));
    const toml::node* pts = t->get("points");
    if (plan.kind == SamplingPlan::Kind::List) {
      if (!pts || !pts->is_array() || pts->as_array()->empty())
        fail(pts ? pts : t, p + "points", "sampling \"list\" needs points = [[...], ...] (one array per point)");
      const int d = m_def.parameters.size();
      for (size_t k = 0; k < pts->as_array()->size(); ++k) {
        const toml::node& e = *pts->as_array()->get(k);
        const std::string key = p + "points[" + std::to_string(k) + "]";
        Param mu(d);
        if (e.is_number() && d == 1) {
          mu(0) = number(&e, key);
        } else {
          if (!e.is_array() || static_cast<int>(e.as_array()->size()) != d)
            fail(&e, key, "expected an array of " + std::to_string(d) + " values (one per parameter)");
          for (int c = 0; c < d; ++c) mu(c) = number(e.as_array()->get(static_cast<size_t>(c)), key);
        }
        if (!m_def.parameters.contains(mu))
          fail(&e, key, "lies outside the parameter range; expected " + m_def.parameters.range_text());
        plan.points.push_back(mu);
      }
    } else if (pts) {
      fail(pts, p + "points", "is only read with sampling = \"list\"");
    }
    return plan;
  }

  void read_training(const toml::table* t) { m_def.training = sampling(t, "training", false); }
  void read_validation(const toml::table* t) { m_def.validation = sampling(t, "validation", true); }

  void read_rom(const toml::table* t) {
    if (!t) return;
    allow_keys(*t, "rom.", {"convex_hull", "cpg_tolerance", "penetration_tolerance", "complementarity_tolerance",
                            "negative_pressure_tolerance"});
    m_def.rom.convex_hull = boolean(*t, "rom.", "convex_hull", false);
    const auto fraction = [&](const char* key, double& out) {
      if (const toml::node* n = t->get(key)) {
        out = number(n, std::string("rom.") + key);
        if (!(out > 0 && out < 1))
          fail(n, std::string("rom.") + key, "is " + format_number(out) + "; expected a number in (0, 1)");
      }
    };
    fraction("cpg_tolerance", m_def.rom.cpg_tolerance);
    fraction("penetration_tolerance", m_def.rom.penetration_tolerance);
    fraction("complementarity_tolerance", m_def.rom.complementarity_tolerance);
    fraction("negative_pressure_tolerance", m_def.rom.negative_pressure_tolerance);
  }

  ProblemDefinition& m_def;
};

std::string read_text_file(const std::string& path) {
  // A small TOML file: at most 16 MiB.
  return read_input_file(path, "problem file", std::uintmax_t{16} << 20);
}

}  // namespace

std::string ProblemDefinition::where(const SourceLocation& at) const {
  std::string out = "problem file '" + (path.empty() ? name : path) + "'";
  if (at.line > 0) out += ", line " + std::to_string(at.line);
  if (!at.key.empty()) out += ", key " + quoted(at.key, 200);
  return out;
}

ProblemDefinition parse_problem_text(const std::string& text, const std::string& path) {
  ProblemDefinition def;
  def.path = path;
  def.text = text;
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    std::string what(e.description());
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw InputError("problem file " + quoted(path, 200) + ", line " + std::to_string(e.source().begin.line) +
                     ": TOML syntax error: " + what);
  }
  Reader(def).read(root);
  return def;
}

ProblemDefinition read_problem_file(const std::string& path) { return parse_problem_text(read_text_file(path), path); }

std::string problem_directory() { return data_directory("problems", "CONTACTROM_PROBLEM_DIR"); }

std::vector<std::string> shipped_problem_names() {
  std::vector<std::string> names{"rope"};
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(problem_directory(), ec))
    if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
  std::sort(names.begin() + 1, names.end());
  return names;
}

std::string find_problem_file(const std::string& name_or_path) {
  const bool is_path = name_or_path.find('/') != std::string::npos ||
                       (name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".toml");
  if (is_path) {
    std::error_code ec;
    if (!fs::exists(name_or_path, ec)) throw InputError("problem file " + quoted(name_or_path, 200) + " not found");
    return name_or_path;
  }
  const std::string dir = problem_directory(), path = dir + "/" + name_or_path + ".toml";
  std::error_code ec;
  if (name_or_path.empty() || !fs::exists(path, ec)) {
    std::string list;
    for (const auto& n : shipped_problem_names()) list += (list.empty() ? "" : ", ") + n;
    std::string where = "; the shipped problems are looked for in " + quoted(dir, 200);
    if (!fs::is_directory(dir, ec))
      where += ", which does not exist: set CONTACTROM_PROBLEM_DIR to the folder that holds them "
               "(PREFIX/share/contactrom/problems of an install)";
    throw InputError("unknown problem " + quoted(name_or_path, 200) + "; expected a problem file path or one of: " + list +
                     where);
  }
  return path;
}

}  // namespace contactrom::fom
